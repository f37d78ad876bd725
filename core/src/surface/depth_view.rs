//! [`DepthView`]: one depth image (z along the optical axis, metres) and the pose of the
//! camera that took it.

use nalgebra::Point3;

use crate::math::Pose;

use super::PinholeIntrinsics;

/// A depth image and its camera-to-world pose.
#[derive(Debug, Clone, PartialEq)]
pub struct DepthView {
    /// The camera.
    pub intrinsics: PinholeIntrinsics,
    /// Depth per pixel (z in the camera frame), row-major, metres; NaN or 0 where there
    /// is no return.
    pub depth: Vec<f32>,
    /// Camera frame → world frame.
    pub pose: Pose,
}

impl DepthView {
    /// The depth image of `points` (world frame) seen by a camera at `pose`: each point
    /// goes to the pixel it projects into, the nearest point winning. For points that came
    /// from that very camera's image (an object cut out of a frame) this is the frame's
    /// depth at the object's pixels and nothing elsewhere.
    ///
    /// ```
    /// use nbv_core::rig::DepthCameraSpec;
    /// use nbv_core::surface::{DepthView, PinholeIntrinsics};
    /// use nalgebra::{Isometry3, Point3};
    /// let k = PinholeIntrinsics::of_camera(&DepthCameraSpec::ipa1110());
    /// let view = DepthView::from_points(k, Isometry3::identity(), &[Point3::new(0.0, 0.0, 0.4)]);
    /// assert_eq!(view.depth_at(160, 120), Some(0.4));
    /// assert_eq!(view.valid_pixels(), 1);
    /// ```
    pub fn from_points(intrinsics: PinholeIntrinsics, pose: Pose, points: &[Point3<f64>]) -> Self {
        let mut depth = vec![f32::NAN; intrinsics.width * intrinsics.height];
        let to_camera = pose.inverse();
        for p in points {
            let c = to_camera * p;
            if let Some((u, v)) = intrinsics.pixel_of(&c) {
                let d = &mut depth[v * intrinsics.width + u];
                let z = c.z as f32;
                if d.is_nan() || z < *d {
                    *d = z;
                }
            }
        }
        Self {
            intrinsics,
            depth,
            pose,
        }
    }

    /// The depth at pixel `(u, v)`, if it has a return.
    pub fn depth_at(&self, u: usize, v: usize) -> Option<f32> {
        let d = *self.depth.get(v * self.intrinsics.width + u)?;
        (d.is_finite() && d > 0.0).then_some(d)
    }

    /// Pixels with a return.
    pub fn valid_pixels(&self) -> usize {
        self.depth
            .iter()
            .filter(|d| d.is_finite() && **d > 0.0)
            .count()
    }

    /// The returns as points in the world frame, row by row.
    pub fn points(&self) -> Vec<Point3<f64>> {
        let k = &self.intrinsics;
        let mut out = Vec::new();
        for v in 0..k.height {
            for u in 0..k.width {
                if let Some(d) = self.depth_at(u, v) {
                    out.push(self.pose * Point3::from(k.ray(u as f64, v as f64) * f64::from(d)));
                }
            }
        }
        out
    }
}
