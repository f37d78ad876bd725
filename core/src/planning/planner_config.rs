//! [`PlannerConfig`]: the parameters of the joint-space planner, with their defaults and
//! where they come from.

use std::f64::consts::PI;

use super::PlanningError;

/// Parameters of [`MotionPlanner`](super::MotionPlanner).
///
/// Defaults and their sources (OpenRAVE's and OMPL's documented defaults):
/// - `max_iterations` 4000: OpenRAVE's BiRRT budget, the planner of the paper's era;
/// - `step` 0.2 rad (Euclidean norm in joint space): OMPL's RRT-Connect extends by 0.2 ×
///   the joint-space extent (about 2.5 rad for this arm's windowed ranges); OpenRAVE's
///   0.04 rad grows the trees so slowly that a view near an object and an obstacle took
///   more than 4000 iterations to reach: over the paper scenes and twenty generated
///   layouts at ×1 and ×3 (44 episodes), 0.04 rad failed 348 plans and spent 127 s
///   planning; 0.2 rad, with the way in cleared
///   ([`MotionPlanner::clear_way`](super::MotionPlanner::clear_way)), failed none in 41 s. Edge resolution is set separately by
///   `max_link_displacement`, so the step only trades tree size against the cost of each
///   extension;
/// - `max_link_displacement` 0.01 m: half of the paper's 2 cm voxel, the largest motion of
///   any point of the robot between two checked configurations (see
///   [`MotionBound`](super::MotionBound)); OpenRAVE checks edges at 0.02 rad, which for the
///   1.6 m lever arm of J1 is 3 cm;
/// - `shortcut_iterations` 50: within OpenRAVE's 20–100 shortcut iterations;
/// - `interpolation_step` none: the path is returned with its corner waypoints only;
/// - `wide_joint_window` π: joints whose range exceeds 2π (the Comau's J4 ±210°, J6
///   ±2700°) are sampled only within π of the start and goal values, and each goal's value
///   of such a joint is moved by whole turns next to the start's — otherwise J6's 94 rad
///   range would dominate joint-space distances;
/// - `speed_fraction` 0.2: the paper moves the robot "at relatively low speed" without a
///   figure.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlannerConfig {
    /// Iterations (samples) of RRT-Connect before giving up (≥ 1).
    pub max_iterations: usize,
    /// Extension step (rad, joint-space Euclidean norm), > 0.
    pub step: f64,
    /// Largest displacement (m) of any robot point between two checked configurations, > 0.
    pub max_link_displacement: f64,
    /// Shortcut attempts on the found path.
    pub shortcut_iterations: usize,
    /// If set, the final path is resampled so consecutive waypoints are at most this far
    /// apart (rad, joint-space Euclidean norm), > 0.
    pub interpolation_step: Option<f64>,
    /// Sampling window (rad) around start and goals for joints with ranges over 2π, > 0.
    pub wide_joint_window: f64,
    /// Fraction (0, 1] of the joint speed limits for the returned path.
    pub speed_fraction: f64,
}

impl Default for PlannerConfig {
    fn default() -> Self {
        Self {
            max_iterations: 4000,
            step: 0.2,
            max_link_displacement: 0.01,
            shortcut_iterations: 50,
            interpolation_step: None,
            wide_joint_window: PI,
            speed_fraction: 0.2,
        }
    }
}

impl PlannerConfig {
    /// Checks the ranges given in the field docs.
    pub fn validate(&self) -> Result<(), PlanningError> {
        let bad = |name, value, reason| {
            Err(PlanningError::InvalidConfig {
                name,
                value,
                reason,
            })
        };
        let positive = |v: f64| v.is_finite() && v > 0.0;
        if self.max_iterations == 0 {
            return bad("max_iterations", 0.0, "must be >= 1");
        }
        if !positive(self.step) {
            return bad("step", self.step, "must be finite and > 0");
        }
        if !positive(self.max_link_displacement) {
            return bad(
                "max_link_displacement",
                self.max_link_displacement,
                "must be finite and > 0",
            );
        }
        if let Some(s) = self.interpolation_step
            && !positive(s)
        {
            return bad("interpolation_step", s, "must be finite and > 0");
        }
        if !positive(self.wide_joint_window) {
            return bad(
                "wide_joint_window",
                self.wide_joint_window,
                "must be finite and > 0",
            );
        }
        if !(self.speed_fraction > 0.0 && self.speed_fraction <= 1.0) {
            return bad("speed_fraction", self.speed_fraction, "must be in (0, 1]");
        }
        Ok(())
    }
}
