//! [`ExplorationMap`]: what the exploration keeps of the workspace between views — the
//! log-odds grid, its reduced map M̄ and, when the view objective reads them, the
//! occlusion distances behind measured surface — and its update by one view.

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
        })
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
