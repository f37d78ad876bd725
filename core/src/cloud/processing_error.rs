//! [`ProcessingError`]: the typed errors shared by the cloud processing steps (voxel
//! filter, outlier removal, plane extraction, clustering).

use thiserror::Error;

use super::CloudError;

/// Why a cloud processing step refused its input.
#[derive(Debug, Error, PartialEq)]
pub enum ProcessingError {
    /// The input cloud has no point.
    #[error("the input cloud is empty")]
    EmptyCloud,
    /// A parameter is out of its valid range.
    #[error("parameter `{name}` = {value}: {reason}")]
    InvalidParameter {
        /// Parameter name.
        name: &'static str,
        /// The offending value (as f64 for display).
        value: f64,
        /// What the valid range is.
        reason: &'static str,
    },
    /// The cloud itself is malformed (column lengths, non-finite coordinates).
    #[error(transparent)]
    Cloud(#[from] CloudError),
    /// The step needs more points than the cloud has.
    #[error("need at least {needed} points, the cloud has {got}")]
    TooFewPoints {
        /// Minimum number of points.
        needed: usize,
        /// Points in the cloud.
        got: usize,
    },
    /// The cloud has more points than 32-bit indices (a k-d tree's items) can address.
    #[error("the cloud has {0} points, more than 32-bit indices can address")]
    TooManyPoints(usize),
    /// A coordinate divided by the voxel size does not fit a voxel key.
    #[error("point {index} is too far from the origin for voxel size {leaf_size}")]
    VoxelKeyOverflow {
        /// Index of the point.
        index: usize,
        /// The voxel size.
        leaf_size: f64,
    },
    /// RANSAC found no admissible plane (all samples degenerate or too tilted).
    #[error("no admissible plane found in {iterations} RANSAC iterations")]
    NoPlaneFound {
        /// Iterations tried.
        iterations: usize,
    },
}

/// Checks that a cloud is usable: non-empty, consistent columns, finite coordinates.
pub(crate) fn check_cloud(cloud: &super::PointCloud) -> Result<(), ProcessingError> {
    if cloud.is_empty() {
        return Err(ProcessingError::EmptyCloud);
    }
    cloud.validate()?;
    Ok(())
}

/// Builds the 3-D k-d tree used by the neighbourhood queries (items are point indices).
pub(crate) fn build_kd_tree(
    cloud: &super::PointCloud,
) -> Result<kiddo::ImmutableKdTree<f64, 3>, ProcessingError> {
    if u32::try_from(cloud.len()).is_err() {
        return Err(ProcessingError::TooManyPoints(cloud.len()));
    }
    let coords: Vec<[f64; 3]> = cloud.points.iter().map(|p| [p.x, p.y, p.z]).collect();
    kiddo::ImmutableKdTree::new_from_slice(&coords)
        .map_err(|_| ProcessingError::TooManyPoints(cloud.len()))
}
