//! [`ErrorModel`]: the errors the twin injects into the poses the rig reports.

use super::PoseSpec;
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
