//! Log-odds arithmetic of the ray sensor model (paper eq. (1)–(2)) and the voxel states:
//! [`OccupancyParams`], [`VoxelState`], [`log_odds`], [`probability`].

use super::OccupancyError;

/// `ln(p / (1 − p))`.
///
/// ```
/// use nbv_core::occupancy::{log_odds, probability};
/// assert!((log_odds(0.7) - 0.8472978603872037).abs() < 1e-15);
/// assert!((probability(log_odds(0.3)) - 0.3).abs() < 1e-15);
/// ```
pub fn log_odds(p: f64) -> f64 {
    (p / (1.0 - p)).ln()
}

/// `p(m) = 1 / (1 + exp(−o))`, the inverse of [`log_odds`].
pub fn probability(o: f64) -> f64 {
    1.0 / (1.0 + (-o).exp())
}

/// The state of a voxel, by its log-odds `o` and the threshold `ε_o`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum VoxelState {
    /// `|o| ≤ ε_o`.
    Unknown,
    /// `o < −ε_o`.
    Empty,
    /// `o > ε_o`.
    Occupied,
}

/// Parameters of the log-odds map.
///
/// The paper's ray model is symmetric: a hit adds `u = ln(p̄/(1−p̄))` to the hit voxel and
/// a pass adds `−u` to every voxel the ray crosses before it (eq. (2)). Defaults:
/// - `hit_probability` p̄ = 0.7, OctoMap's hit probability, so u ≈ 0.847. (OctoMap's miss
///   probability 0.4 would give an asymmetric −0.405; the paper's model uses −u.)
/// - clamping to OctoMap's `[logit(0.1192), logit(0.971)]` ≈ `[−2.000, 3.511]`;
/// - `occupied_epsilon` ε_o = 0.1: well below u, so one hit or one pass decides a voxel's
///   state, and well above the f32 rounding left by cancelling updates. (The paper does not
///   give ε_o; OctoMap's occupancy threshold 0.5 corresponds to ε_o = 0.)
///
/// ```
/// use nbv_core::occupancy::{OccupancyParams, VoxelState};
/// let p = OccupancyParams::default();
/// let u = p.hit_log_odds();
/// assert_eq!(p.state(p.after_hit(0.0)), VoxelState::Occupied);
/// assert_eq!(p.state(p.after_pass(0.0)), VoxelState::Empty);
/// assert_eq!(p.after_hit(p.after_hit(p.after_hit(p.after_hit(u)))), p.clamp_max);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OccupancyParams {
    /// p̄ of eq. (1), in (0.5, 1).
    pub hit_probability: f64,
    /// Lower clamp of the log-odds, strictly below −`occupied_epsilon`.
    pub clamp_min: f32,
    /// Upper clamp of the log-odds, strictly above `occupied_epsilon`.
    pub clamp_max: f32,
    /// ε_o: the state threshold, ≥ 0.
    pub occupied_epsilon: f32,
}

impl Default for OccupancyParams {
    fn default() -> Self {
        Self {
            hit_probability: 0.7,
            clamp_min: log_odds(0.1192) as f32,
            clamp_max: log_odds(0.971) as f32,
            occupied_epsilon: 0.1,
        }
    }
}

impl OccupancyParams {
    /// Checks the ranges: `0.5 < p̄ < 1` (u finite and non-zero), finite clamps with
    /// `clamp_min < −ε_o` and `clamp_max > ε_o` (every state reachable), `ε_o ≥ 0`.
    pub fn validate(&self) -> Result<(), OccupancyError> {
        let bad = |name, value: f64, reason| {
            Err(OccupancyError::InvalidParameter {
                name,
                value,
                reason,
            })
        };
        let p = self.hit_probability;
        if !(p > 0.5 && p < 1.0 && (log_odds(p) as f32).is_finite()) {
            return bad("hit_probability", p, "must be in (0.5, 1)");
        }
        let eps = self.occupied_epsilon;
        if !(eps.is_finite() && eps >= 0.0) {
            return bad("occupied_epsilon", eps.into(), "must be finite and >= 0");
        }
        if !(self.clamp_min.is_finite() && self.clamp_min < -eps) {
            return bad(
                "clamp_min",
                self.clamp_min.into(),
                "must be finite and < -occupied_epsilon",
            );
        }
        if !(self.clamp_max.is_finite() && self.clamp_max > eps) {
            return bad(
                "clamp_max",
                self.clamp_max.into(),
                "must be finite and > occupied_epsilon",
            );
        }
        Ok(())
    }

