//! The scene's sections as the pipeline's parameter types: the workspace as a
//! [`GridGeometry`], `[mapping]` as [`OccupancyParams`], `[segmentation]` as
//! [`SegmentationParams`], and the whole of phase 1 as a [`PhaseOneConfig`] — of a scene,
//! or without one ([`default_phase_one_config`]).

use crate::error::{Problem, SceneError};
use crate::placed::obstacle_local_mesh;
use crate::scene::Scene;
use crate::schema::{Mapping, MidRangeSensor, Segmentation, Workspace};
use nalgebra::{Isometry3, Point3, Vector3};
use nbv_core::math::Pose;
use nbv_core::occupancy::{GridGeometry, OccupancyError, OccupancyParams};
use nbv_core::perception::{OrientedBox, PhaseOneConfig, SegmentationParams};

/// The paper's workspace: x ∈ [0.30, 1.50], y ∈ [−0.70, 0.70], z ∈ [0.23, 0.83] m at
/// 0.02 m (one voxel layer at the table top).
pub const PAPER_WORKSPACE: Workspace = Workspace {
    min: [0.30, -0.70, 0.23],
    max: [1.50, 0.70, 0.83],
    resolution: 0.02,
};

/// Phase 1 without a scene (`nbv map` without `--scene`): the grid over
/// [`PAPER_WORKSPACE`], the scene schema's `[segmentation]` and `[mapping]` defaults, the
/// mid-range sensor's default maximum range, the workspace as the region and nothing
/// excluded.
///
/// ```
/// let c = nbv_scenes::pipeline_params::default_phase_one_config().unwrap();
/// assert_eq!(c.grid.len(), 126_000);
/// assert_eq!(c.max_range, 3.0);
/// assert!(c.exclude.is_empty());
/// ```
pub fn default_phase_one_config() -> Result<PhaseOneConfig, OccupancyError> {
    let w = PAPER_WORKSPACE;
    let grid = GridGeometry::new(Point3::from(w.min), Point3::from(w.max), w.resolution)?;
    let mut config = PhaseOneConfig::new(grid);
    config.segmentation = Segmentation::default().params(SegmentationParams::default().seed);
    config.occupancy = Mapping::default().occupancy_params();
    config.max_range = MidRangeSensor::default().range[1];
    Ok(config)
}

impl Workspace {
    /// The grid's lattice: `dims()` voxels of `resolution` from `min`.
    ///
    /// ```
    /// use nbv_scenes::schema::Workspace;
    /// let w = Workspace { min: [0.30, -0.70, 0.23], max: [1.50, 0.70, 0.83], resolution: 0.02 };
    /// let g = w.grid_geometry().unwrap();
    /// assert_eq!((g.dims(), g.len()), ([60, 70, 30], 126_000));
    /// ```
    pub fn grid_geometry(&self) -> Result<GridGeometry, nbv_core::occupancy::OccupancyError> {
        GridGeometry::from_dims(Point3::from(self.min), self.resolution, self.dims())
    }

    /// The workspace box.
    pub fn bounds(&self) -> (Point3<f64>, Point3<f64>) {
        (Point3::from(self.min), Point3::from(self.max))
    }
}

impl Mapping {
    /// The grid's log-odds parameters: p̄ = `p_hit`, the clamps, ε_o = `epsilon_o`.
    ///
    /// ```
    /// let p = nbv_scenes::schema::Mapping::default().occupancy_params();
    /// assert_eq!((p.hit_probability, p.occupied_epsilon, p.clamp_min), (0.7, 0.4, -2.0));
    /// assert!(p.validate().is_ok());
    /// ```
    pub fn occupancy_params(&self) -> OccupancyParams {
        OccupancyParams {
            hit_probability: self.p_hit,
            clamp_min: self.clamp[0] as f32,
            clamp_max: self.clamp[1] as f32,
            occupied_epsilon: self.epsilon_o as f32,
        }
    }
}

impl Segmentation {
    /// The segmentation parameters, with `seed` for RANSAC and the default table tilt limit.
    ///
    /// ```
    /// let p = nbv_scenes::schema::Segmentation::default().params(7);
    /// assert_eq!(p, nbv_core::perception::SegmentationParams { seed: 7, ..Default::default() });
    /// ```
    pub fn params(&self, seed: u64) -> SegmentationParams {
        SegmentationParams {
            voxel: self.voxel,
            outlier_neighbours: self.outlier_neighbours as usize,
            outlier_std: self.outlier_std,
            plane_distance: self.plane_distance,
            plane_iterations: self.plane_iterations as usize,
            cluster_tolerance: self.cluster_tolerance,
            min_cluster_points: self.min_cluster_points as usize,
            max_cluster_points: self.max_cluster_points as usize,
            seed,
            ..SegmentationParams::default()
        }
    }
}

impl Scene {
    /// Phase 1 as this scene defines it: its workspace grid, `[mapping]`,
    /// `[segmentation]` (RANSAC seeded with the scene seed), the mid-range sensor's maximum
    /// range, the workspace as the region, and every *known* obstacle's box (a mesh
    /// obstacle: its bounding box in its own frame) grown by the clustering tolerance as
    /// an excluded box. Unknown obstacles are not excluded: the robot cannot tell them
    /// from objects.
    ///
    /// ```
    /// let scene = nbv_scenes::builtin::load("paper-env1").unwrap();
    /// let c = scene.phase_one_config().unwrap();
    /// assert_eq!(c.grid.len(), 126_000);
    /// assert_eq!(c.exclude.len(), 2); // back panel and crate
    /// assert_eq!(c.max_range, 3.0);
    /// ```
    pub fn phase_one_config(&self) -> Result<PhaseOneConfig, SceneError> {
        let grid = self
            .workspace
            .grid_geometry()
            .map_err(|e| SceneError::Invalid {
                file: self.file(),
                key: "workspace".into(),
                problem: Box::new(Problem::OutOfRange {
                    value: format!("{:?} .. {:?}", self.workspace.min, self.workspace.max),
                    expected: e.to_string(),
                }),
            })?;
        let margin = self.segmentation.cluster_tolerance;
        let exclude = self
            .known_obstacle_boxes()?
            .into_iter()
            .map(|(_, pose, half)| OrientedBox::new(pose, half).inflated(margin))
            .collect();
        let (lo, hi) = self.workspace.bounds();
        Ok(PhaseOneConfig {
            segmentation: self.segmentation.params(self.seed),
            grid,
            occupancy: self.mapping.occupancy_params(),
            max_range: self.sensors.mid_range.range[1],
            region: Some(OrientedBox::from_bounds(lo, hi)),
            exclude,
        })
    }

    /// The known obstacles as boxes: name, pose of the box centre (world) and half
    /// extents — the bounds of each obstacle's mesh in its own frame. Phase 1 excludes
    /// them from segmentation; the planner avoids them.
    pub fn known_obstacle_boxes(&self) -> Result<Vec<(String, Pose, Vector3<f64>)>, SceneError> {
        let mut boxes = Vec::new();
        for (i, o) in self.obstacles.iter().enumerate().filter(|(_, o)| o.known) {
            let local = obstacle_local_mesh(o).map_err(|source| SceneError::Mesh {
                file: self.file(),
                key: format!("obstacles[{i}].mesh"),
                source,
            })?;
            let Some((lo, hi)) = local.bounds() else {
                continue;
            };
            let c = nalgebra::center(&lo, &hi);
            let pose = o.pose.to_pose() * Isometry3::translation(c.x, c.y, c.z);
            boxes.push((o.name.clone(), pose, (hi - lo) / 2.0));
        }
        Ok(boxes)
    }
}
