//! [`Mapping`]: the log-odds occupancy grid's sensor model and thresholds.

use super::Check;
use crate::error::{Problem, SceneError};
use serde::{Deserialize, Serialize};

/// Occupancy update of eq. (1)–(2): `+u` at the hit voxel, `−u` along the ray, with
/// `u = ln(p_hit / (1 − p_hit))`, clamped; states by `ε_o` (occupied `o > ε_o`, unknown
/// `|o| ≤ ε_o`, empty `o < −ε_o`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Mapping {
    /// The paper's `p̄` ∈ (0.5, 1). Default 0.7 (OctoMap's hit probability).
    pub p_hit: f64,
    /// Unknown band `ε_o` (log-odds), below `u` so one observation decides a voxel.
    /// Default 0.4.
    pub epsilon_o: f64,
    /// Log-odds clamping `[min, max]`. Default `[-2.0, 3.5]` (OctoMap's 0.1192 / 0.971).
    pub clamp: [f64; 2],
    /// Free space (m along the ray) that a depth pixel without a return in any frame of a
    /// view's burst clears, away from the image's returns and short of the surfaces the
    /// grid already holds (`nbv_core::rig::no_return_pixels`,
    /// `nbv_core::occupancy::OccupancyGrid::insert_scan`); 0 clears nothing. In
    /// `[0, sensors.short_range.range[1]]`. Default 0 (off; measured in docs/mapping.md,
    /// "Free space where the camera returns nothing"). For the Dinast, 0.75: its far limit
    /// (0.8 m) less its 5 cm `range_margin`, within which a surface in view returns.
    pub no_return_clearing: f64,
}

impl Default for Mapping {
    fn default() -> Self {
        Self {
            p_hit: 0.7,
            epsilon_o: 0.4,
            clamp: [-2.0, 3.5],
            no_return_clearing: 0.0,
        }
    }
}

impl Mapping {
    /// The log-odds increment `u = ln(p_hit / (1 − p_hit))`.
    ///
    /// ```
    /// let u = nbv_scenes::schema::Mapping::default().log_odds_hit();
    /// assert!((u - 0.8473).abs() < 1e-4);
    /// ```
    pub fn log_odds_hit(&self) -> f64 {
        (self.p_hit / (1.0 - self.p_hit)).ln()
    }
}

impl Mapping {
    /// Checks every value of `[mapping]`; the error names the key.
    pub(crate) fn check(&self, c: &Check) -> Result<(), SceneError> {
        c.within(
            "mapping.p_hit",
            self.p_hit,
            0.5 + 1e-9,
            1.0 - 1e-9,
            "(0.5, 1)",
        )?;
        let u = self.log_odds_hit();
        c.within(
            "mapping.epsilon_o",
            self.epsilon_o,
            0.0,
            u - 1e-9,
            &format!("[0, u) with u = ln(p_hit/(1-p_hit)) = {u:.4}"),
        )?;
        c.finite("mapping.clamp", &self.clamp)?;
        if !(self.clamp[0] < -self.epsilon_o && self.clamp[1] > self.epsilon_o) {
            return Err(c.err(
                "mapping.clamp",
                Problem::OutOfRange {
                    value: format!("[{}, {}]", self.clamp[0], self.clamp[1]),
                    expected: "min < -epsilon_o and max > epsilon_o".into(),
                },
            ));
        }
        Ok(())
    }
}
