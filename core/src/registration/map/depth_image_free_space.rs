//! [`DepthImageFreeSpace`]: the space a depth camera saw to be empty — in front of each
//! pixel's return — tested by projecting a point into the camera's depth image.
//!
//! It is the camera's counterpart of [`FreeSpace`](crate::registration::FreeSpace) (the laser sweep's
//! rays marked in a grid): an organised depth image already says where every ray went, so
//! the test is one projection and four pixel lookups, with nothing to build. A point is
//! free when it lies in front of the camera and, at each of the four pixels around its
//! projection, nearer than that pixel's return by more than the margin (the averaged
//! frame's noise): within the image of a surface, beside a silhouette where the rays passed
//! on to the table, but not across a silhouette (the four pixels disagree), not behind a
//! surface, not where a pixel had no return (nothing known), not outside the image.
//!
//! The registration uses it for the laser → camera direction: a laser point that lies
//! beyond the edge of a camera view's surface where that camera saw through contradicts
//! the view's pose (the view slid past the rim of a box's top that the laser saw).

use std::sync::Arc;

use nalgebra::Point3;

use crate::math::Pose;
use crate::registration::RegistrationError;

/// Where a pinhole depth camera's rays passed before their returns.
#[derive(Clone)]
pub struct DepthImageFreeSpace {
    /// The camera's optical frame (z forward, x right, y down) in the view's frame.
    sensor: Pose,
    focal: f64,
    width: usize,
    height: usize,
    /// Per pixel (row-major), the depth up to which its ray passed through empty space:
    /// the return's depth less the margin; NaN without a return.
    free_to: Arc<[f32]>,
}

impl std::fmt::Debug for DepthImageFreeSpace {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("DepthImageFreeSpace")
            .field("sensor", &self.sensor)
            .field("focal", &self.focal)
            .field("width", &self.width)
            .field("height", &self.height)
            .finish_non_exhaustive()
    }
}

/// Equal when built from the same image and camera (pixels without a return compare
/// equal).
impl PartialEq for DepthImageFreeSpace {
    fn eq(&self, other: &Self) -> bool {
        self.sensor == other.sensor
            && self.focal == other.focal
            && (self.width, self.height) == (other.width, other.height)
            && self.free_to.len() == other.free_to.len()
            && self
                .free_to
                .iter()
                .zip(other.free_to.iter())
                .all(|(a, b)| a.to_bits() == b.to_bits())
    }
}

impl DepthImageFreeSpace {
    /// The free space of a depth image: `depth` (z in the optical frame, metres, NaN
    /// where invalid; row-major `width × height`) taken by a pinhole camera of `focal`
    /// pixels with its principal point at the image centre (pixel `(u, v)` looks along
    /// `((u + 0.5 − width/2)/focal, (v + 0.5 − height/2)/focal, 1)`), its optical frame at
    /// `sensor` in the view's frame; each pixel's ray is free up to `margin(z)` short of
    /// its return at depth `z`.
    ///
    /// ```
    /// use nbv_core::registration::DepthImageFreeSpace;
    /// use nalgebra::{Isometry3, Point3};
    /// // A 40 × 30 image looking along z: a wall at 0.5 m on the left half, the floor of
    /// // a well at 0.9 m on the right.
    /// let (w, h) = (40, 30);
    /// let depth: Vec<f32> = (0..w * h).map(|i| if i % w < w / 2 { 0.5 } else { 0.9 }).collect();
    /// let free = DepthImageFreeSpace::new(Isometry3::identity(), 40.0, w, h, &depth, |_| 0.01)
    ///     .unwrap();
    /// assert!(free.contains(&Point3::new(-0.1, 0.0, 0.45))); // in front of the wall
    /// assert!(!free.contains(&Point3::new(-0.1, 0.0, 0.6))); // behind it
    /// assert!(free.contains(&Point3::new(0.1, 0.0, 0.6))); // beside it, in the well
    /// assert!(!free.contains(&Point3::new(0.0, 0.0, 0.6))); // at the silhouette
    /// assert!(!free.contains(&Point3::new(2.0, 0.0, 0.6))); // outside the image
    /// ```
    pub fn new(
        sensor: Pose,
        focal: f64,
        width: usize,
        height: usize,
        depth: &[f32],
        margin: impl Fn(f64) -> f64,
    ) -> Result<Self, RegistrationError> {
        if !(focal.is_finite() && focal > 0.0) {
            return Err(RegistrationError::InvalidParameter {
                name: "depth_image.focal",
                value: focal,
                reason: "must be finite and > 0",
            });
        }
        if depth.len() != width * height {
            return Err(RegistrationError::InvalidParameter {
                name: "depth_image.pixels",
                value: depth.len() as f64,
                reason: "must be width × height",
            });
        }
        let free_to = depth
            .iter()
            .map(|&z| {
                let z = f64::from(z);
                if z.is_finite() && z > 0.0 {
                    (z - margin(z).max(0.0)) as f32
                } else {
                    f32::NAN
                }
            })
            .collect();
        Ok(Self {
            sensor,
            focal,
            width,
            height,
            free_to,
        })
    }

