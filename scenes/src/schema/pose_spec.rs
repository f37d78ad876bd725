//! [`PoseSpec`]: a pose as written in scene files (`{ xyz = [...], rpy_deg = [...] }`).

use nbv_core::math::{Pose, pose_from_xyz_rpy};
use serde::{Deserialize, Serialize};

/// A rigid pose: translation (m) and URDF roll-pitch-yaw (degrees; fixed axes x, y, z).
///
/// ```
/// use nbv_scenes::schema::PoseSpec;
/// let p = PoseSpec { xyz: [1.0, 0.0, 0.25], rpy_deg: [0.0, 0.0, 90.0] };
/// let x = p.to_pose().rotation * nalgebra::Vector3::x();
/// assert!((x.y - 1.0).abs() < 1e-12);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PoseSpec {
    /// Translation `[x, y, z]` in metres.
    pub xyz: [f64; 3],
    /// Roll, pitch, yaw in degrees (URDF convention `R = Rz(yaw)·Ry(pitch)·Rx(roll)`).
    /// Default `[0, 0, 0]`.
    #[serde(default)]
    pub rpy_deg: [f64; 3],
}

impl PoseSpec {
    /// The pose as an isometry.
    pub fn to_pose(&self) -> Pose {
        pose_from_xyz_rpy(self.xyz, self.rpy_deg.map(f64::to_radians))
    }

    /// Whether every number is finite.
    pub fn is_finite(&self) -> bool {
        self.xyz.iter().chain(&self.rpy_deg).all(|v| v.is_finite())
    }
}
