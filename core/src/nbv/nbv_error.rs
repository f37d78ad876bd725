//! [`NbvError`]: why a next-best-view computation could not be carried out.

use crate::kinematics::IkError;
use crate::occupancy::OccupancyError;

/// A next-best-view query that cannot be answered (bad parameters or inputs). An
/// unreachable viewpoint is not an error: it is dropped and counted.
#[derive(Debug, PartialEq, thiserror::Error)]
pub enum NbvError {
    /// A parameter is out of its range.
    #[error("invalid NBV parameter `{name}` = {value}: {reason}")]
    InvalidParameter {
        /// Parameter name.
        name: &'static str,
        /// The value given.
        value: f64,
        /// What is required.
        reason: &'static str,
    },
    /// The object's centroid (or a viewpoint) is not finite, or the object cloud is empty.
    #[error("invalid input: {0}")]
    InvalidInput(&'static str),
    /// Two grids that should share a lattice do not.
    #[error("the grids before and after the observation have different geometries")]
    GeometryMismatch,
    /// A voxel index is outside the grid.
    #[error("voxel {linear} is outside the grid of {len} voxels")]
    VoxelOutOfRange {
        /// The linear index.
        linear: usize,
        /// Number of voxels of the grid.
        len: usize,
    },
    /// A ray could not be traversed.
    #[error(transparent)]
    Occupancy(#[from] OccupancyError),
    /// Inverse kinematics could not answer (unknown sensor frame, unsupported robot); an
    /// unreachable pose is not reported here.
    #[error("inverse kinematics: {0}")]
    Kinematics(#[from] IkError),
}
