//! The occupancy grid map of the paper (section III, eq. (1)–(2)) and its reduced map M̄.
//!
//! - [`GridGeometry`]: the bounded workspace lattice (e.g. the paper's 60×70×30 voxels of
//!   2 cm), index helpers and the entry point to ray traversal;
//! - [`VoxelTraversal`]: 3-D DDA (Amanatides–Woo) clipped to the grid, reusable for
//!   next-best-view visibility;
//! - [`OccupancyParams`], [`VoxelState`]: the log-odds ray model and the states by ε_o;
//! - [`OccupancyGrid`]: dense f32 log-odds, per-scan ray updates (parallel, deterministic,
//!   touching only the voxels a scan reaches: see [`OccupancyGrid::insert_rays`]);
//! - [`ReducedMap`]: occupied voxels plus the unknown crust, with statistics;
//! - [`OcclusionDistances`]: how far behind measured surface each unmeasured voxel lies
//!   (the proximity-count and area-factor objectives' map data);
//! - the binary grid file format (see [`OccupancyGrid::write_to`]).
//!
//! Conventions: a point belongs to voxel `floor((p − min)/resolution)` (a point on a face
//! belongs to the higher-index voxel; the grid is half-open on its upper faces); linear
//! index `ix + nx·(iy + ny·iz)`.
//!
//! # Grid file format (version 1)
//!
//! Written by [`OccupancyGrid::save`] (atomically) and read by [`OccupancyGrid::load`];
//! all numbers little-endian, an 80-byte header then the values:
//!
//! | offset | type      | field                                         |
//! |-------:|-----------|-----------------------------------------------|
//! | 0      | `[u8; 8]` | magic `NBVGRID\0`                             |
//! | 8      | `u32`     | version = 1                                   |
//! | 12     | `u32` ×3  | dims `nx, ny, nz`                             |
//! | 24     | `f64` ×3  | lower corner `min` (m)                        |
//! | 48     | `f64`     | resolution (m)                                |
//! | 56     | `f64`     | hit probability p̄                             |
//! | 64     | `f32` ×3  | clamp min, clamp max (log-odds), ε_o          |
//! | 76     | `u32`     | reserved = 0                                  |
//! | 80     | `f32` ×N  | log-odds, N = nx·ny·nz, linear index order    |
//!
//! The file is exactly `80 + 4·N` bytes. The reader checks the magic, the version, the
//! geometry (at most [`MAX_VOXELS`] voxels) and the parameters, reads the values in chunks
//! (memory follows the bytes present, not the header's claim), rejects truncation,
//! trailing bytes and non-finite values, each with its own [`GridFileError`].

mod grid_file;
mod grid_geometry;
mod lattice_planes;
mod log_odds;
mod occlusion_distances;
mod occupancy_error;
mod occupancy_grid;
mod reduced_map;
mod scan_marks;
mod voxel_traversal;

pub use grid_file::{GRID_FILE_MAGIC, GRID_FILE_VERSION, GridFileError};
pub use grid_geometry::{GridGeometry, MAX_VOXELS, VoxelIndex};
pub use log_odds::{OccupancyParams, VoxelState, log_odds, probability};
pub use occlusion_distances::{OCCLUSION_UPDATE_DISTANCE, OcclusionDistances};
pub use occupancy_error::OccupancyError;
pub use occupancy_grid::{FreeRay, OccupancyGrid, ScanUpdate, ScanVoxels, StateCounts};
pub use reduced_map::{ReducedMap, ReducedMapStats};
pub use voxel_traversal::{VoxelCrossing, VoxelTraversal};
