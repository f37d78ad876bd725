//! Episode recordings for the Rerun viewer (feature `rerun`): `episode.rrd`, everything
//! the robot did, saw and decided, on two timelines — `sim_time` (the rig's clock,
//! seconds) and `step` (the index of the pipeline event).
//!
//! The recorder is an [`ExploreObserver`](nbv_core::pipeline::ExploreObserver): it logs
//! the pipeline's events as they come ([`EpisodeRecorder::observe`] puts it beside the
//! progress bars), then the report's figures at the end ([`EpisodeRecorder::finish`]),
//! and writes the file atomically.
//!
//! Entity paths, by the paper's terms ([`entity`]):
//!
//! ```text
//! world/scene/{table,obstacles/<i>,objects/<name>}  the scene's truth (static)
//! world/robot/<link>[/visual_<k>]                    link meshes (static), link poses
//! world/sweep/{line,cloud/<batch>,clusters/<j>}      phase 1: the laser line, the cloud, the clusters
//! world/grid/{occupied,unknown}                      the reduced map after each update
//! world/objects/<j>/{candidates,failed,path,camera,frame,views/view_<k>}
//!                                                    the NBV loop of object j
//! world/models/<j>/{before,after}                    the views before and after registration
//! plots/{gain,coverage,times/<step>}/<j>             time series
//! log                                                the decisions
//! ```

pub mod entity;
mod episode_recorder;
mod layout;
mod palette;
mod robot_links;

pub use episode_recorder::{EpisodeRecorder, RecordingTee};
