//! [`CameraModel`]: a short-range view as a ROS camera — the object's points in the
//! camera's optical frame, the whole depth frame as a `32FC1` image in metres (REP 118;
//! NaN where no return), and the `CameraInfo` of the camera's pinhole intrinsics
//! (`plumb_bob`, no distortion).
//!
//! The camera's URDF frame (`dinast`) is an optical frame (x right, y down, z forward), so
//! the messages carry it as their `frame_id`.

use super::stamps::header;
use nalgebra::Point3;
use nbv_bag::messages::{CameraInfo, Image, PointCloud2};
use nbv_bag::point_cloud::cloud_from_points_f64;
use nbv_core::cloud::PointCloud;
use nbv_core::math::Pose;
use nbv_core::rig::DepthCameraSpec;
use nbv_core::surface::{DepthView, PinholeIntrinsics};

/// The depth camera's frame and intrinsics.
#[derive(Debug, Clone)]
pub struct CameraModel {
    frame: String,
    intrinsics: PinholeIntrinsics,
}

impl CameraModel {
    /// The camera of `spec`.
    pub fn new(spec: &DepthCameraSpec) -> Self {
        Self {
            frame: spec.frame.clone(),
            intrinsics: PinholeIntrinsics::of_camera(spec),
        }
    }

    /// `/nbv/camera/points`: `cloud` (world frame) seen from `pose` (camera → world).
    pub fn points(&self, pose: &Pose, cloud: &PointCloud, ns: u64) -> PointCloud2 {
        let to_camera = pose.inverse();
        let points: Vec<Point3<f64>> = cloud.points.iter().map(|p| to_camera * p).collect();
        cloud_from_points_f64(header(&self.frame, ns), &points)
    }

    /// `/nbv/camera/depth`: the depth image of `frame` (the whole depth frame, world frame)
    /// taken from `pose`, z along the optical axis in metres, NaN where nothing returned.
    pub fn depth(&self, pose: &Pose, frame: &PointCloud, ns: u64) -> Image {
        let view = DepthView::from_points(self.intrinsics, *pose, &frame.points);
        let k = &self.intrinsics;
        Image {
            header: header(&self.frame, ns),
            height: u32::try_from(k.height).unwrap_or(u32::MAX),
            width: u32::try_from(k.width).unwrap_or(u32::MAX),
            encoding: "32FC1".into(),
            is_bigendian: 0,
            step: u32::try_from(4 * k.width).unwrap_or(u32::MAX),
            data: view.depth.iter().flat_map(|d| d.to_le_bytes()).collect(),
        }
    }

    /// `/nbv/camera/camera_info`: K and P of the pinhole, R the identity, zero distortion.
    pub fn info(&self, ns: u64) -> CameraInfo {
        let k = &self.intrinsics;
        CameraInfo {
            header: header(&self.frame, ns),
            height: u32::try_from(k.height).unwrap_or(u32::MAX),
            width: u32::try_from(k.width).unwrap_or(u32::MAX),
            distortion_model: "plumb_bob".into(),
            d: vec![0.0; 5],
            k: [k.fx, 0.0, k.cx, 0.0, k.fy, k.cy, 0.0, 0.0, 1.0],
            r: [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0],
            p: [
                k.fx, 0.0, k.cx, 0.0, 0.0, k.fy, k.cy, 0.0, 0.0, 0.0, 1.0, 0.0,
            ],
            ..Default::default()
        }
    }
}