    /// Whether `p` (view frame) lies where the camera's rays passed: in front of the
    /// camera, inside the image, and nearer than every one of the four pixels around its
    /// projection saw empty space to.
    pub fn contains(&self, p: &Point3<f64>) -> bool {
        let q = self.sensor.inverse_transform_point(p);
        if q.z.is_nan() || q.z <= 0.0 {
            return false;
        }
        // Continuous pixel coordinates, integers at pixel centres.
        let u = self.focal * q.x / q.z + 0.5 * self.width as f64 - 0.5;
        let v = self.focal * q.y / q.z + 0.5 * self.height as f64 - 0.5;
        let (u0, v0) = (u.floor(), v.floor());
        if u0.is_nan()
            || v0.is_nan()
            || u0 < 0.0
            || v0 < 0.0
            || u0 + 1.0 >= self.width as f64
            || v0 + 1.0 >= self.height as f64
        {
            return false;
        }
        let (u0, v0) = (u0 as usize, v0 as usize);
        let z = q.z as f32;
        [(0, 0), (1, 0), (0, 1), (1, 1)]
            .iter()
            .all(|&(du, dv)| z < self.free_to[(v0 + dv) * self.width + u0 + du])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Translation3, UnitQuaternion, Vector3};

    #[test]
    fn the_test_follows_the_camera_pose() {
        // A flat wall 0.4 m in front of a camera placed and turned somewhere: points in
        // front of it are free wherever the camera is, points behind it never.
        let sensor = Pose::from_parts(
            Translation3::new(0.3, -0.2, 0.9),
            UnitQuaternion::from_euler_angles(2.9, 0.3, -1.2),
        );
        let (w, h) = (64, 48);
        let depth = vec![0.4f32; w * h];
        let free = DepthImageFreeSpace::new(sensor, 50.0, w, h, &depth, |z| 0.01 * z).unwrap();
        for (x, y) in [(0.0, 0.0), (0.1, -0.05), (-0.15, 0.1)] {
            let ray = Vector3::new(x, y, 1.0);
            let at = |z: f64| sensor * Point3::from(ray * z);
            assert!(free.contains(&at(0.3)), "{x} {y}");
            assert!(free.contains(&at(0.39)), "{x} {y}");
            // Within the margin (4 mm) of the wall, and behind it.
            assert!(!free.contains(&at(0.397)), "{x} {y}");
            assert!(!free.contains(&at(0.5)), "{x} {y}");
            // Behind the camera.
            assert!(!free.contains(&at(-0.3)), "{x} {y}");
        }
    }

    #[test]
    fn a_pixel_without_a_return_is_unknown() {
        let (w, h) = (8, 8);
        let mut depth = vec![1.0f32; w * h];
        depth[3 * w + 3] = f32::NAN;
        let free = DepthImageFreeSpace::new(Pose::identity(), 8.0, w, h, &depth, |_| 0.0).unwrap();
        // Pixel (3, 3)'s centre, and a point among pixels (5..7, 5..7).
        let centre =
            |u: f64, v: f64| Point3::new((u + 0.5 - 4.0) / 8.0, (v + 0.5 - 4.0) / 8.0, 1.0);
        assert!(!free.contains(&(centre(3.0, 3.0) * 0.5)));
        assert!(!free.contains(&(centre(2.5, 2.5) * 0.5)));
        assert!(free.contains(&(centre(5.5, 5.5) * 0.5)));
    }

    proptest::proptest! {
        /// The free space is star-shaped from the camera: wherever a point along a ray is
        /// free, every point nearer the camera on that ray is free too; and nothing behind
        /// every return is.
        #[test]
        fn the_free_space_is_star_shaped_from_the_camera(
            depths in proptest::collection::vec(proptest::option::of(0.2f32..1.0), 12 * 9),
            roll in -3.0f64..3.0,
            (x, y) in (-0.5f64..0.5, -0.4f64..0.4),
            t in 0.05f64..1.2,
            shrink in 0.0f64..1.0,
        ) {
            let (w, h) = (12, 9);
            let depth: Vec<f32> = depths.iter().map(|d| d.unwrap_or(f32::NAN)).collect();
            let sensor = Pose::from_parts(
                Translation3::new(0.1, 0.2, 0.3),
                UnitQuaternion::from_euler_angles(roll, 0.2, -0.4),
            );
            let free = DepthImageFreeSpace::new(sensor, 10.0, w, h, &depth, |z| 0.02 * z).unwrap();
            let ray = Vector3::new(x, y, 1.0);
            let at = |z: f64| sensor * Point3::from(ray * z);
            if free.contains(&at(t)) {
                proptest::prop_assert!(free.contains(&at(t * shrink.max(1e-3))));
            }
            // Behind every return of the image (all nearer than 1 m): never free.
            proptest::prop_assert!(!free.contains(&at(1.01)));
        }
    }

    #[test]
    fn bad_images_are_errors() {
        let depth = vec![1.0f32; 12];
        let make = |focal: f64, w: usize, h: usize| {
            DepthImageFreeSpace::new(Pose::identity(), focal, w, h, &depth, |_| 0.0)
        };
        assert!(make(10.0, 4, 3).is_ok());
        assert!(make(10.0, 4, 4).is_err());
        assert!(make(0.0, 4, 3).is_err());
        assert!(make(f64::NAN, 4, 3).is_err());
    }
}
