//! [`OcclusionDistances`]: per voxel, how far behind a measured surface point it lies —
//! the extra map data of the proximity-count and area-factor objectives
//! ([`Objective`](crate::nbv::Objective)), written by the map update.
//!
//! Isler et al.'s reference implementation (`rpg_ig_active_reconstruction`,
//! `octomap_ray_occlusion_calculator.inl`) marks, behind each measured point of a scan, the
//! **unmeasured** voxels along the measurement ray out to `occlusion_update_dist_m` = 0.3 m
//! with their step index behind the point (1, 2, …), keeping the minimum over scans. The
//! same here, with the grid's DDA: the walk starts at the point, the point's own voxel is
//! step 0 and is not marked. "Unmeasured" is a voxel whose log-odds is exactly the prior 0
//! (never updated, or updates that cancelled: its probability is the prior again).

use nalgebra::Point3;
use rayon::prelude::*;

use super::{OccupancyError, OccupancyGrid};
use crate::cloud::PointCloud;

/// How far behind a measured point voxels are marked (m): the reference's
/// `occlusion_update_dist_m`.
pub const OCCLUSION_UPDATE_DISTANCE: f64 = 0.3;

/// Step index behind the nearest measured surface for every voxel of a grid (0: not
/// marked).
///
/// ```
/// use nbv_core::occupancy::{GridGeometry, OccupancyGrid, OccupancyParams, OcclusionDistances};
/// use nalgebra::Point3;
/// let g = GridGeometry::from_dims(Point3::origin(), 0.1, [8, 1, 1]).unwrap();
/// let mut grid = OccupancyGrid::new(g, OccupancyParams::default()).unwrap();
/// let (o, p) = ([Point3::new(-1.0, 0.05, 0.05)], [Point3::new(0.25, 0.05, 0.05)]);
/// grid.insert_rays(&o, &p, 5.0).unwrap();
/// let mut marks = OcclusionDistances::new(grid.geometry().len());
/// marks.mark_behind(&grid, &o, &p).unwrap();
/// // Voxel 2 holds the point; 3, 4, 5 lie 1, 2, 3 steps behind it (0.3 m at 0.1 m).
/// assert_eq!(marks.steps()[..7], [0, 0, 0, 1, 2, 3, 0]);
/// assert_eq!(marks.max_steps(0.1), 6);
/// ```
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct OcclusionDistances {
    steps: Vec<u16>,
}

impl OcclusionDistances {
    /// No voxel marked, for a grid of `len` voxels.
    pub fn new(len: usize) -> Self {
        Self {
            steps: vec![0; len],
        }
    }

    /// Given steps, one per voxel in linear order (0: not marked).
    pub fn from_steps(steps: Vec<u16>) -> Self {
        Self { steps }
    }

    /// The step index of every voxel (linear order; 0: not marked).
    pub fn steps(&self) -> &[u16] {
        &self.steps
    }

    /// The marked step of voxel `linear` (0: not marked or outside).
    pub fn step(&self, linear: usize) -> u16 {
        self.steps.get(linear).copied().unwrap_or(0)
    }

    /// The reference's `maxDist` = 2·0.3 m / resolution (30 at 2 cm), rounded down.
    pub fn max_steps(&self, resolution: f64) -> u16 {
        (2.0 * OCCLUSION_UPDATE_DISTANCE / resolution + 1e-9).floor() as u16
    }

    /// Marks the unmeasured voxels of `grid` behind each point `points[i]` along its ray
    /// from `origins[i]` (call after the scan was inserted). Points outside the grid mark
    /// what lies behind them inside it. Deterministic at any thread count (minimum over
    /// rays).
    pub fn mark_behind(
        &mut self,
        grid: &OccupancyGrid,
        origins: &[Point3<f64>],
        points: &[Point3<f64>],
    ) -> Result<(), OccupancyError> {
        let g = grid.geometry();
        if self.steps.len() != g.len() {
            self.steps = vec![0; g.len()];
        }
        let values = grid.log_odds();
        let reach = OCCLUSION_UPDATE_DISTANCE + 1e-9;
        let marked = origins
            .par_iter()
            .zip(points.par_iter())
            .map(|(o, p)| -> Result<Vec<(usize, u16)>, OccupancyError> {
                let dir = p - o;
                let mut out = Vec::new();
                if dir.norm() <= 0.0 || !dir.norm().is_finite() {
                    return Ok(out);
                }
                let own = g.voxel_of(p).and_then(|v| g.linear(v));
                let mut k: u16 = 0;
                g.traverse(p, &dir, reach)?.for_each_linear(|l| {
                    if Some(l) == own {
                        return;
                    }
                    k = k.saturating_add(1);
                    if values[l] == 0.0 {
                        out.push((l, k));
                    }
                });
                Ok(out)
            })
            .collect::<Result<Vec<_>, _>>()?;
        for (l, k) in marked.into_iter().flatten() {
            let s = &mut self.steps[l];
            if *s == 0 || k < *s {
                *s = k;
            }
        }
        Ok(())
    }
}

impl OcclusionDistances {
    /// [`mark_behind`](Self::mark_behind) for a scan given as a cloud with its `origins`
    /// column; a cloud without origins marks nothing.
    pub fn mark_cloud(
        &mut self,
        grid: &OccupancyGrid,
        cloud: &PointCloud,
    ) -> Result<(), OccupancyError> {
        match cloud.origins.as_deref() {
            Some(origins) if origins.len() == cloud.points.len() => {
                self.mark_behind(grid, origins, &cloud.points)
            }
            _ => Ok(()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::occupancy::{GridGeometry, OccupancyParams};

    #[test]
    fn minimum_over_scans_and_measured_voxels_skipped() {
        let g = GridGeometry::from_dims(Point3::origin(), 0.1, [8, 1, 1]).unwrap();
        let mut grid = OccupancyGrid::new(g, OccupancyParams::default()).unwrap();
        let o = [Point3::new(-1.0, 0.05, 0.05)];
        grid.insert_rays(&o, &[Point3::new(0.25, 0.05, 0.05)], 5.0)
            .unwrap();
        let mut marks = OcclusionDistances::new(8);
        marks
            .mark_behind(&grid, &o, &[Point3::new(0.25, 0.05, 0.05)])
            .unwrap();
        assert_eq!(marks.steps(), &[0, 0, 0, 1, 2, 3, 0, 0]);
        // A later point at voxel 4: voxel 5 is now 1 behind it, 6 and 7 are 2 and 3; voxel 4
        // itself is measured (hit) and keeps its old mark.
        let p = [Point3::new(0.45, 0.05, 0.05)];
        grid.insert_rays(&o, &p, 5.0).unwrap();
        marks.mark_behind(&grid, &o, &p).unwrap();
        assert_eq!(marks.steps(), &[0, 0, 0, 1, 2, 1, 2, 3]);
        assert_eq!(marks.step(99), 0);
        assert_eq!(marks.max_steps(0.02), 30);
    }
}
