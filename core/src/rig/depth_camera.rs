//! [`DepthCamera`]: a time-of-flight/structured-light camera (Dinast IPA-1110 class) that
//! returns organised depth frames.
//!
//! Optical frame: z forward, x to the image's right, y down the image. Pixel `(u, v)` (u
//! the column) looks along `((u + 0.5 − cx)/fx, (v + 0.5 − cy)/fy, 1)`.

use super::{RigError, TruthHit};
use nalgebra::{Point3, Vector3};

/// What the pipeline needs to know of a depth camera (pinhole model).
#[derive(Debug, Clone, PartialEq)]
pub struct DepthCameraSpec {
    /// Name of the sensor frame on the robot model (URDF link), e.g. `dinast`.
    pub frame: String,
    /// Minimum and maximum range of a valid return (distance along the ray), metres.
    pub range: [f64; 2],
    /// Image width, pixels.
    pub width: usize,
    /// Image height, pixels.
    pub height: usize,
    /// Horizontal field of view, radians.
    pub hfov: f64,
}

impl DepthCameraSpec {
    /// The Dinast IPA-1110 as the paper uses it: 320×240 pixels, 80° horizontal field of
    /// view, returns from 0.1 to 0.8 m, URDF frame `dinast`.
    ///
    /// ```
    /// let spec = nbv_core::rig::DepthCameraSpec::ipa1110();
    /// assert!((spec.focal() - 160.0 / 40f64.to_radians().tan()).abs() < 1e-12);
    /// ```
    pub fn ipa1110() -> Self {
        Self {
            frame: "dinast".into(),
            range: [0.1, 0.8],
            width: 320,
            height: 240,
            hfov: 80f64.to_radians(),
        }
    }

    /// Focal length in pixels (square pixels, principal point at the image centre).
    pub fn focal(&self) -> f64 {
        0.5 * self.width as f64 / (0.5 * self.hfov).tan()
    }

    /// Unnormalised ray direction of pixel `(u, v)` with z = 1, in the sensor frame.
    pub fn pixel_ray(&self, u: usize, v: usize) -> Vector3<f64> {
        let f = self.focal();
        Vector3::new(
            (u as f64 + 0.5 - 0.5 * self.width as f64) / f,
            (v as f64 + 0.5 - 0.5 * self.height as f64) / f,
            1.0,
        )
    }
}

/// One organised depth frame.
#[derive(Debug, Clone, PartialEq)]
pub struct DepthFrame {
    /// Rig time of the exposure, seconds.
    pub time: f64,
    /// Width, pixels.
    pub width: usize,
    /// Height, pixels.
    pub height: usize,
    /// Depth (z in the optical frame) per pixel, row-major, metres; NaN where invalid.
    pub depth: Vec<f32>,
    /// Ground truth per pixel (the twin only).
    pub truth: Option<Vec<Option<TruthHit>>>,
}

impl DepthFrame {
    /// Pixel `(u, v)`'s return as a point in the sensor frame, if valid.
    pub fn point(&self, spec: &DepthCameraSpec, u: usize, v: usize) -> Option<Point3<f64>> {
        let z = f64::from(*self.depth.get(v * self.width + u)?);
        if !z.is_finite() {
            return None;
        }
        Some(Point3::from(spec.pixel_ray(u, v) * z))
    }

    /// σ (m) at depth `z` of a burst of eight IPA-1110 frames averaged: 4 cm at 1 m, over
    /// √8. The noise of [`Self::averaged_burst`].
    #[cfg(test)]
    pub(crate) fn burst_sigma(z: f64) -> f64 {
        0.04 * z / 8f64.sqrt()
    }

    /// A test frame of `spec`'s size at time 0: each pixel's true depth `depth(ray)` (its
    /// unnormalised ray, `None` for no return) through [`Self::burst_sigma`]'s normal
    /// noise, one draw per pixel in row-major order from a ChaCha8 stream seeded by `seed`.
    #[cfg(test)]
    pub(crate) fn averaged_burst(
        spec: &DepthCameraSpec,
        seed: u64,
        depth: impl Fn(&Vector3<f64>) -> Option<f64>,
    ) -> Self {
        use rand::SeedableRng;
        use rand_distr::{Distribution, Normal};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let unit = Normal::new(0.0, 1.0).expect("σ = 1 is a valid normal");
        let depth = (0..spec.width * spec.height)
            .map(|i| {
                let n: f64 = unit.sample(&mut rng);
                let ray = spec.pixel_ray(i % spec.width, i / spec.width);
                depth(&ray).map_or(f32::NAN, |z| (z + Self::burst_sigma(z) * n) as f32)
            })
            .collect();
        Self {
            time: 0.0,
            width: spec.width,
            height: spec.height,
            depth,
            truth: None,
        }
    }
}

/// A depth camera.
pub trait DepthCamera {
    /// The camera's specification.
    fn spec(&self) -> &DepthCameraSpec;

    /// Captures one frame at the arm's current pose.
    fn capture(&mut self) -> Result<DepthFrame, RigError>;
}
