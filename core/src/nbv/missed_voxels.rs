//! [`MissedVoxels`]: the unknown voxels of the reduced map that taken views predicted they
//! would observe and did not — an object's inside, its contact with the table, the gap
//! behind an obstacle, surface at grazing angles. Eq. (4) counts every unknown voxel a
//! candidate's rays reach, so such voxels keep attracting views that add nothing; after
//! `limit` misses a voxel no longer counts in |O_v^u| (it still blocks the predicted rays
//! and remains an obstacle for planning). `limit = 0` keeps eq. (4) as printed.

use crate::occupancy::{OccupancyGrid, VoxelState};
use std::collections::HashMap;

/// Misses per unknown voxel, and how many make a voxel stop counting.
///
/// ```
/// use nbv_core::nbv::MissedVoxels;
/// let mut missed = MissedVoxels::new(2);
/// missed.record(&[3, 4], |v| v == 3); // voxel 3 stayed unknown, 4 was observed
/// assert!(!missed.ignored(3));
/// missed.record(&[3], |_| true);
/// assert!(missed.ignored(3) && !missed.ignored(4));
/// assert!(!MissedVoxels::new(0).ignored(3)); // off
/// ```
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct MissedVoxels {
    limit: u32,
    misses: HashMap<usize, u32>,
}

impl MissedVoxels {
    /// No miss yet; a voxel stops counting after `limit` misses (0: never).
    pub fn new(limit: u32) -> Self {
        Self {
            limit,
            misses: HashMap::new(),
        }
    }

    /// After a view: of the unknown voxels it was predicted to observe (`predicted`,
    /// linear indices), those `still_unknown` counts one miss more.
    pub fn record(&mut self, predicted: &[usize], still_unknown: impl Fn(usize) -> bool) {
        if self.limit == 0 {
            return;
        }
        for &v in predicted {
            if still_unknown(v) {
                *self.misses.entry(v).or_insert(0) += 1;
            }
        }
    }

    /// [`record`](Self::record) against the grid after the view's update.
    pub fn record_in(&mut self, predicted: &[usize], grid: &OccupancyGrid) {
        self.record(predicted, |v| {
            grid.state_linear(v) == Some(VoxelState::Unknown)
        });
    }

    /// Whether voxel `v` no longer counts in eq. (4).
    pub fn ignored(&self, v: usize) -> bool {
        self.limit > 0 && self.misses.get(&v).is_some_and(|&m| m >= self.limit)
    }
}
