//! The simulated sensors as pure functions of the twin world and a true sensor pose: the
//! LMS400 line scanner ([`LaserModel`]) and the Dinast depth camera ([`CameraModel`]). The
//! rig devices ([`crate::rig`]) decide *when* and *from where* they are cast.

mod acquisition_id;
mod camera_model;
mod laser_model;

pub use acquisition_id::AcquisitionId;
pub use camera_model::{CameraModel, TrueFrame, TruePixel};
pub use laser_model::LaserModel;
