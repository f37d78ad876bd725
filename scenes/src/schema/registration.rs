//! [`Registration`]: the registration of each object's views (the MAP registration that
//! makes the model; the paper's p-ICP-GPA and sequential ICP as baselines).

use super::Check;
use crate::error::SceneError;
use nbv_core::registration::RegistrationParams;
use serde::{Deserialize, Serialize};

/// Global registration of an object's views.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Registration {
    /// Largest correspondence distance `d_max` (m). Default: nbv-core's
    /// ([`RegistrationParams`]), 0.03.
    pub d_max: f64,
    /// Iteration cap. Default: nbv-core's, 100.
    pub max_iterations: u32,
    /// Stop when the mean squared distance to the centroids changes by less than this
    /// fraction between iterations. Default: nbv-core's, 1e-6.
    pub tolerance: f64,
    /// Points per view the registration reads, subsampled by index (the model keeps every
    /// point of its views). Default 2000 (paper).
    pub points_per_view: u32,
    /// Largest correction (degrees) a registration may apply to a view's reported pose:
    /// the robot's kinematics bound the pose error, so a larger turn (a slide along a
    /// symmetry of the object) marks the registration as rejected and the model keeps the
    /// reported poses. Default 5.
    pub max_correction_deg: f64,
    /// Largest displacement (m) of a view's centroid by the correction. Default 0.03.
    pub max_correction_m: f64,
    /// Correct the laser sweep's reported pose by the workcell it sees (the table top and
    /// the known obstacles) before segmentation, so the laser cluster — the registration's
    /// anchor — and the exclusion of known obstacles are where the scene says. Default
    /// true.
    pub align_to_workcell: bool,
    /// Calibrate the rig while exploring: estimate one hand-eye correction of the depth
    /// camera (and the joint offsets) from every object's registration and from where
    /// each view's table points fall off the table top the laser measured, then register
    /// each object again from the calibrated poses (docs/registration.md). Default true.
    pub calibrate_hand_eye: bool,
    /// Camera views the self-calibration reads at least, per episode: when the exploration
    /// takes fewer, each object, once explored, is seen from more of its candidate
    /// viewpoints for the calibration alone. Each view carries a standstill error of its
    /// own, and the estimate's spread falls with the views (docs/hand-eye.md); the views
    /// join the object's registration, not its model, its views or its coverage by view.
    /// Default 15: the twin preset's exploration takes about 13 views an episode on the
    /// paper scenes, and from 15 or more the estimate is within 0.1° on 19 of 20 episodes
    /// (docs/hand-eye.md, "Views for the calibration alone"); 0 takes none.
    pub calibration_views: u32,
    /// Run the paper's p-ICP-GPA and sequential ICP beside the model's MAP registration,
    /// for the report's comparison (`error_pgpa`, `error_icp`) and Table III. They do not
    /// change the model; turning them off makes an episode several times cheaper in CPU
    /// (sweeps that tune exploration, not registration). Default true.
    pub baselines: bool,
}

impl Default for Registration {
    fn default() -> Self {
        let core = RegistrationParams::default();
        Self {
            d_max: core.max_correspondence_distance,
            max_iterations: core.max_iterations as u32,
            tolerance: core.tolerance,
            points_per_view: 2000,
            max_correction_deg: 5.0,
            max_correction_m: 0.03,
            align_to_workcell: true,
            calibrate_hand_eye: true,
            calibration_views: 15,
            baselines: true,
        }
    }
}

impl Registration {
    /// Checks every value of `[registration]`; the error names the key.
    pub(crate) fn check(&self, c: &Check) -> Result<(), SceneError> {
        c.positive("registration.d_max", self.d_max)?;
        c.at_least("registration.max_iterations", self.max_iterations.into(), 1)?;
        c.positive("registration.tolerance", self.tolerance)?;
        c.at_least(
            "registration.points_per_view",
            self.points_per_view.into(),
            3,
        )?;
        c.positive("registration.max_correction_deg", self.max_correction_deg)?;
        c.positive("registration.max_correction_m", self.max_correction_m)?;
        Ok(())
    }
}
