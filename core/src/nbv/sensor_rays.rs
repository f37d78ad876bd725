//! [`SensorRays`]: the predicted sensor's ray set D of Algorithm 2 — a subsampled set of the
//! depth camera's pinhole rays — and its range interval [r_min, r_max].

use nalgebra::Vector3;

use super::NbvError;
use crate::rig::DepthCameraSpec;

/// Ray directions in the sensor (optical) frame, unit length, and the range interval.
///
/// Built from a [`DepthCameraSpec`] by keeping every `stride`-th pixel in u and in v,
/// starting at pixel `stride / 2` (so the kept pixels sit near the centres of
/// `stride × stride` blocks): pixel `(u, v)` looks along
/// [`DepthCameraSpec::pixel_ray`]`(u, v)`. The Dinast's 320×240 image with the default
/// stride 8 gives 40 × 30 = 1200 rays.
///
/// ```
/// use nbv_core::nbv::SensorRays;
/// use nbv_core::rig::DepthCameraSpec;
/// let spec = DepthCameraSpec::ipa1110();
/// let rays = SensorRays::from_camera(&spec, 8)?;
/// assert_eq!(rays.directions.len(), 1200);
/// assert_eq!(rays.range, [0.1, 0.8]);
/// # Ok::<(), nbv_core::nbv::NbvError>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct SensorRays {
    /// Unit directions in the sensor frame (z forward), row-major over the kept pixels.
    pub directions: Vec<Vector3<f64>>,
    /// `[r_min, r_max]` (m): a voxel is observed if the distance to its entry point lies
    /// in this closed interval.
    pub range: [f64; 2],
}

impl SensorRays {
    /// Every `stride`-th pixel of the camera (stride ≥ 1).
    pub fn from_camera(spec: &DepthCameraSpec, stride: usize) -> Result<Self, NbvError> {
        if stride == 0 {
            return Err(NbvError::InvalidParameter {
                name: "ray stride",
                value: 0.0,
                reason: "must be >= 1",
            });
        }
        if spec.width == 0 || spec.height == 0 {
            return Err(NbvError::InvalidInput("camera image has no pixel"));
        }
        if !(spec.hfov > 0.0 && spec.hfov < std::f64::consts::PI) {
            return Err(NbvError::InvalidParameter {
                name: "camera hfov",
                value: spec.hfov,
                reason: "must be in (0, π)",
            });
        }
        let first = stride / 2;
        let mut directions = Vec::new();
        for v in (first..spec.height).step_by(stride) {
            for u in (first..spec.width).step_by(stride) {
                directions.push(spec.pixel_ray(u, v).normalize());
            }
        }
        Self::new(directions, spec.range)
    }

    /// Explicit directions (any non-zero length; they are normalised) and range.
    pub fn new(directions: Vec<Vector3<f64>>, range: [f64; 2]) -> Result<Self, NbvError> {
        let [r_min, r_max] = range;
        if !(r_min >= 0.0 && r_max.is_finite() && r_min <= r_max) {
            return Err(NbvError::InvalidParameter {
                name: "sensor range",
                value: r_max,
                reason: "needs 0 <= r_min <= r_max < ∞",
            });
        }
        let mut out = Vec::with_capacity(directions.len());
        for d in directions {
            let n = d.norm();
            if !(n.is_finite() && n > 0.0) {
                return Err(NbvError::InvalidInput(
                    "a ray direction is zero or not finite",
                ));
            }
            out.push(d / n);
        }
        Ok(Self {
            directions: out,
            range,
        })
    }

    /// Number of rays.
    pub fn len(&self) -> usize {
        self.directions.len()
    }

    /// Whether there is no ray.
    pub fn is_empty(&self) -> bool {
        self.directions.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dinast() -> DepthCameraSpec {
        DepthCameraSpec::ipa1110()
    }

    #[test]
    fn subsampled_pixels_and_field_of_view() {
        let spec = dinast();
        let all = SensorRays::from_camera(&spec, 1).unwrap();
        assert_eq!(all.len(), 76_800);
        let rays = SensorRays::from_camera(&spec, 8).unwrap();
        assert_eq!(rays.len(), 40 * 30);
        // First ray: pixel (4, 4); last: pixel (316, 236).
        assert!((rays.directions[0] - spec.pixel_ray(4, 4).normalize()).norm() < 1e-15);
        assert!((rays.directions[1199] - spec.pixel_ray(316, 236).normalize()).norm() < 1e-15);
        // All unit, forward, within the 80° horizontal field of view.
        let half = 40f64.to_radians();
        for d in &rays.directions {
            assert!((d.norm() - 1.0).abs() < 1e-12 && d.z > 0.0);
            assert!(d.x.atan2(d.z).abs() < half);
        }
        assert_eq!(SensorRays::from_camera(&spec, 7).unwrap().len(), 46 * 34);
        assert!(SensorRays::from_camera(&spec, 0).is_err());
        assert!(SensorRays::new(vec![Vector3::zeros()], [0.1, 0.8]).is_err());
        assert!(SensorRays::new(vec![Vector3::z()], [0.9, 0.8]).is_err());
    }
}
