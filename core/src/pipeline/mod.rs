//! The method end to end (the paper's Figure 2), generic over the rig traits: the
//! phase-1 laser sweep, segmentation, the occupancy grid and its reduced map, then for each
//! object next-best-view exploration with the depth camera (Algorithm 1), and finally
//! the global registration of each object's views (a maximum a posteriori estimate with
//! the rig's pose uncertainty as the prior; the paper's p-ICP-GPA and sequential ICP
//! beside it).
//!
//! [`explore`] drives an [`Arm`](crate::rig::Arm), a
//! [`LineScanner`](crate::rig::LineScanner) and a
//! [`DepthCamera`](crate::rig::DepthCamera); it never knows whether they are the twin or
//! the real devices. Progress goes to an [`ExploreObserver`].

mod exploration;
mod explore_config;
mod explore_event;
mod hand_eye;
mod object_crop;
mod pipeline_error;
mod pose_uncertainty;
mod results;
mod table_filter;

pub use exploration::{explore, run_phase_one};
pub use explore_config::{ExploreConfig, ExploreMode};
pub use explore_event::{ExploreEvent, ExploreObserver, NoObserver};
pub use hand_eye::{HandEyeEstimate, estimate_hand_eye};
pub use object_crop::ObjectRegion;
pub use pipeline_error::PipelineError;
pub use pose_uncertainty::PoseUncertainty;
pub use results::{
    AcquiredView, Exploration, ObjectExploration, ObjectRegistration, ObjectStop, PhaseOneReport,
    StepTimes, ViewFailure,
};
pub use table_filter::TableFilter;
