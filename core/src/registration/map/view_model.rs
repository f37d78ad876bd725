//! [`ViewModel`]: what the maximum a posteriori registration knows about a view besides
//! its points — the range noise of the sensor that took it ([`RangeNoise`]) and how far its
//! reported pose may be off ([`PosePrior`]).
//!
//! A view's pose correction is parameterised about its sensor origin `o` (the view's
//! `origins` column, else its centroid): `x ↦ R(ω)·(x − o) + o + t`, with `ω` a rotation
//! vector and `t` a translation, both in the world frame. A sensor's pose error (a
//! rotation and a translation in the sensor frame, as a hand-eye error or a reported
//! pose's noise) maps onto exactly this form with the same magnitudes, which is why the
//! prior is isotropic per component.

use nalgebra::{Matrix6, Vector6};
use serde::{Deserialize, Serialize};

/// Range noise of a sensor: `σ(d) = sigma_at_1m · d^exponent` along the viewing ray (d in
/// metres). The LMS400 is `exponent = 0` (constant); the Dinast's σ grows linearly.
///
/// ```
/// use nbv_core::registration::RangeNoise;
/// let laser = RangeNoise::constant(0.002);
/// assert_eq!(laser.sigma(2.5), 0.002);
/// let camera = RangeNoise { sigma_at_1m: 0.04, exponent: 1.0 }.averaged(4);
/// assert!((camera.sigma(0.5) - 0.01).abs() < 1e-12); // 2 cm at 0.5 m, halved by 4 frames
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RangeNoise {
    /// σ at 1 m range (m).
    pub sigma_at_1m: f64,
    /// Exponent of the range.
    pub exponent: f64,
}

impl RangeNoise {
    /// Noise independent of range.
    pub fn constant(sigma: f64) -> Self {
        Self {
            sigma_at_1m: sigma,
            exponent: 0.0,
        }
    }

    /// σ at range `d` (m).
    pub fn sigma(&self, d: f64) -> f64 {
        self.sigma_at_1m * d.max(1e-3).powf(self.exponent)
    }

    /// The noise of the mean of `frames` independent frames (σ/√frames).
    pub fn averaged(self, frames: usize) -> Self {
        Self {
            sigma_at_1m: self.sigma_at_1m / (frames.max(1) as f64).sqrt(),
            ..self
        }
    }

    /// Whether both numbers are finite, σ is positive and the exponent is at least 0.
    pub fn is_valid(&self) -> bool {
        self.sigma_at_1m.is_finite()
            && self.sigma_at_1m > 0.0
            && self.exponent.is_finite()
            && self.exponent >= 0.0
    }
}

impl Default for RangeNoise {
    /// The LMS400's ±4 mm as a constant 2 mm σ.
    fn default() -> Self {
        Self::constant(0.002)
    }
}

/// Gaussian prior on a view's pose correction: independent zero-mean components, σ per
/// rotation-vector component (rad) and per translation component (m), about the view's
/// sensor origin.
///
/// ```
/// use nbv_core::registration::PosePrior;
/// use nalgebra::Vector6;
/// let p = PosePrior { rotation_sigma: 0.01, translation_sigma: 0.002 };
/// // One σ on every component: χ² = 6.
/// let xi = Vector6::new(0.01, -0.01, 0.01, 0.002, 0.002, -0.002);
/// assert!((p.chi2(&xi) - 6.0).abs() < 1e-9);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PosePrior {
    /// σ of each component of the rotation vector (rad).
    pub rotation_sigma: f64,
    /// σ of each translation component (m).
    pub translation_sigma: f64,
}

impl PosePrior {
    /// The inverse covariance, rotation first.
    pub fn information(&self) -> Matrix6<f64> {
        let (r, t) = (
            1.0 / (self.rotation_sigma * self.rotation_sigma),
            1.0 / (self.translation_sigma * self.translation_sigma),
        );
        Matrix6::from_diagonal(&Vector6::new(r, r, r, t, t, t))
    }

    /// Mahalanobis χ² (6 degrees of freedom) of a correction `(ω, t)`.
    pub fn chi2(&self, xi: &Vector6<f64>) -> f64 {
        xi.dot(&(self.information() * xi))
    }

    /// σ of the displacement of a point `range` (m) from the sensor under this pose error:
    /// the translation's σ plus the rotation's lever, added as in the worst direction.
    ///
    /// ```
    /// use nbv_core::registration::PosePrior;
    /// let p = PosePrior { rotation_sigma: 0.001, translation_sigma: 0.002 };
    /// assert!((p.point_sigma(1.5) - 0.0035).abs() < 1e-12);
    /// ```
    pub fn point_sigma(&self, range: f64) -> f64 {
        self.translation_sigma + range * self.rotation_sigma
    }

    /// Whether both σ are finite and positive.
    pub fn is_valid(&self) -> bool {
        [self.rotation_sigma, self.translation_sigma]
            .iter()
            .all(|s| s.is_finite() && *s > 0.0)
    }
}

/// The noise of a view's points and the prior on its pose; `prior: None` leaves the pose
/// to the data alone (the reference view's prior is never used: it is fixed).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct ViewModel {
    /// Range noise of the sensor that took the view.
    pub noise: RangeNoise,
    /// Prior on the view's pose correction.
    pub prior: Option<PosePrior>,
}
