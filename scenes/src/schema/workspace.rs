//! [`Workspace`]: the box covered by the occupancy grid, and its resolution.

use super::Check;
use crate::error::{Problem, SceneError};
use serde::{Deserialize, Serialize};

/// The occupancy-grid workspace (world frame = robot base frame).
///
/// The paper's grid is 1.40 × 1.20 × 0.60 m at 0.02 m (70 × 60 × 30 = 126K voxels); the
/// paper scenes place it at x ∈ [0.30, 1.50], y ∈ [−0.70, 0.70], z ∈ [0.23, 0.83], which
/// includes one voxel layer at the table top.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Workspace {
    /// Lower corner `[x, y, z]` (m). Required.
    pub min: [f64; 3],
    /// Upper corner `[x, y, z]` (m), above `min` on every axis. Required.
    pub max: [f64; 3],
    /// Voxel edge length (m); must divide every side of the box. Default 0.02 (paper).
    #[serde(default = "default_resolution")]
    pub resolution: f64,
}

fn default_resolution() -> f64 {
    0.02
}

impl Workspace {
    /// Number of voxels along x, y and z (`round(side / resolution)`; validation checks
    /// that the division is exact).
    ///
    /// ```
    /// use nbv_scenes::schema::Workspace;
    /// let w = Workspace { min: [0.30, -0.70, 0.23], max: [1.50, 0.70, 0.83], resolution: 0.02 };
    /// assert_eq!(w.dims(), [60, 70, 30]);
    /// ```
    pub fn dims(&self) -> [usize; 3] {
        [0, 1, 2].map(|a| {
            let n = ((self.max[a] - self.min[a]) / self.resolution).round();
            if n.is_finite() && n > 0.0 {
                n as usize
            } else {
                0
            }
        })
    }

    /// Total number of voxels.
    pub fn voxel_count(&self) -> usize {
        self.dims().iter().product()
    }

    /// Whether the point lies in the box (bounds included, with tolerance `tol`).
    pub fn contains(&self, p: &[f64; 3], tol: f64) -> bool {
        (0..3).all(|a| p[a] >= self.min[a] - tol && p[a] <= self.max[a] + tol)
    }
}

/// Largest grid accepted (voxels).
const MAX_VOXELS: usize = 100_000_000;

impl Workspace {
    /// Checks every value of `[workspace]`; the error names the key.
    pub(crate) fn check(&self, c: &Check) -> Result<(), SceneError> {
        c.boxed("workspace", self.min, self.max)?;
        c.positive("workspace.resolution", self.resolution)?;
        for a in 0..3 {
            let side = self.max[a] - self.min[a];
            let n = side / self.resolution;
            if (n - n.round()).abs() > 1e-6 * n.max(1.0) || n.round() < 1.0 {
                return Err(c.err(
                    "workspace.resolution",
                    Problem::ResolutionNotDividing {
                        resolution: self.resolution,
                        side,
                        axis: ['x', 'y', 'z'][a],
                    },
                ));
            }
        }
        let voxels = self
            .dims()
            .iter()
            .try_fold(1usize, |acc, &d| acc.checked_mul(d));
        match voxels {
            Some(v) if v <= MAX_VOXELS => {}
            other => {
                return Err(c.err(
                    "workspace",
                    Problem::GridTooLarge(other.unwrap_or(usize::MAX)),
                ));
            }
        }
        Ok(())
    }
}
