//! Point clouds: the container shared by sensors, mapping and registration, and the
//! processing steps of phase 1 (voxel downsampling, statistical outlier removal,
//! dominant-plane extraction, Euclidean clustering).

mod euclidean_cluster;
pub mod io;
mod k_nearest;
mod outlier_filter;
mod plane_ransac;
mod point_cloud;
mod processing_error;
mod proximity;
mod voxel_filter;

pub use euclidean_cluster::{Cluster, EuclideanClustering};
pub use io::{CloudIoError, read_cloud, write_cloud};
pub use k_nearest::KNearest;
pub use outlier_filter::StatisticalOutlierFilter;
pub use plane_ransac::{PlaneFit, PlaneRansac};
pub use point_cloud::{CloudError, PointCloud};
pub use processing_error::ProcessingError;
pub use proximity::{near_mask, nearest_distances, neighbour_counts};
pub use voxel_filter::VoxelFilter;
