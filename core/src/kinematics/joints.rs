//! Joint vectors of the six-axis arm and the limits of one revolute joint.

use nalgebra::SVector;
use serde::{Deserialize, Serialize};
use std::f64::consts::{PI, TAU};

/// Number of revolute joints of the arms this module handles.
pub const DOF: usize = 6;

/// Joint angles J1..J6 in radians, in chain order (base to flange).
///
/// A fixed-size `nalgebra` vector rather than an array so that differences, norms and
/// interpolation come for free; build one with `Joints::new(q1, …, q6)` or
/// `Joints::from([q1, …, q6])`.
///
/// ```
/// use nbv_core::kinematics::Joints;
/// let a = Joints::new(0.0, 0.0, -std::f64::consts::FRAC_PI_2, 0.0, 0.0, 0.0);
/// let b = Joints::from([0.1, 0.0, -1.5, 0.0, 0.0, 0.0]);
/// assert!((a - b).norm() > 0.0);
/// ```
pub type Joints = SVector<f64, DOF>;

/// Limits of one revolute joint, as the URDF `<limit>` element gives them.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct JointLimit {
    /// Lowest position (rad).
    pub lower: f64,
    /// Highest position (rad).
    pub upper: f64,
    /// Largest speed (rad/s).
    pub velocity: f64,
    /// Largest effort (N·m); informative only.
    pub effort: f64,
}

impl JointLimit {
    /// Whether `q` lies within `[lower, upper]`.
    ///
    /// ```
    /// use nbv_core::kinematics::JointLimit;
    /// let l = JointLimit { lower: -1.0, upper: 2.0, velocity: 1.0, effort: 0.0 };
    /// assert!(l.contains(2.0) && !l.contains(2.1));
    /// ```
    pub fn contains(&self, q: f64) -> bool {
        q >= self.lower && q <= self.upper
    }

    /// The middle of the range (rad).
    pub fn centre(&self) -> f64 {
        0.5 * (self.lower + self.upper)
    }

    /// The angle congruent to `q` modulo 2π that lies within the limits (widened by `tol`,
    /// then clamped back into them) and is nearest to `target`; `None` if there is none.
    pub(crate) fn representative_near(&self, q: f64, target: f64, tol: f64) -> Option<f64> {
        if !q.is_finite() || !target.is_finite() {
            return None;
        }
        let k_min = ((self.lower - tol - q) / TAU).ceil();
        let k_max = ((self.upper + tol - q) / TAU).floor();
        if k_min > k_max {
            return None;
        }
        let k = ((target - q) / TAU).round().clamp(k_min, k_max);
        Some((q + TAU * k).clamp(self.lower, self.upper))
    }
}

/// Wraps an angle into `(-π, π]`.
pub(crate) fn wrap_to_pi(a: f64) -> f64 {
    let w = a - TAU * ((a + PI) / TAU).floor();
    // `w` lies in [-π, π); move -π to π.
    if w <= -PI { w + TAU } else { w }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    const J6: JointLimit = JointLimit {
        lower: -47.1238898038469,
        upper: 47.1238898038469,
        velocity: 9.6,
        effort: 7.0,
    };

    #[test]
    fn wrap_is_half_open() {
        assert!((wrap_to_pi(PI) - PI).abs() < 1e-15);
        assert!((wrap_to_pi(-PI) - PI).abs() < 1e-15);
        assert!((wrap_to_pi(3.0 * PI) - PI).abs() < 1e-12);
        assert!((wrap_to_pi(0.5) - 0.5).abs() < 1e-15);
    }

    #[test]
    fn representative_outside_narrow_range_is_none() {
        let l = JointLimit {
            lower: -1.0,
            upper: 1.0,
            velocity: 1.0,
            effort: 0.0,
        };
        assert_eq!(l.representative_near(2.0, 0.0, 1e-10), None);
        assert_eq!(l.representative_near(f64::NAN, 0.0, 1e-10), None);
        // Just outside, within the tolerance: clamped onto the limit.
        assert_eq!(l.representative_near(1.0 + 1e-12, 0.0, 1e-10), Some(1.0));
    }

    proptest! {
        #[test]
        fn representative_is_congruent_in_range_and_nearest(q in -PI..PI, target in -47.0f64..47.0) {
            let r = J6.representative_near(q, target, 0.0).unwrap();
            prop_assert!(J6.contains(r));
            let k = (r - q) / TAU;
            prop_assert!((k - k.round()).abs() < 1e-9);
            // No other representative inside the range is nearer to the target.
            for other in [r - TAU, r + TAU] {
                if J6.contains(other) {
                    prop_assert!((r - target).abs() <= (other - target).abs() + 1e-12);
                }
            }
        }

        #[test]
        fn wrap_stays_congruent(a in -100.0f64..100.0) {
            let w = wrap_to_pi(a);
            prop_assert!(w > -PI && w <= PI);
            let k = (a - w) / TAU;
            prop_assert!((k - k.round()).abs() < 1e-9);
        }
    }
}
