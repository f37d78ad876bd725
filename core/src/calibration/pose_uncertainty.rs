//! [`PoseUncertainty`]: what the rig declares about its sensors — the range noise of each
//! and how far the pose it reports for each may be off — turned into the
//! [`ViewModel`]s of an object's registration.
//!
//! The registration fixes the laser cluster and corrects each camera view relative to it,
//! so a camera view's prior is the sum of both sensors' pose errors: its own, and the
//! laser's, whose rotation error `σ_r` displaces the object, seen from the camera at
//! distance `d` from the laser, by about `σ_r·d` (`σ_r·d·√(2/3)` per axis).

use crate::cloud::PointCloud;
use crate::registration::{PosePrior, RangeNoise, ViewModel};

/// The rig's sensor noise and pose uncertainty (per-component σ; see [`PosePrior`]).
///
/// ```
/// use nbv_core::calibration::PoseUncertainty;
/// use nbv_core::registration::{PosePrior, RangeNoise};
/// let u = PoseUncertainty {
///     laser_noise: RangeNoise::constant(0.002),
///     camera_noise: RangeNoise { sigma_at_1m: 0.04, exponent: 1.0 },
///     laser_pose: PosePrior { rotation_sigma: 0.002, translation_sigma: 0.002 },
///     camera_pose: PosePrior { rotation_sigma: 0.005, translation_sigma: 0.003 },
///     hand_eye: PosePrior { rotation_sigma: 0.004, translation_sigma: 0.002 },
///     joint_offset_sigma: 0.001,
///     view_noise: PosePrior { rotation_sigma: 0.002, translation_sigma: 0.002 },
/// };
/// let prior = u.camera_prior(1.0);
/// // The laser's 0.002 rad at 1 m adds about 1.6 mm per axis.
/// assert!((prior.translation_sigma - (0.003f64.powi(2) + 0.002f64.powi(2)
///     + (0.002f64 * 1.0).powi(2) * 2.0 / 3.0).sqrt()).abs() < 1e-12);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PoseUncertainty {
    /// The line scanner's range noise.
    pub laser_noise: RangeNoise,
    /// The depth camera's range noise of one frame.
    pub camera_noise: RangeNoise,
    /// How far the laser sweep's reported pose may be off.
    pub laser_pose: PosePrior,
    /// How far a camera view's reported pose may be off (hand-eye, kinematics, noise of
    /// the reported pose): the prior of the first registration pass.
    pub camera_pose: PosePrior,
    /// How far the depth camera's mount (hand-eye) may be off: one error that every
    /// camera view shares, which the rig's self-calibration estimates.
    pub hand_eye: PosePrior,
    /// σ of each joint's angle offset (rad), the kinematic calibration error.
    pub joint_offset_sigma: f64,
    /// How far one standstill's reported pose may be off beyond the hand-eye and joint
    /// errors (independent per view).
    pub view_noise: PosePrior,
}

impl PoseUncertainty {
    /// The prior of a camera view whose sensor is `distance` (m) from the laser's.
    pub fn camera_prior(&self, distance: f64) -> PosePrior {
        let (c, l) = (&self.camera_pose, &self.laser_pose);
        let lever = l.rotation_sigma * distance;
        PosePrior {
            rotation_sigma: c.rotation_sigma.hypot(l.rotation_sigma),
            translation_sigma: (c.translation_sigma.powi(2)
                + l.translation_sigma.powi(2)
                + lever * lever * 2.0 / 3.0)
                .sqrt(),
        }
    }

    /// The models of an object's views: the laser cluster first (the anchor: no prior),
    /// then camera views of `frames` averaged frames each. Sensor positions come from the
    /// views' `origins` columns (the centroid stands in where there is none).
    pub fn view_models(&self, views: &[PointCloud], frames: usize) -> Vec<ViewModel> {
        self.view_models_with(views, frames, |_| self.camera_pose)
    }

    /// [`view_models`](Self::view_models) with camera view `k`'s own pose σ
    /// `camera_pose(k)` in place of [`camera_pose`](Self::camera_pose) (the laser's
    /// share is added as there).
    pub fn view_models_with(
        &self,
        views: &[PointCloud],
        frames: usize,
        camera_pose: impl Fn(usize) -> PosePrior,
    ) -> Vec<ViewModel> {
        let origin = |v: &PointCloud| v.origin_centroid().or_else(|| v.centroid());
        let laser = views.first().and_then(origin);
        views
            .iter()
            .enumerate()
            .map(|(k, v)| {
                if k == 0 {
                    return ViewModel {
                        noise: self.laser_noise,
                        prior: None,
                    };
                }
                let at = origin(v);
                let distance = match (laser, at) {
                    (Some(a), Some(b)) => (a - b).norm(),
                    _ => 0.0,
                };
                let own = Self {
                    camera_pose: camera_pose(k),
                    ..*self
                };
                ViewModel {
                    noise: self.camera_noise.averaged(frames),
                    prior: Some(own.camera_prior(distance)),
                }
            })
            .collect()
    }
}
