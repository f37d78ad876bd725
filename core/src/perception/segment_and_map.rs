//! [`phase_one`]: the whole of phase 1 — the mid-range cloud P becomes the object clusters
//! P_j^0, the occupancy grid M (eq. (1)–(2)) and the reduced map M̄ (Figure 2, lines 3–6).

use crate::cloud::PointCloud;
use crate::occupancy::{GridGeometry, OccupancyGrid, OccupancyParams, ReducedMap, ScanUpdate};
use crate::registration::PosePrior;
use nalgebra::Point3;

use super::{
    ObjectSegmentation, OrientedBox, PerceptionError, SegmentationParams, segment_objects,
};

/// Everything phase 1 needs besides the cloud.
#[derive(Debug, Clone, PartialEq)]
pub struct PhaseOneConfig {
    /// Segmentation parameters.
    pub segmentation: SegmentationParams,
    /// The grid's lattice (the scene's workspace).
    pub grid: GridGeometry,
    /// Log-odds model and state threshold ε_o.
    pub occupancy: OccupancyParams,
    /// The sensor's maximum range (m): longer rays clear free space up to it and hit
    /// nothing.
    pub max_range: f64,
    /// Points outside this box are not segmented (they still update the grid).
    pub region: Option<OrientedBox>,
    /// Boxes whose points are not segmented: the obstacles the robot knows about.
    pub exclude: Vec<OrientedBox>,
}

impl PhaseOneConfig {
    /// Default parameters over `grid`: default segmentation and occupancy parameters, the
    /// LMS400's 3 m maximum range, the grid's box as the region, nothing excluded.
    ///
    /// ```
    /// use nbv_core::occupancy::GridGeometry;
    /// use nbv_core::perception::PhaseOneConfig;
    /// use nalgebra::Point3;
    /// let g = GridGeometry::new(
    ///     Point3::new(0.30, -0.70, 0.23), Point3::new(1.50, 0.70, 0.83), 0.02).unwrap();
    /// let c = PhaseOneConfig::new(g);
    /// assert!(c.region.unwrap().contains(&Point3::new(1.49, 0.69, 0.82)));
    /// assert_eq!(c.max_range, 3.0);
    /// ```
    pub fn new(grid: GridGeometry) -> Self {
        Self {
            segmentation: SegmentationParams::default(),
            region: Some(OrientedBox::from_bounds(grid.min(), grid.max())),
            grid,
            occupancy: OccupancyParams::default(),
            max_range: 3.0,
            exclude: Vec::new(),
        }
    }
}

impl PhaseOneConfig {
    /// The same configuration with every excluded box grown by three standard deviations
    /// of how far the pose error `prior` of a sensor at `sensor` can move the box's
    /// points (the lever: its centre's range plus its half diagonal, a bound on its
    /// farthest corner's): a known obstacle's surface
    /// seen through a wrong pose still falls inside its box. For the laser sweep after
    /// [`align_to_workcell`](super::align_to_workcell), `prior` is what is left of the
    /// error (the alignment's posterior σ); otherwise the rig's declared prior.
    ///
    /// ```
    /// use nbv_core::occupancy::GridGeometry;
    /// use nbv_core::perception::{OrientedBox, PhaseOneConfig};
    /// use nbv_core::registration::PosePrior;
    /// use nalgebra::Point3;
    /// let g = GridGeometry::new(Point3::new(0.0, -1.0, 0.0), Point3::new(2.0, 1.0, 1.0), 0.02).unwrap();
    /// let mut c = PhaseOneConfig::new(g);
    /// c.exclude.push(OrientedBox::from_bounds(Point3::new(1.5, -0.5, 0.0), Point3::new(1.6, 0.5, 0.5)));
    /// let prior = PosePrior { rotation_sigma: 0.002, translation_sigma: 0.003 };
    /// let grown = c.with_pose_error(&prior, &Point3::new(0.0, 0.0, 1.0));
    /// // Lever: |(1.55, 0, -0.75)| + |(0.05, 0.5, 0.25)| = 1.722 + 0.561 m.
    /// let lever = 1.55f64.hypot(0.75) + (0.05f64.powi(2) + 0.25 + 0.0625).sqrt();
    /// let margin = grown.exclude[0].half_extents.x - c.exclude[0].half_extents.x;
    /// assert!((margin - 3.0 * (0.003 + lever * 0.002)).abs() < 1e-9);
    /// assert!(margin > 0.022 && margin < 0.023);
    /// ```
    pub fn with_pose_error(&self, prior: &PosePrior, sensor: &Point3<f64>) -> Self {
        let exclude = self
            .exclude
            .iter()
            .map(|b| {
                let reach =
                    (b.pose.translation.vector - sensor.coords).norm() + b.half_extents.norm();
                b.inflated(POSE_ERROR_SIGMAS * prior.point_sigma(reach))
            })
            .collect();
        Self {
            exclude,
            ..self.clone()
        }
    }
}

