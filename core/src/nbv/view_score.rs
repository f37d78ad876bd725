//! [`ScoreWeights`]: the objective of eq. (4), `α_u·|O_v^u| + α_o·|O_v^o|`.

use super::{NbvError, VisibleVoxels};

/// The weights (α_u, α_o) of eq. (4); the paper uses (4, 1): unknown voxels (new surface)
/// count four times as much as occupied ones (overlap with what is known, which
/// registration needs).
///
/// ```
/// use nbv_core::nbv::{ScoreWeights, VisibleVoxels};
/// let v = VisibleVoxels { unknown: vec![1, 2, 3], occupied: vec![7, 9], ..Default::default() };
/// assert_eq!(ScoreWeights::default().score(&v), 4.0 * 3.0 + 2.0);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScoreWeights {
    /// α_u, weight of unknown voxels (≥ 0).
    pub unknown: f64,
    /// α_o, weight of occupied voxels (≥ 0).
    pub occupied: f64,
}

impl Default for ScoreWeights {
    fn default() -> Self {
        Self {
            unknown: 4.0,
            occupied: 1.0,
        }
    }
}

impl ScoreWeights {
    /// Checks that both weights are finite and non-negative.
    pub fn validate(&self) -> Result<(), NbvError> {
        for (name, value) in [("alpha_u", self.unknown), ("alpha_o", self.occupied)] {
            if !(value.is_finite() && value >= 0.0) {
                return Err(NbvError::InvalidParameter {
                    name,
                    value,
                    reason: "must be finite and >= 0",
                });
            }
        }
        Ok(())
    }

    /// Eq. (4) for one viewpoint.
    pub fn score(&self, visible: &VisibleVoxels) -> f64 {
        self.unknown * visible.unknown.len() as f64 + self.occupied * visible.occupied.len() as f64
    }
}