    /// `u = ln(p̄/(1−p̄))`, the log-odds added by a hit (and subtracted by a pass).
    pub fn hit_log_odds(&self) -> f32 {
        log_odds(self.hit_probability) as f32
    }

    /// Log-odds after one hit: `clamp(o + u)`.
    pub fn after_hit(&self, o: f32) -> f32 {
        (o + self.hit_log_odds()).clamp(self.clamp_min, self.clamp_max)
    }

    /// Log-odds after one pass: `clamp(o − u)`.
    pub fn after_pass(&self, o: f32) -> f32 {
        (o - self.hit_log_odds()).clamp(self.clamp_min, self.clamp_max)
    }

    /// The state of a voxel of log-odds `o`.
    pub fn state(&self, o: f32) -> VoxelState {
        if o > self.occupied_epsilon {
            VoxelState::Occupied
        } else if o < -self.occupied_epsilon {
            VoxelState::Empty
        } else {
            VoxelState::Unknown
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_octomap_numbers() {
        let p = OccupancyParams::default();
        assert_eq!(p.validate(), Ok(()));
        assert!((p.hit_log_odds() - 0.847_297_9).abs() < 1e-6);
        assert!((p.clamp_min - (-2.000_028)).abs() < 1e-5);
        assert!((p.clamp_max - 3.511_031).abs() < 1e-5);
        assert!((probability(p.clamp_min.into()) - 0.1192).abs() < 1e-7);
        assert!((probability(p.clamp_max.into()) - 0.971).abs() < 1e-7);
    }

    #[test]
    fn updates_add_u_and_clamp() {
        let p = OccupancyParams::default();
        let u = p.hit_log_odds();
        assert_eq!(p.after_hit(0.0), u);
        assert_eq!(p.after_pass(0.0), -u);
        assert_eq!(p.after_pass(p.after_hit(0.0)), 0.0);
        // Four hits saturate at the upper clamp (4u ≈ 3.39 < 3.51 < 5u).
        let mut o = 0.0;
        let mut seq = Vec::new();
        for _ in 0..6 {
            o = p.after_hit(o);
            seq.push(o);
        }
        assert!((seq[3] - 4.0 * u).abs() < 1e-6);
        assert_eq!(seq[4], p.clamp_max);
        assert_eq!(seq[5], p.clamp_max);
        // Three passes saturate at the lower clamp (2u ≈ 1.69 < 2.00 < 3u).
        let o = p.after_pass(p.after_pass(p.after_pass(0.0)));
        assert_eq!(o, p.clamp_min);
        // From saturation one hit brings a free voxel back towards unknown.
        assert!((p.after_hit(p.clamp_min) - (p.clamp_min + u)).abs() < 1e-7);
        assert_eq!(p.state(p.after_hit(p.clamp_min)), VoxelState::Empty);
    }

    #[test]
    fn states_by_epsilon() {
        let p = OccupancyParams::default();
        assert_eq!(p.state(0.1), VoxelState::Unknown);
        assert_eq!(p.state(-0.1), VoxelState::Unknown);
        assert_eq!(p.state(0.100_001), VoxelState::Occupied);
        assert_eq!(p.state(-0.100_001), VoxelState::Empty);
        assert_eq!(p.state(0.0), VoxelState::Unknown);
    }

    #[test]
    fn invalid_parameters() {
        let d = OccupancyParams::default();
        for bad in [
            OccupancyParams {
                hit_probability: 0.5,
                ..d
            },
            OccupancyParams {
                hit_probability: 1.0,
                ..d
            },
            OccupancyParams {
                hit_probability: f64::NAN,
                ..d
            },
            OccupancyParams {
                clamp_min: 0.0,
                ..d
            },
            OccupancyParams {
                clamp_max: f32::INFINITY,
                ..d
            },
            OccupancyParams {
                occupied_epsilon: -0.1,
                ..d
            },
            OccupancyParams {
                occupied_epsilon: 5.0,
                ..d
            },
        ] {
            assert!(matches!(
                bad.validate(),
                Err(OccupancyError::InvalidParameter { .. })
            ));
        }
    }
}
