//! [`PinholeIntrinsics`]: a pinhole camera's image size, focal lengths and principal
//! point, as Open3D's `PinholeCameraIntrinsic` holds them (pixel centres at integer
//! coordinates: pixel `(u, v)` looks along `((u − cx)/fx, (v − cy)/fy, 1)`).

use nalgebra::{Point3, Vector3};

use crate::rig::DepthCameraSpec;

/// A pinhole camera: `u = fx·x/z + cx`, `v = fy·y/z + cy` (x right, y down, z forward).
///
/// ```
/// use nbv_core::rig::DepthCameraSpec;
/// use nbv_core::surface::PinholeIntrinsics;
/// let k = PinholeIntrinsics::of_camera(&DepthCameraSpec::ipa1110());
/// assert_eq!((k.width, k.height, k.cx, k.cy), (320, 240, 159.5, 119.5));
/// // The principal point looks straight ahead.
/// assert_eq!(k.ray(159.5, 119.5), nalgebra::Vector3::new(0.0, 0.0, 1.0));
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PinholeIntrinsics {
    /// Pixels per row.
    pub width: usize,
    /// Rows.
    pub height: usize,
    /// Focal length along x, pixels.
    pub fx: f64,
    /// Focal length along y, pixels.
    pub fy: f64,
    /// Principal point, x (pixels; the first pixel's centre is 0).
    pub cx: f64,
    /// Principal point, y.
    pub cy: f64,
}

impl PinholeIntrinsics {
    /// The intrinsics of a [`DepthCameraSpec`] (square pixels, principal point at the image
    /// centre).
    pub fn of_camera(spec: &DepthCameraSpec) -> Self {
        let f = spec.focal();
        Self {
            width: spec.width,
            height: spec.height,
            fx: f,
            fy: f,
            cx: 0.5 * spec.width as f64 - 0.5,
            cy: 0.5 * spec.height as f64 - 0.5,
        }
    }

    /// The ray through image point `(u, v)`, with z = 1.
    pub fn ray(&self, u: f64, v: f64) -> Vector3<f64> {
        Vector3::new((u - self.cx) / self.fx, (v - self.cy) / self.fy, 1.0)
    }

    /// Where `p` (camera frame) projects in the image, `(u, v)` with pixel centres at
    /// integers, if it lies in front of the camera.
    pub fn image_point(&self, p: &Point3<f64>) -> Option<(f64, f64)> {
        (p.z > 0.0).then(|| (self.fx * p.x / p.z + self.cx, self.fy * p.y / p.z + self.cy))
    }

    /// The pixel `(column, row)` whose centre is nearest to image point `(u, v)`, if it
    /// lies inside the image.
    pub fn nearest_pixel(&self, u: f64, v: f64) -> Option<(usize, usize)> {
        let (u, v) = (u + 0.5, v + 0.5);
        // Non-negative, so truncation is the floor (without `floor`'s library call).
        (u >= 0.0 && v >= 0.0 && u < self.width as f64 && v < self.height as f64)
            .then_some((u as usize, v as usize))
    }

    /// The pixel `(column, row)` whose centre is nearest to where `p` (camera frame)
    /// projects, if it lies in front of the camera and inside the image.
    pub fn pixel_of(&self, p: &Point3<f64>) -> Option<(usize, usize)> {
        let (u, v) = self.image_point(p)?;
        self.nearest_pixel(u, v)
    }

    /// Whether the numbers make a camera: a non-empty image, positive finite focal
    /// lengths, a finite principal point.
    pub fn is_valid(&self) -> bool {
        self.width > 0
            && self.height > 0
            && [self.fx, self.fy].iter().all(|f| f.is_finite() && *f > 0.0)
            && self.cx.is_finite()
            && self.cy.is_finite()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// A point on a pixel's ray projects back to that pixel.
        #[test]
        fn rays_project_to_their_pixel(u in 0usize..320, v in 0usize..240, z in 0.1f64..2.0) {
            let k = PinholeIntrinsics::of_camera(&DepthCameraSpec::ipa1110());
            let p = Point3::from(k.ray(u as f64, v as f64) * z);
            prop_assert_eq!(k.pixel_of(&p), Some((u, v)));
        }
    }

    /// The same rays as the camera's own pixel model.
    #[test]
    fn agrees_with_the_camera_spec() {
        let spec = DepthCameraSpec::ipa1110();
        let k = PinholeIntrinsics::of_camera(&spec);
        for (u, v) in [(0, 0), (319, 239), (100, 50)] {
            assert!((k.ray(u as f64, v as f64) - spec.pixel_ray(u, v)).norm() < 1e-12);
        }
    }
}
