//! [`ExplorationMap`]: what the exploration keeps of the workspace between views — the
//! log-odds grid, its reduced map M̄ and, when the view objective reads them, the
//! occlusion distances behind measured surface — and its update by one view.

use super::ObjectRegion;
use crate::cloud::PointCloud;
use crate::nbv::{GainMap, Objective};
use crate::occupancy::{FreeRay, OcclusionDistances, OccupancyError, OccupancyGrid, ReducedMap};

/// The map the object loop scores candidates on and updates with each view.
#[derive(Debug, Clone)]
pub struct ExplorationMap {
    /// The log-odds grid.
    pub grid: OccupancyGrid,
    /// Its reduced map (eq. (4)'s O_v and the planner's obstacles), kept up to date.
    pub reduced: ReducedMap,
    /// Steps behind measured surface, kept only for the objectives that read them
    /// ([`Objective::needs_occlusion`]).
    pub occlusion: Option<OcclusionDistances>,
    /// The height (world z, m) above which the planner takes unknown space as free: above
    /// every object phase 1 found ([`NbvParams::free_above_objects`]); `None`: every
    /// unknown voxel of M̄ is an obstacle.
    ///
    /// [`NbvParams::free_above_objects`]: crate::nbv::NbvParams::free_above_objects
    pub free_above: Option<f64>,
}

impl ExplorationMap {
    /// The map after phase 1: its grid, and for `objective`s that need them the occlusion
    /// distances behind the phase-1 cloud's points (through its origins).
    pub fn after_phase_one(
        grid: OccupancyGrid,
        cloud: &PointCloud,
        objective: Objective,
    ) -> Result<Self, OccupancyError> {
        let occlusion = if objective.needs_occlusion() {
            let mut marks = OcclusionDistances::new(grid.geometry().len());
            marks.mark_cloud(&grid, cloud)?;
            Some(marks)
        } else {
            None
        };
        Ok(Self {
            reduced: ReducedMap::from_grid(&grid),
            grid,
            occlusion,
            free_above: None,
        })
    }

    /// Sets [`free_above`](Self::free_above) to the highest top of the objects' `regions`
    /// when `free_above_objects` ([`NbvParams::free_above_objects`]), else to `None`: the
    /// objects stand on the table and phase 1 saw each one's top, so nothing unknown
    /// stands higher.
    ///
    /// [`NbvParams::free_above_objects`]: crate::nbv::NbvParams::free_above_objects
    ///
    /// ```
    /// use nalgebra::Point3;
    /// use nbv_core::cloud::PointCloud;
    /// use nbv_core::nbv::Objective;
    /// use nbv_core::occupancy::{GridGeometry, OccupancyGrid, OccupancyParams};
    /// use nbv_core::pipeline::{ExplorationMap, ObjectRegion};
    /// // Two columns of ten 10 cm voxels, x = 0 seen empty, x = 1 unknown: its crust.
    /// let g = GridGeometry::from_dims(Point3::origin(), 0.1, [2, 1, 10]).unwrap();
    /// let log_odds = (0..20).map(|l| if l % 2 == 0 { -1.0 } else { 0.0 }).collect();
    /// let grid = OccupancyGrid::from_log_odds(g, OccupancyParams::default(), log_odds).unwrap();
    /// let mut map = ExplorationMap::after_phase_one(grid, &PointCloud::default(), Objective::Paper).unwrap();
    /// let region = |top: f64| ObjectRegion {
    ///     min: Point3::new(0.0, 0.0, 0.0), max: Point3::new(0.1, 0.1, top), table: Some(0.0), top,
    /// };
    /// map.set_free_above(&[region(0.25), region(0.42)], true);
    /// assert_eq!(map.free_above, Some(0.42));
    /// // The unknown voxels from z = 0.5 up lie wholly above the higher object.
    /// assert_eq!(map.unknown_above_objects(), vec![11, 13, 15, 17, 19]);
    /// map.set_free_above(&[region(0.25)], false);
    /// assert!(map.unknown_above_objects().is_empty());
    /// ```
    pub fn set_free_above(&mut self, regions: &[ObjectRegion], free_above_objects: bool) {
        self.free_above = regions
            .iter()
            .map(|r| r.max.z)
            .reduce(f64::max)
            .filter(|_| free_above_objects);
    }

    /// The unknown voxels of M̄ lying wholly above [`free_above`](Self::free_above): those
    /// the planner does not take as obstacles (none when it is `None`).
    pub fn unknown_above_objects(&self) -> Vec<usize> {
        let Some(z) = self.free_above else {
            return Vec::new();
        };
        let g = self.reduced.geometry();
        let half = 0.5 * g.resolution();
        self.reduced
            .unknown()
            .iter()
            .copied()
            .filter(|&l| g.unlinear(l).is_some_and(|v| g.center(v).z - half >= z))
            .collect()
    }

    /// Inserts one frame (a cloud with origins; rays beyond `max_range` clear free space
    /// only) with the rays that returned nothing (`free`, see
    /// [`OccupancyGrid::insert_scan`]), then marks the voxels behind its points and
    /// refreshes the reduced map.
    pub fn insert(
        &mut self,
        frame: &PointCloud,
        max_range: f64,
        free: &[FreeRay],
    ) -> Result<(), OccupancyError> {
        self.grid.insert_cloud(frame, max_range, free)?;
        if let Some(marks) = &mut self.occlusion {
            marks.mark_cloud(&self.grid, frame)?;
        }
        self.reduced = ReducedMap::from_grid(&self.grid);
        Ok(())
    }

    /// What the information-gain objectives read.
    pub fn gains(&self) -> GainMap<'_> {
        GainMap {
            grid: &self.grid,
            occlusion: self.occlusion.as_ref(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::occupancy::{GridGeometry, OccupancyParams};
    use nalgebra::Point3;

    #[test]
    fn occlusion_kept_only_when_read_and_updated_with_the_grid() {
        let g = GridGeometry::from_dims(Point3::origin(), 0.1, [8, 1, 1]).unwrap();
        let grid = OccupancyGrid::new(g, OccupancyParams::default()).unwrap();
        let mut frame = PointCloud::from_points(vec![Point3::new(0.25, 0.05, 0.05)]);
        frame.origins = Some(vec![Point3::new(-1.0, 0.05, 0.05)]);
        let empty = PointCloud::default();
        let paper =
            ExplorationMap::after_phase_one(grid.clone(), &empty, Objective::Paper).unwrap();
        assert!(paper.occlusion.is_none());
        let mut pc =
            ExplorationMap::after_phase_one(grid, &empty, Objective::ProximityCount).unwrap();
        pc.insert(&frame, 5.0, &[]).unwrap();
        assert_eq!(
            pc.occlusion.as_ref().unwrap().steps()[..6],
            [0, 0, 0, 1, 2, 3]
        );
        assert_eq!(pc.reduced.occupied(), &[2]);
        assert!(pc.gains().occlusion.is_some());
    }
}
