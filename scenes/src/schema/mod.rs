//! The scene file schema: one struct per TOML section. The rustdoc of every field is the
//! schema's documentation (units, meaning, default). Unknown keys are errors everywhere.
//! Each section's file also checks its values (`check`, over [`Check`]); `validate` runs
//! them in file order and then checks the scene's geometry.
//!
//! Defaults are the paper's values where it gives them (Aleotti et al. 2014), OctoMap's and
//! OpenRAVE's where it is silent, and a stated assumption otherwise (each key's doc says
//! which).

mod check;
mod error_model;
mod layout;
mod mapping;
mod model;
mod nbv;
mod objects;
mod planner;
mod pose_spec;
mod registration;
mod robot;
mod segmentation;
mod sensors;
mod sweep;
mod table;
mod workspace;

pub(crate) use check::Check;
pub use error_model::{ErrorModel, PoseNoise};
pub use layout::Layout;
pub use mapping::Mapping;
pub use model::Model;
pub use nbv::{GainMeasureName, Nbv, NbvPreset};
pub use objects::{ObjectSpec, ObstacleSpec};
pub use planner::Planner;
pub use pose_spec::PoseSpec;
pub use registration::Registration;
pub use robot::RobotSpec;
pub use segmentation::Segmentation;
pub use sensors::{CameraNoise, LaserNoise, MidRangeSensor, Sensors, ShortRangeSensor};
pub use sweep::Sweep;
pub use table::Table;
pub use workspace::Workspace;
