//! The repository's robot asset, the Comau SMART SiX with its sensor bracket
//! (`assets/urdf/comau_smart_six.urdf`): the one place that spells its path, for the
//! tests, doc examples, benchmarks and fuzz targets of every crate.

use super::{Robot, UrdfError};

/// Absolute path of the Comau SMART SiX URDF in this source tree.
pub const COMAU_URDF: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../assets/urdf/comau_smart_six.urdf"
);

/// The Comau SMART SiX model loaded from [`COMAU_URDF`].
///
/// ```
/// let robot = nbv_core::kinematics::comau_smart_six()?;
/// assert!(robot.fk(&nbv_core::kinematics::Joints::zeros(), "dinast").is_ok());
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn comau_smart_six() -> Result<Robot, UrdfError> {
    Robot::from_urdf_file(COMAU_URDF)
}
