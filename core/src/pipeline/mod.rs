//! The method end to end (the paper's Figure 2), generic over the rig traits: the
//! phase-1 laser sweep, segmentation, the occupancy grid and its reduced map, then for each
//! object next-best-view exploration with the depth camera (Algorithm 1), and finally
//! the global registration of each object's views (a maximum a posteriori estimate with
//! the rig's pose uncertainty as the prior; the paper's p-ICP-GPA and sequential ICP
//! beside it).
//!
//! [`explore`] drives a [`Rig`](crate::rig::Rig) — an arm, a line scanner and a depth
//! camera with the robot model — and never knows whether it is the twin or the real
//! devices. Progress goes to an [`ExploreObserver`]. One file per stage of Figure 2:
//! `phase_one` (sweep, workcell alignment, segmentation, grid), `object_loop` (Algorithm
//! 1 for one object), `candidates` (Algorithm 2 around the object), `plan_and_execute`,
//! `acquire_and_update`, `register_views`, `calibration_views`; `exploration` runs them in order.

mod acquire_and_update;
mod calibration_views;
mod candidates;
mod episode_state;
mod exploration;
mod exploration_map;
mod explore_config;
mod explore_event;
mod fuse_surface;
mod object_crop;
mod object_loop;
mod phase_one;
mod pipeline_error;
mod plan_and_execute;
mod register_views;
mod results;
mod step_timer;

pub use acquire_and_update::REGISTRATION_SMOOTHING;
pub use calibration_views::calibration_share;
pub use candidates::{
    ObjectSurface, ViewCandidates, object_surface_score, view_candidates, viewing_centre,
};
pub use exploration::explore;
pub use exploration_map::ExplorationMap;
pub use explore_config::{ExploreConfig, ExploreMode, SURVEY_HEIGHT, SURVEY_SPACING};
pub use explore_event::{ExploreEvent, ExploreObserver, NoObserver};
pub use fuse_surface::object_views;
pub use object_crop::ObjectRegion;
pub use phase_one::run_phase_one;
pub use pipeline_error::PipelineError;
pub use plan_and_execute::{goals_at, plan_clearing_start};
pub use register_views::sweep_free_space;
pub use results::{
    AcquiredView, Exploration, ObjectExploration, ObjectRegistration, ObjectStop, PhaseOneReport,
    StepTimes, ViewFailure,
};
