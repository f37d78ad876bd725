//! The fused surface of an object: its registered depth views integrated into a truncated
//! signed distance function and its zero set extracted as a triangle mesh.
//!
//! - [`PinholeIntrinsics`]: the depth camera's pinhole model (Open3D's convention);
//! - [`DepthView`]: one depth image with its camera-to-world pose;
//! - [`TsdfParams`], [`TsdfVolume`]: projective TSDF fusion in sparse 8³ blocks, each
//!   observation weighted by the camera's noise at its depth (1/σ²), tapered from two
//!   noise sigmas behind the surface;
//! - [`TsdfVolume::extract_mesh`]: the zero set by marching cubes (`mcubes`), only where
//!   every corner of a cell was observed;
//! - [`RgbdDataset`]: views in Open3D's reconstruction-system layout (16-bit depth PNGs,
//!   `camera_intrinsic.json`, `trajectory.log`), written and read.

mod depth_view;
mod extract;
mod pinhole;
mod rgbd_dataset;
mod surface_error;
mod tsdf;

pub use depth_view::DepthView;
pub use extract::SurfaceMesh;
pub use pinhole::PinholeIntrinsics;
pub use rgbd_dataset::{DEPTH_SCALE, RgbdDataset, parse_intrinsics, parse_trajectory};
pub use surface_error::SurfaceError;
pub use tsdf::{TsdfParams, TsdfVolume};
