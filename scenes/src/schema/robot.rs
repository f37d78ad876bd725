//! [`RobotSpec`]: which robot, where, and its home configuration.

use super::Check;
use super::PoseSpec;
use crate::error::SceneError;
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

/// The arm: a URDF with the sensor frames (`lms400`, `dinast`), its base pose in the world
/// and the home configuration the episode starts from.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RobotSpec {
    /// URDF file, relative to the scene file's directory (resolved on load). Required.
    pub urdf: PathBuf,
    /// Pose of the robot's base link in the world. Default: the origin (the world frame
    /// *is* the robot base frame in the paper scenes).
    #[serde(default)]
    pub base: PoseSpec,
    /// Home joint angles J1..J6 (degrees, Comau signs). Default `[0, 0, -90, 0, 90, 0]`:
    /// upper arm vertical, forearm horizontal (the calibration pose), wrist bent down, so
    /// the sensors sit above the front of the table, clear of it.
    #[serde(default = "default_home")]
    pub home_deg: [f64; 6],
}

fn default_home() -> [f64; 6] {
    [0.0, 0.0, -90.0, 0.0, 90.0, 0.0]
}

impl RobotSpec {
    /// Checks the values of `[robot]` but the URDF (which is loaded and checked with the
    /// scene's geometry); the error names the key.
    pub(crate) fn check(&self, c: &Check) -> Result<(), SceneError> {
        c.pose("robot.base", &self.base)?;
        c.finite("robot.home_deg", &self.home_deg)?;
        Ok(())
    }
}
