//! [`OccupancyError`]: the typed errors of grid construction, parameters and updates.

use thiserror::Error;

use crate::cloud::CloudError;

/// Why a grid could not be built or updated.
#[derive(Debug, Error, PartialEq)]
pub enum OccupancyError {
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
    /// The workspace box is empty, inverted or not finite.
    #[error("invalid workspace bounds: min {min:?}, max {max:?}")]
    InvalidBounds {
        /// Lower corner given.
        min: [f64; 3],
        /// Upper corner given.
        max: [f64; 3],
    },
    /// The grid would have more voxels than [`super::MAX_VOXELS`].
    #[error("the grid would have {voxels} voxels, more than the limit {limit}")]
    TooManyVoxels {
        /// Voxels asked for.
        voxels: f64,
        /// The limit.
        limit: usize,
    },
    /// A ray has a non-finite origin or end point, or a zero or non-finite direction.
    #[error("ray {index}: {reason}")]
    InvalidRay {
        /// Index of the ray (0 for a single traversal).
        index: usize,
        /// What is wrong.
        reason: &'static str,
    },
    /// A cloud inserted into the grid has no sensor origins.
    #[error("the cloud has no `origins` column: a grid update needs each ray's origin")]
    MissingOrigins,
    /// Origins and points differ in number.
    #[error("{origins} origins for {points} points")]
    LengthMismatch {
        /// Number of origins.
        origins: usize,
        /// Number of points.
        points: usize,
    },
    /// The cloud is malformed.
    #[error(transparent)]
    Cloud(#[from] CloudError),
    /// A log-odds array does not match the grid size.
    #[error("{got} log-odds values for a grid of {expected} voxels")]
    ValueCount {
        /// Voxels in the grid.
        expected: usize,
        /// Values given.
        got: usize,
    },
    /// A log-odds value is NaN or infinite.
    #[error("log-odds of voxel {index} is not finite")]
    NonFiniteValue {
        /// Linear index of the voxel.
        index: usize,
    },
}
