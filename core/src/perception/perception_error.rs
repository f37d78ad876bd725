//! [`PerceptionError`]: why phase 1 could not turn a cloud into clusters and a map.

use thiserror::Error;

use crate::cloud::ProcessingError;
use crate::occupancy::OccupancyError;

/// Why phase 1 failed.
#[derive(Debug, Error, PartialEq)]
pub enum PerceptionError {
    /// The cloud has no per-point sensor origins, so no ray can be cast into the grid.
    #[error(
        "the cloud has no per-point sensor origins (`ox oy oz` in PLY, `vp_x vp_y vp_z` in \
         PCD): the occupancy grid needs the ray from the sensor to every point"
    )]
    MissingOrigins,
    /// A processing step refused its input or its parameters.
    #[error("{step}: {source}")]
    Processing {
        /// The step (voxel filter, outlier removal, table plane, clustering).
        step: &'static str,
        /// What it said.
        #[source]
        source: ProcessingError,
    },
    /// No point of the cloud lies in the region of interest (outside the known obstacles).
    #[error("none of the {points} points lies inside the region of interest")]
    NothingInRegion {
        /// Points in the input cloud.
        points: usize,
    },
    /// A segmentation parameter is out of range.
    #[error("segmentation parameter `{name}` = {value}: {reason}")]
    InvalidParameter {
        /// Parameter name.
        name: &'static str,
        /// The offending value.
        value: f64,
        /// The valid range.
        reason: &'static str,
    },
    /// The grid could not be built or updated.
    #[error("occupancy grid: {0}")]
    Occupancy(#[from] OccupancyError),
}
