//! [`ViewSphere`]: the discretised viewing sphere of Algorithm 2 (lines 2–4), with the
//! duplicate samples removed.

use std::f64::consts::{PI, TAU};

use super::NbvError;

/// Tolerance (rad, relative to a step) of the floor divisions and of the φ wrap test, so
/// that 2π/30° counts 12 whole steps whatever the rounding of π/6.
const STEP_TOLERANCE: f64 = 1e-9;

/// The viewing sphere: radius and the inclination and azimuth steps of Algorithm 2.
///
/// Samples: θ = Δθ·i_θ for i_θ = 0..=⌊θ_max/Δθ⌋ and φ = −π + Δφ·i_φ for
/// i_φ = 0..=⌊2π/Δφ⌋, with two kinds of duplicates removed:
/// - when 2π/Δφ is a whole number, i_φ = ⌊2π/Δφ⌋ gives φ = π, the same azimuth as
///   φ = −π: that last sample is dropped (φ covers [−π, π));
/// - at a pole (sin θ = 0, i.e. θ = 0 and θ = π) every φ gives the same position and the
///   same optical axis, the samples differing only by the roll about that axis: one sample
///   (i_φ = 0) is kept.
///
/// The paper gives no values for Δθ, θ_max and Δφ; its preset
/// ([`NbvPreset::sphere`](super::NbvPreset::sphere)) has 1 + 5·12 = 61 samples. The
/// default is the twin preset's.
///
/// ```
/// use nbv_core::nbv::NbvPreset;
/// let s = NbvPreset::Paper.sphere().samples()?;
/// assert_eq!(s.len(), 61);
/// assert_eq!((s[0].theta, s[0].phi), (0.0, -std::f64::consts::PI));
/// assert_eq!((s[1].i_theta, s[1].i_phi), (1, 0));
/// # Ok::<(), nbv_core::nbv::NbvError>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ViewSphere {
    /// Radius r (m), > 0.
    pub radius: f64,
    /// Inclination step Δθ (rad), > 0.
    pub delta_theta: f64,
    /// Largest inclination θ_max (rad), in [0, π]; θ = 0 is straight above the centroid.
    pub theta_max: f64,
    /// Azimuth step Δφ (rad), in (0, 2π].
    pub delta_phi: f64,
    /// The nearer radius (m) a sample falls back to when no roll of it is reachable at
    /// `radius`, in [0, radius): the far side of an object near the arm's reach lies
    /// beyond it at `radius`. 0: off (Algorithm 2 as printed).
    pub near_radius: f64,
}

impl Default for ViewSphere {
    fn default() -> Self {
        super::NbvPreset::default().sphere()
    }
}

/// One (θ, φ) sample of the sphere with its indices.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SphereSample {
    /// i_θ.
    pub i_theta: usize,
    /// i_φ.
    pub i_phi: usize,
    /// θ = Δθ·i_θ (rad).
    pub theta: f64,
    /// φ = −π + Δφ·i_φ (rad).
    pub phi: f64,
}

impl ViewSphere {
    /// Checks the ranges given in the field docs.
    pub fn validate(&self) -> Result<(), NbvError> {
        let bad = |name, value, reason| {
            Err(NbvError::InvalidParameter {
                name,
                value,
                reason,
            })
        };
        if !(self.radius.is_finite() && self.radius > 0.0) {
            return bad("radius", self.radius, "must be finite and > 0");
        }
        if !(self.near_radius >= 0.0 && self.near_radius < self.radius) {
            return bad("near_radius", self.near_radius, "must be in [0, radius)");
        }
        if !(self.delta_theta.is_finite() && self.delta_theta > 0.0) {
            return bad("delta_theta", self.delta_theta, "must be finite and > 0");
        }
        if !(self.theta_max >= 0.0 && self.theta_max <= PI) {
            return bad("theta_max", self.theta_max, "must be in [0, π]");
        }
        if !(self.delta_phi > 0.0 && self.delta_phi <= TAU) {
            return bad("delta_phi", self.delta_phi, "must be in (0, 2π]");
        }
        Ok(())
    }

