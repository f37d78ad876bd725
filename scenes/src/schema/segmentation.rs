//! [`Segmentation`]: outlier removal, table-plane extraction and Euclidean clustering of
//! the mid-range cloud (the paper follows PCL; defaults are PCL tutorial values).

use super::Check;
use crate::error::SceneError;
use nbv_core::perception::SegmentationParams;
use serde::{Deserialize, Serialize};

/// Parameters of phase-1 segmentation into object clusters.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Segmentation {
    /// Voxel-grid downsampling leaf (m) before segmentation; 0 disables it. Default 0.005.
    pub voxel: f64,
    /// Neighbours per point in statistical outlier removal. Default 50.
    pub outlier_neighbours: u32,
    /// A point is an outlier when its mean neighbour distance exceeds the global mean by
    /// this many standard deviations. Default 3.0: PCL's tutorial value 1.0 always drops
    /// about a tenth of the points, and in a laser sweep those are the sparsely sampled
    /// steep sides of the objects (on the paper scenes it split the jug and lost parts of
    /// the bottle and mallet).
    pub outlier_std: f64,
    /// RANSAC inlier distance (m) of the dominant (table) plane. Default 0.01.
    pub plane_distance: f64,
    /// RANSAC iterations for the plane. Default 1000.
    pub plane_iterations: u32,
    /// Euclidean clustering (flood fill) distance (m). Default 0.02.
    pub cluster_tolerance: f64,
    /// Smallest cluster kept as an object (points). Default 100.
    pub min_cluster_points: u32,
    /// Largest cluster kept as an object (points). Default 25000.
    pub max_cluster_points: u32,
}

impl Default for Segmentation {
    fn default() -> Self {
        let core = SegmentationParams::default();
        Self {
            voxel: core.voxel,
            outlier_neighbours: core.outlier_neighbours as u32,
            outlier_std: core.outlier_std,
            plane_distance: core.plane_distance,
            plane_iterations: core.plane_iterations as u32,
            cluster_tolerance: core.cluster_tolerance,
            min_cluster_points: core.min_cluster_points as u32,
            max_cluster_points: core.max_cluster_points as u32,
        }
    }
}

impl Segmentation {
    /// Checks every value of `[segmentation]`; the error names the key.
    pub(crate) fn check(&self, c: &Check) -> Result<(), SceneError> {
        c.within("segmentation.voxel", self.voxel, 0.0, 1.0, "[0, 1] m")?;
        c.at_least(
            "segmentation.outlier_neighbours",
            self.outlier_neighbours.into(),
            1,
        )?;
        c.positive("segmentation.outlier_std", self.outlier_std)?;
        c.positive("segmentation.plane_distance", self.plane_distance)?;
        c.at_least(
            "segmentation.plane_iterations",
            self.plane_iterations.into(),
            1,
        )?;
        c.positive("segmentation.cluster_tolerance", self.cluster_tolerance)?;
        c.at_least(
            "segmentation.min_cluster_points",
            self.min_cluster_points.into(),
            1,
        )?;
        c.at_least(
            "segmentation.max_cluster_points",
            self.max_cluster_points.into(),
            self.min_cluster_points.into(),
        )?;
        Ok(())
    }
}
