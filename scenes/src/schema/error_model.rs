//! [`ErrorModel`]: the errors the twin injects into the poses the rig reports.

use super::Check;
use super::PoseSpec;
use crate::error::SceneError;
use serde::{Deserialize, Serialize};

/// What separates the reported sensor poses from the true ones, so registration has real
/// work to do (defaults are assumptions: the paper gives none).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ErrorModel {
    /// Hand-eye calibration error of the short-range camera: its true mount is the
    /// nominal URDF mount composed with this pose (constant over the episode; the laser
    /// is taken as the calibrated reference). Default 4 mm / 0.5° scale.
    pub hand_eye: PoseSpec,
    /// Constant joint offsets (degrees) between the commanded/reported and the true joint
    /// angles (kinematic calibration error). Default `[0.05, -0.04, 0.03, 0.05, -0.05, 0.05]`.
    pub joint_offset_deg: [f64; 6],
    /// Random error of each reported view pose.
    pub pose_noise: PoseNoise,
    /// Scale of the whole model: hand-eye, joint offsets and pose noise are multiplied by
    /// it, in the twin and in the registration's prior alike (a sweep key for the error
    /// level: `errors.scale = 3`). Default 1.
    pub scale: f64,
}

impl ErrorModel {
    /// Hand-eye error (metres, radians) after [`scale`](Self::scale).
    pub fn scaled_hand_eye(&self) -> ([f64; 3], [f64; 3]) {
        let s = self.scale;
        let (t, r) = (self.hand_eye.xyz, self.hand_eye.rpy_deg);
        (
            [t[0] * s, t[1] * s, t[2] * s],
            [
                (r[0] * s).to_radians(),
                (r[1] * s).to_radians(),
                (r[2] * s).to_radians(),
            ],
        )
    }

    /// Joint offsets (radians) after [`scale`](Self::scale).
    pub fn scaled_joint_offsets(&self) -> [f64; 6] {
        self.joint_offset_deg.map(|d| (d * self.scale).to_radians())
    }

    /// Pose noise σ (metres, radians) after [`scale`](Self::scale).
    pub fn scaled_pose_noise(&self) -> (f64, f64) {
        (
            self.pose_noise.translation_sigma * self.scale,
            (self.pose_noise.rotation_sigma_deg * self.scale).to_radians(),
        )
    }
}

impl Default for ErrorModel {
    fn default() -> Self {
        Self {
            hand_eye: PoseSpec {
                xyz: [0.004, -0.003, 0.002],
                rpy_deg: [0.4, -0.3, 0.5],
            },
            joint_offset_deg: [0.05, -0.04, 0.03, 0.05, -0.05, 0.05],
            pose_noise: PoseNoise::default(),
            scale: 1.0,
        }
    }
}

/// Zero-mean Gaussian perturbation of each reported sensor pose (seeded).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PoseNoise {
    /// σ of each translation component (m). Default 0.002.
    pub translation_sigma: f64,
    /// σ of the rotation angle about a random axis (degrees). Default 0.2.
    pub rotation_sigma_deg: f64,
}

impl Default for PoseNoise {
    fn default() -> Self {
        Self {
            translation_sigma: 0.002,
            rotation_sigma_deg: 0.2,
        }
    }
}

impl ErrorModel {
    /// Checks every value of `[errors]`; the error names the key.
    pub(crate) fn check(&self, c: &Check) -> Result<(), SceneError> {
        c.pose("errors.hand_eye", &self.hand_eye)?;
        c.finite("errors.joint_offset_deg", &self.joint_offset_deg)?;
        c.within(
            "errors.pose_noise.translation_sigma",
            self.pose_noise.translation_sigma,
            0.0,
            1.0,
            "[0, 1] m",
        )?;
        c.within(
            "errors.pose_noise.rotation_sigma_deg",
            self.pose_noise.rotation_sigma_deg,
            0.0,
            90.0,
            "[0, 90] degrees",
        )?;
        c.within("errors.scale", self.scale, 0.0, 100.0, "[0, 100]")
    }
}
