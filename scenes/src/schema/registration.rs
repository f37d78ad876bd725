//! [`Registration`]: p-ICP-GPA (and the sequential ICP baseline).

use super::Check;
use crate::error::SceneError;
use serde::{Deserialize, Serialize};

/// Global registration of an object's views.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Registration {
    /// Largest mutual-nearest-neighbour distance `d_max` (m). Default 0.03 (about twice
    /// the short-range noise at working distance; assumed).
    pub d_max: f64,
    /// Iteration cap. Default 100.
    pub max_iterations: u32,
    /// Stop when the mean squared distance to the centroids changes by less than this
    /// fraction between iterations. Default 1e-6.
    pub tolerance: f64,
    /// Points per view after undersampling. Default 2000 (paper).
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
    /// camera (and the joint offsets) from every object's registration, then register
    /// each object again from the calibrated poses. Default true.
    pub calibrate_hand_eye: bool,
    /// Let the self-calibration read the table around the objects in every camera view:
    /// the laser measured the table top, and where a view's table points fall off that
    /// plane fixes the view's height and tilts, free of the bias the camera's noise leaves
    /// on curved objects; the views see the table from many directions, so together they
    /// fix every direction of the mount. Both paper scenes × seeds 1–10 at ×1: the
    /// hand-eye estimate 0.141° / 1.00 mm off without it, 0.049° / 0.71 mm with it
    /// (benches/README, "The table as a calibration target"). Default true.
    pub table_evidence: bool,
    /// Give the model's MAP registration the laser sweep's free space around each
    /// object (where its rays passed before they hit something): a camera point beyond
    /// the edge of the laser cluster is pulled back where the laser saw through to the
    /// table and left alone where the laser never looked. Default true; false is the
    /// previous release's data term (boundary rejection alone), for comparison.
    pub free_space: bool,
    /// Give the model's MAP registration each camera view's own free space (in front of
    /// its averaged depth image's returns): a laser point beyond the edge of a view's
    /// surface where the camera saw through contradicts the view's pose and pulls it back
    /// (a view slid along a box's top, past a rim the laser saw but could not see
    /// beyond). Default true; false is the previous release.
    pub camera_free_space: bool,
    /// Half-width (pixels) of the edge-gated plane fit that smooths each view's averaged
    /// depth frame for the registration alone ([`smooth_frame`](nbv_core::rig::smooth_frame)):
    /// the views are registered from the smoothed frame's points, the grid and the model
    /// keep the averaged frame's. The camera's noise along its rays leaves registered views
    /// 1–3 mm too deep on curved objects; the fit takes most of it out (benches/README,
    /// "Smoothing the registration's input"). Default 2 (5 × 5 pixels); 0 registers the
    /// averaged frame's points (the previous release). Unused where `[nbv]
    /// depth_smoothing` already smooths the frame.
    pub smoothing: u32,
    /// Match each camera point to the laser cluster where its viewing ray crosses the
    /// cluster's surface, not at its nearest laser point (projective association): the
    /// camera's centimetre noise lies along its rays, and on a curved object the nearest
    /// point of a displaced camera point lies off its ray, on a plane tilted towards it.
    /// The registration converges by nearest points first, then refines along the rays.
    /// Default false (nearest points only): true lowers the alignment error in Table III
    /// and on held-out seeds but costs ~1.6× the registration's time (benches/README,
    /// "What limits a camera view's registration").
    pub along_rays: bool,
    /// Refine each object's final MAP registration along the camera's rays: started where
    /// it ended (after the self-calibration's passes), with the same priors, each camera
    /// point matched where its viewing ray crosses the laser cluster. What `along_rays`
    /// does in its last stages, once per object instead of in every pass, at about a tenth
    /// of an episode's time instead of ~1.6× the registration's; the hand-eye estimate is
    /// the passes' (benches/README, "Refining along the rays once"). Default true; false is
    /// the previous release (nearest points only).
    pub refine_along_rays: bool,
    /// Register each object's views against every laser point the cluster's 5 mm voxels
    /// hold, as measured, instead of the voxel centroids the segmentation keeps (the
    /// model keeps the centroids). A centroid lies inside a curved surface and rounds a
    /// rim off, and near the scanner a voxel holds several points. With the hand-eye
    /// error alone and a tenth of the scenes' sensor noise, the measured points take the
    /// hand-eye estimate from 0.130° to 0.049° off and the models from 0.53 to 0.33 mm;
    /// with the scenes' errors and a tenth of the laser's noise, the models from 1.24 to
    /// 1.11 mm; at the scenes' own noise the two are even (0.127° and 1.24 mm with the
    /// centroids, 0.130° and 1.25 mm measured) — benches/README, "The registration's
    /// reference". Default false (the centroids).
    pub measured_reference: bool,
    /// Run the paper's p-ICP-GPA and sequential ICP beside the model's MAP registration,
    /// for the report's comparison (`error_pgpa`, `error_icp`) and Table III. They do not
    /// change the model; turning them off makes an episode several times cheaper in CPU
    /// (sweeps that tune exploration, not registration). Default true.
    pub baselines: bool,
}

impl Default for Registration {
    fn default() -> Self {
        Self {
            d_max: 0.03,
            max_iterations: 100,
            tolerance: 1e-6,
            points_per_view: 2000,
            max_correction_deg: 5.0,
            max_correction_m: 0.03,
            align_to_workcell: true,
            calibrate_hand_eye: true,
            table_evidence: true,
            free_space: true,
            camera_free_space: true,
            smoothing: 2,
            along_rays: false,
            refine_along_rays: true,
            measured_reference: false,
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
        c.within(
            "registration.smoothing",
            self.smoothing.into(),
            0.0,
            8.0,
            "[0, 8] pixels",
        )?;
        Ok(())
    }
}