    /// The same sphere at half its steps: every sample of this one and those between.
    ///
    /// ```
    /// use nbv_core::nbv::NbvPreset;
    /// let sphere = NbvPreset::Paper.sphere();
    /// // Δθ 7.5° to 75° and Δφ 15°: 1 + 10·24 samples.
    /// assert_eq!(sphere.refined().samples()?.len(), 241);
    /// # Ok::<(), nbv_core::nbv::NbvError>(())
    /// ```
    pub fn refined(self) -> Self {
        Self {
            delta_theta: self.delta_theta / 2.0,
            delta_phi: self.delta_phi / 2.0,
            ..self
        }
    }

    /// The samples in Algorithm 2's loop order (i_θ outer, i_φ inner), duplicates removed
    /// (see the type's doc).
    pub fn samples(&self) -> Result<Vec<SphereSample>, NbvError> {
        self.validate()?;
        let n_theta = (self.theta_max / self.delta_theta + STEP_TOLERANCE).floor() as usize;
        let n_phi = (TAU / self.delta_phi + STEP_TOLERANCE).floor() as usize;
        let mut out = Vec::with_capacity((n_theta + 1) * (n_phi + 1));
        for i_theta in 0..=n_theta {
            let theta = self.delta_theta * i_theta as f64;
            let pole = theta.sin().abs() < 1e-12;
            for i_phi in 0..=n_phi {
                let offset = self.delta_phi * i_phi as f64;
                // φ = π repeats φ = −π.
                if offset >= TAU - STEP_TOLERANCE * self.delta_phi {
                    continue;
                }
                if pole && i_phi > 0 {
                    continue;
                }
                out.push(SphereSample {
                    i_theta,
                    i_phi,
                    theta,
                    phi: -PI + offset,
                });
            }
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nbv::view_position;
    use nalgebra::Point3;

    #[test]
    fn counts_with_and_without_the_wrap_duplicate() {
        let deg = |d: f64| d.to_radians();
        let count = |dt: f64, tmax: f64, dp: f64| {
            ViewSphere {
                radius: 0.3,
                delta_theta: deg(dt),
                theta_max: deg(tmax),
                delta_phi: deg(dp),
                near_radius: 0.0,
            }
            .samples()
            .unwrap()
            .len()
        };
        // 360/30 = 12 exactly: i_φ = 12 (φ = π) dropped; pole once; 5 rings of 12.
        assert_eq!(count(15.0, 75.0, 30.0), 61);
        // 360/45 = 8: 1 + 2·8.
        assert_eq!(count(30.0, 60.0, 45.0), 17);
        // 360/50 = 7.2: i_φ = 0..=7, none at π, all kept: 1 + 1·8.
        assert_eq!(count(40.0, 79.0, 50.0), 9);
        // θ_max = 0: the pole only.
        assert_eq!(count(15.0, 0.0, 30.0), 1);
        // θ up to 180°: both poles collapse: 1 + 11·12 + 1.
        assert_eq!(count(15.0, 180.0, 30.0), 134);
    }

    #[test]
    fn samples_are_distinct_positions() {
        let s = crate::nbv::NbvPreset::Paper.sphere().samples().unwrap();
        let c = Point3::origin();
        for (i, a) in s.iter().enumerate() {
            assert!(a.phi >= -PI && a.phi < PI);
            for b in &s[i + 1..] {
                let d = (view_position(&c, 0.3, a.theta, a.phi)
                    - view_position(&c, 0.3, b.theta, b.phi))
                .norm();
                assert!(d > 0.03, "{a:?} {b:?} {d}");
            }
        }
        // Loop order: i_θ outer, i_φ inner.
        assert_eq!((s[12].i_theta, s[12].i_phi), (1, 11));
        assert_eq!((s[13].i_theta, s[13].i_phi), (2, 0));
        assert!((s[13].theta - 30f64.to_radians()).abs() < 1e-15);
        assert!((s[12].phi - 150f64.to_radians()).abs() < 1e-12);
    }

    #[test]
    fn invalid_spheres() {
        let d = ViewSphere::default();
        for bad in [
            ViewSphere { radius: 0.0, ..d },
            ViewSphere {
                radius: f64::NAN,
                ..d
            },
            ViewSphere {
                delta_theta: 0.0,
                ..d
            },
            ViewSphere {
                near_radius: d.radius,
                ..d
            },
            ViewSphere {
                theta_max: 4.0,
                ..d
            },
            ViewSphere {
                delta_phi: 7.0,
                ..d
            },
        ] {
            assert!(matches!(
                bad.samples(),
                Err(NbvError::InvalidParameter { .. })
            ));
        }
    }
}
