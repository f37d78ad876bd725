//! Point clouds: the container shared by sensors, mapping and registration, and the
//! processing steps of phase 1.

mod point_cloud;

pub use point_cloud::{CloudError, PointCloud};
