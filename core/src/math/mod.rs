//! Small geometric helpers shared by every module: poses and their text forms, the
//! eigen-decomposition of a 3×3 covariance.

mod pose;
pub mod pose_file;
mod symmetric_eigen3;

pub use pose::{Pose, pose_from_xyz_rpy, pose_to_xyz_rpy};
pub use symmetric_eigen3::symmetric_eigen3;