/// Standard deviations of pose error an exclusion box is grown by.
const POSE_ERROR_SIGMAS: f64 = 3.0;

/// The occupancy grid after the phase-1 cloud, and its reduced map.
#[derive(Debug, Clone, PartialEq)]
pub struct PhaseOneMap {
    /// The log-odds grid M.
    pub grid: OccupancyGrid,
    /// What the scan did (rays, voxels updated, truncated rays, hits outside the grid).
    pub scan: ScanUpdate,
    /// The reduced map M̄ with its statistics.
    pub reduced: ReducedMap,
}

/// The result of [`phase_one`].
#[derive(Debug, Clone, PartialEq)]
pub struct PhaseOne {
    /// The object clusters and the intermediate counts.
    pub segmentation: ObjectSegmentation,
    /// The grid and its reduced map.
    pub map: PhaseOneMap,
}

/// Builds the occupancy grid of `cloud` (lines 4–6 of Figure 2): an all-unknown grid over
/// `geometry`, one scan of the rays `origins[i] → points[i]`, then the reduced map.
/// Fails with [`PerceptionError::MissingOrigins`] when the cloud has no origins.
pub fn build_map(
    cloud: &PointCloud,
    geometry: GridGeometry,
    occupancy: OccupancyParams,
    max_range: f64,
) -> Result<PhaseOneMap, PerceptionError> {
    let origins = cloud
        .origins
        .as_deref()
        .ok_or(PerceptionError::MissingOrigins)?;
    let mut grid = OccupancyGrid::new(geometry, occupancy)?;
    let scan = grid.insert_rays(origins, &cloud.points, max_range)?;
    let reduced = ReducedMap::from_grid(&grid);
    Ok(PhaseOneMap {
        grid,
        scan,
        reduced,
    })
}

/// Phase 1 on the accumulated mid-range cloud: [`segment_objects`] on the points inside
/// the region, and [`build_map`] from every point of the cloud (points outside the region
/// or in excluded boxes are real surfaces: they still mark the grid).
///
/// The origins are checked first, so a cloud without them fails before any work.
///
/// ```
/// use nbv_core::cloud::PointCloud;
/// use nbv_core::occupancy::GridGeometry;
/// use nbv_core::perception::{PhaseOneConfig, SegmentationParams, phase_one};
/// use nalgebra::Point3;
/// let g = GridGeometry::new(Point3::new(0.0, 0.0, 0.0), Point3::new(1.0, 1.0, 0.5), 0.05).unwrap();
/// let mut config = PhaseOneConfig::new(g);
/// config.segmentation = SegmentationParams {
///     voxel: 0.0, outlier_neighbours: 0, min_cluster_points: 5, ..Default::default()
/// };
/// // A floor at z = 0.1 and a small pole, seen from a sensor 1 m above.
/// let mut pts: Vec<_> = (0..400)
///     .map(|i| Point3::new(0.025 + (i % 20) as f64 * 0.05, 0.025 + (i / 20) as f64 * 0.05, 0.1))
///     .collect();
/// pts.extend((1..=10).map(|k| Point3::new(0.51, 0.51, 0.105 + k as f64 * 0.015)));
/// let mut cloud = PointCloud::from_points(pts);
/// assert!(phase_one(&cloud, &config).is_err()); // no origins
/// cloud.origins = Some(vec![Point3::new(0.5, 0.5, 1.2); cloud.len()]);
/// let out = phase_one(&cloud, &config).unwrap();
/// assert_eq!(out.segmentation.clusters.len(), 1);
/// assert!(out.map.reduced.stats().grid.occupied > 0);
/// ```
pub fn phase_one(cloud: &PointCloud, config: &PhaseOneConfig) -> Result<PhaseOne, PerceptionError> {
    if cloud.origins.is_none() {
        return Err(PerceptionError::MissingOrigins);
    }
    let segmentation = segment_objects(
        cloud,
        &config.segmentation,
        config.region.as_ref(),
        &config.exclude,
    )?;
    let map = build_map(cloud, config.grid, config.occupancy, config.max_range)?;
    Ok(PhaseOne { segmentation, map })
}
