//! [`ExploreConfig`]: every parameter of the pipeline, and [`ExploreMode`], the method or
//! one of its baselines.

use crate::kinematics::Joints;
use crate::nbv::{NbvParams, StopRule};
use crate::perception::PhaseOneConfig;
use crate::planning::{Obstacle, PlannerConfig};
use crate::registration::RegistrationParams;

/// Height (m) of the camera above the table top during the short-only survey: the Dinast
/// (0.1–0.8 m) sees the table and objects up to 0.35 m tall from there.
pub const SURVEY_HEIGHT: f64 = 0.45;
/// Largest spacing (m) between survey poses: the camera's footprint at [`SURVEY_HEIGHT`] is
/// about 0.75 × 0.54 m, so neighbouring frames overlap.
pub const SURVEY_SPACING: f64 = 0.35;

/// Which sensors the exploration uses.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum ExploreMode {
    /// The paper's hybrid method: the laser sweep, then next-best views with the camera.
    #[default]
    Hybrid,
    /// The laser sweep only: each object's model is its phase-1 cluster.
    MidOnly,
    /// No laser: the camera surveys the workspace from [`ExploreConfig::survey`] (moving
    /// through space no sensor has seen: only the known obstacles are avoided), the
    /// survey's cloud is segmented and mapped as phase 1 would, then each object is
    /// explored with next-best views as in the hybrid method.
    ShortOnly,
}

impl ExploreMode {
    /// The name used on the command line and in reports (`hybrid`, `mid-only`, `short-only`).
    pub fn name(self) -> &'static str {
        match self {
            Self::Hybrid => "hybrid",
            Self::MidOnly => "mid-only",
            Self::ShortOnly => "short-only",
        }
    }
}

/// Everything [`explore`](super::explore) needs besides the rig and the robot model.
#[derive(Debug, Clone, PartialEq)]
pub struct ExploreConfig {
    /// The method or a baseline.
    pub mode: ExploreMode,
    /// Camera poses (world frame) of the short-only survey, in order; each is tried with
    /// the NBV rolls about its optical axis.
    pub survey: Vec<crate::math::Pose>,
    /// The sweep's joint waypoints (the first is reached without scanning).
    pub sweep: Vec<Joints>,
    /// Speed fraction of the sweep (0, 1].
    pub sweep_speed: f64,
    /// Segmentation, grid and occupancy model of phase 1.
    pub phase_one: PhaseOneConfig,
    /// Algorithm 2's parameters.
    pub nbv: NbvParams,
    /// When an object is done.
    pub stop: StopRule,
    /// Visited-view thresholds: distance (m) and angle (rad) between sensor poses.
    pub visited: (f64, f64),
    /// Depth frames captured and averaged at each viewpoint (1: a single frame).
    pub frames_per_view: usize,
    /// A pixel of the averaged frame is kept where more than this share of the burst's
    /// frames returned ([`average_frames`](crate::rig::average_frames)), in [0, 1).
    pub return_share: f64,
    /// Half-width (pixels) of the plane fit that smooths each averaged frame
    /// ([`smooth_frame`](crate::rig::smooth_frame)); 0 leaves it as averaged.
    pub depth_smoothing: usize,
    /// Length (m) of free space a view's depth pixel without a return in any frame of
    /// its burst clears along its ray (away from the image's returns, short of the
    /// surfaces the grid knows: [`no_return_pixels`](crate::rig::no_return_pixels),
    /// [`OccupancyGrid::insert_scan`](crate::occupancy::OccupancyGrid::insert_scan));
    /// 0 clears nothing.
    pub no_return_clearing: f64,
    /// Hard cap on short-range views per object.
    pub max_views_per_object: usize,
    /// The joint-space planner.
    pub planner: PlannerConfig,
    /// Obstacles the robot knows besides the map (the table, known obstacles), in the
    /// world frame.
    pub obstacles: Vec<Obstacle>,
    /// Registration parameters (method and reference are set per run).
    pub registration: RegistrationParams,
    /// Correct the laser sweep's pose by the workcell it sees (the table top and the
    /// known obstacles in `obstacles`) before segmenting it
    /// ([`align_to_workcell`](crate::perception::align_to_workcell)).
    pub align_to_workcell: bool,
    /// Estimate the depth camera's hand-eye correction and the joint offsets from every
    /// object's registration and each view's table evidence
    /// ([`TableEvidence`](crate::calibration::TableEvidence)), and register each object again from the
    /// calibrated poses ([`estimate_hand_eye`](crate::calibration::estimate_hand_eye)).
    pub calibrate_hand_eye: bool,
    /// Camera views the self-calibration reads at least, per episode: with
    /// `calibrate_hand_eye`, an object whose exploration leaves the episode short of them
    /// takes more views of it for the calibration alone
    /// ([`ObjectExploration::calibration_views`]).
    ///
    /// [`ObjectExploration::calibration_views`]: super::ObjectExploration::calibration_views
    pub calibration_views: usize,
    /// Register each object by the paper's p-ICP-GPA and sequential ICP too, beside the
    /// model's MAP registration (for comparison only: the model does not use them).
    pub registration_baselines: bool,
    /// The sensors' noise and pose uncertainty: the MAP registration's weights and priors.
    pub uncertainty: crate::calibration::PoseUncertainty,
    /// Points per view kept for registration (views are subsampled evenly); 0 keeps all.
    pub registration_points: usize,
    /// Largest correction the paper's p-ICP-GPA and sequential ICP may apply to a view's
    /// reported pose: rotation (rad) and displacement of the view's centroid (m). Beyond
    /// it their registration is rejected (the MAP registration has its χ² gate instead).
    pub max_correction: (f64, f64),
    /// Margin (m) around an object's phase-1 bounding box within which short-range points
    /// belong to the object.
    pub object_margin: f64,
    /// Takes the table out of each short-range view before it joins the object's model
    /// (the noise model of the camera); `None` keeps every point above the region's floor.
    pub table_filter: Option<crate::perception::TableFilter>,
    /// The fused surface of each object's registered camera views
    /// ([`TsdfVolume`](crate::surface::TsdfVolume)); `None` makes none.
    pub surface: Option<crate::surface::TsdfParams>,
    /// Seed of every random choice the pipeline makes (the planner's samples).
    pub seed: u64,
}
