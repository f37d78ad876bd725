//! [`SegmentationParams`]: the parameters of phase-1 segmentation (voxel filter, outlier
//! removal, table plane, Euclidean clustering), as in a scene's `[segmentation]` section.

use super::PerceptionError;

/// Parameters of [`segment_objects`](super::segment_objects). The defaults are the scene
/// schema's (PCL tutorial values, see `nbv_scenes::schema::Segmentation`), plus a table
/// tilt limit and a seed that the scene file does not carry.
///
/// ```
/// use nbv_core::perception::SegmentationParams;
/// let p = SegmentationParams::default();
/// assert_eq!((p.voxel, p.outlier_neighbours, p.min_cluster_points), (0.005, 50, 100));
/// assert!(p.validate().is_ok());
/// assert!(SegmentationParams { cluster_tolerance: 0.0, ..p }.validate().is_err());
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SegmentationParams {
    /// Voxel-grid leaf (m) of the downsampling before segmentation; 0 disables it.
    pub voxel: f64,
    /// Neighbours per point in statistical outlier removal; 0 disables it.
    pub outlier_neighbours: usize,
    /// Standard-deviation multiplier of the outlier threshold. Default 3.0 (see the scene
    /// schema: 1.0 removes the sparse sides of objects in a laser sweep).
    pub outlier_std: f64,
    /// RANSAC inlier distance (m) of the table plane; points above the plane by more than
    /// this are the ones clustered.
    pub plane_distance: f64,
    /// RANSAC iterations.
    pub plane_iterations: usize,
    /// Largest angle (rad) between the table normal and the vertical. Default 0.35 (20°).
    pub plane_max_tilt: f64,
    /// Euclidean clustering link distance (m).
    pub cluster_tolerance: f64,
    /// Smallest cluster kept as an object (points, after downsampling).
    pub min_cluster_points: usize,
    /// Largest cluster kept as an object.
    pub max_cluster_points: usize,
    /// Seed of the RANSAC sampler. Default 2014 (the scene's default seed).
    pub seed: u64,
}

impl Default for SegmentationParams {
    fn default() -> Self {
        Self {
            voxel: 0.005,
            outlier_neighbours: 50,
            outlier_std: 3.0,
            plane_distance: 0.01,
            plane_iterations: 1000,
            plane_max_tilt: 0.35,
            cluster_tolerance: 0.02,
            min_cluster_points: 100,
            max_cluster_points: 25_000,
            seed: 2014,
        }
    }
}

impl SegmentationParams {
    /// Checks every range before any work is done.
    pub fn validate(&self) -> Result<(), PerceptionError> {
        let bad = |name, value: f64, reason| {
            Err(PerceptionError::InvalidParameter {
                name,
                value,
                reason,
            })
        };
        if !(self.voxel.is_finite() && self.voxel >= 0.0) {
            return bad("voxel", self.voxel, "must be finite and >= 0 (0 disables)");
        }
        if !self.outlier_std.is_finite() {
            return bad("outlier_std", self.outlier_std, "must be finite");
        }
        if !(self.plane_distance.is_finite() && self.plane_distance > 0.0) {
            return bad(
                "plane_distance",
                self.plane_distance,
                "must be finite and > 0",
            );
        }
        if self.plane_iterations == 0 {
            return bad("plane_iterations", 0.0, "must be >= 1");
        }
        if !(self.plane_max_tilt > 0.0 && self.plane_max_tilt <= std::f64::consts::FRAC_PI_2) {
            return bad(
                "plane_max_tilt",
                self.plane_max_tilt,
                "must be in (0, pi/2]",
            );
        }
        if !(self.cluster_tolerance.is_finite() && self.cluster_tolerance > 0.0) {
            return bad(
                "cluster_tolerance",
                self.cluster_tolerance,
                "must be finite and > 0",
            );
        }
        if self.min_cluster_points == 0 {
            return bad("min_cluster_points", 0.0, "must be >= 1");
        }
        if self.max_cluster_points < self.min_cluster_points {
            return bad(
                "max_cluster_points",
                self.max_cluster_points as f64,
                "must be >= min_cluster_points",
            );
        }
        Ok(())
    }
}
