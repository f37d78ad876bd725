//! Small geometric helpers shared by every module: poses and their text forms.

mod pose;
pub mod pose_file;

pub use pose::{Pose, pose_from_xyz_rpy, pose_to_xyz_rpy};
