//! Point clouds: the container shared by sensors, mapping and registration, and the
//! processing steps of phase 1.

pub mod io;
mod point_cloud;

pub use io::{CloudIoError, read_cloud, write_cloud};
pub use point_cloud::{CloudError, PointCloud};
