//! [`MotionBound`]: how far any point of the robot's collision geometry can move for a
//! joint-space step, and hence how finely a straight joint-space edge must be checked.
//!
//! # The bound
//!
//! Let `o_k` be the point of joint k's axis given by its joint frame (it is fixed both in
//! body k−1 and in body k), `L_j = |o_{j+1} − o_j|` (constant: both points are fixed in
//! body j), and `ρ_b` the largest distance from `o_b` of any point of the collision
//! primitives carried by body b (centre distance plus the primitive's bounding-sphere
//! radius; constant, as both are fixed in body b). Any point of body b ≥ k is within
//!
//! ```text
//! R_k = max_{b ≥ k} ( Σ_{j=k}^{b−1} L_j + ρ_b )
//! ```
//!
//! of `o_k`, hence of axis k, at every configuration: `R_k` is joint k's lever arm. Turning
//! joint k by `δq_k` moves such a point along an arc of length at most `R_k·|δq_k|`, so on
//! a straight joint-space segment `q(s) = q_a + s·Δq` no point of any link moves more than
//! `Σ_k R_k·|Δq_k|` (the motions of the joints add up along the chain). Checking the
//! segment at `n = ⌈Σ_k R_k·|Δq_k| / δ⌉` equal steps guarantees that between consecutive
//! checked configurations no point moves more than δ (default 0.01 m, half a 2 cm voxel).
//! The bound is conservative (distance to a point of the axis, not to the axis). It bounds
//! the length of each point's trajectory, not only the chord, so with the robot padded by
//! δ/2 and free at both ends of every interval, each point is free all along: at any
//! instant it is within δ/2 (along its trajectory) of its position at one of the ends,
//! where it was more than δ/2 from every obstacle. For two links (each padded, so more than
//! δ apart at both ends) the two points' distances travelled from the two ends add up to
//! at most 2δ, so they cannot meet in between either.

use super::CollisionWorld;
use crate::kinematics::{DOF, Joints};

/// Lever arms of the six joints and the resulting edge resolution.
///
/// ```
/// use nbv_core::kinematics::{Joints, Robot};
/// use nbv_core::planning::{CollisionWorld, MotionBound};
/// let path = nbv_core::kinematics::COMAU_URDF;
/// let world = CollisionWorld::new(&Robot::from_urdf_file(path)?, &[])?;
/// let bound = MotionBound::new(&world);
/// // J1 carries the whole arm: its (conservative) lever arm exceeds the 1.4 m reach.
/// let r1 = bound.lever_arms[0];
/// assert!(r1 > 1.4 && r1 < 2.5);
/// // Turning J1 by 0.1 rad is checked every centimetre of the farthest point's motion.
/// let steps = bound.steps(&Joints::zeros(), &Joints::new(0.1, 0.0, 0.0, 0.0, 0.0, 0.0), 0.01);
/// assert_eq!(steps, (0.1 * r1 / 0.01).ceil() as usize);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MotionBound {
    /// `R_k` (m) for joints 1..6.
    pub lever_arms: [f64; DOF],
}

impl MotionBound {
    /// The lever arms of the world's robot (from its collision primitives).
    pub fn new(world: &CollisionWorld) -> Self {
        let robot = world.robot();
        let q0 = Joints::zeros();
        let axes = robot.joint_axes(&q0);
        let frames = robot.link_poses(&q0);
        // ρ_b for bodies 1..=6 (index b − 1); −∞ for a body without geometry.
        let mut rho = [f64::NEG_INFINITY; DOF];
        for s in &world.shapes().shapes {
            if s.body == 0 || s.body > DOF {
                continue;
            }
            let centre = (frames[s.frame] * s.local).translation.vector;
            let d = (centre - axes[s.body - 1].1.coords).norm() + s.radius;
            rho[s.body - 1] = rho[s.body - 1].max(d);
        }
        let mut lever_arms = [0.0; DOF];
        for (k, arm) in lever_arms.iter_mut().enumerate() {
            let mut chain = 0.0;
            for b in k..DOF {
                if b > k {
                    chain += (axes[b].1 - axes[b - 1].1).norm();
                }
                *arm = f64::max(*arm, chain + rho[b]);
            }
        }
        Self { lever_arms }
    }

    /// Upper bound (m) on how far any point of the robot moves along the straight segment
    /// `a → b`.
    pub fn displacement(&self, a: &Joints, b: &Joints) -> f64 {
        (0..DOF)
            .map(|k| self.lever_arms[k] * (b[k] - a[k]).abs())
            .sum()
    }

    /// Number of equal steps (≥ 1) the segment `a → b` is checked at so that no point moves
    /// more than `max_displacement` between checks.
    pub fn steps(&self, a: &Joints, b: &Joints, max_displacement: f64) -> usize {
        let n = (self.displacement(a, b) / max_displacement).ceil();
        if n.is_finite() && n >= 1.0 {
            n as usize
        } else {
            1
        }
    }
}

/// The indices 1..=n in the order a segment is checked: the end first, then the interior
/// by bisection (midpoints of ever finer halves), so a blocked edge is usually rejected
/// after few checks. Every index appears once.
pub(crate) fn bisection_order(n: usize) -> Vec<usize> {
    let mut out = Vec::with_capacity(n);
    if n == 0 {
        return out;
    }
    out.push(n);
    let mut queue = std::collections::VecDeque::from([(0usize, n)]);
    while let Some((lo, hi)) = queue.pop_front() {
        if hi - lo < 2 {
            continue;
        }
        let mid = lo + (hi - lo) / 2;
        out.push(mid);
        queue.push_back((lo, mid));
        queue.push_back((mid, hi));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kinematics::Robot;
    use proptest::prelude::*;

    fn world() -> CollisionWorld {
        let path = crate::kinematics::COMAU_URDF;
        CollisionWorld::new(&Robot::from_urdf_file(path).unwrap(), &[]).unwrap()
    }

    #[test]
    fn bisection_visits_each_index_once() {
        for n in 0..40 {
            let mut o = bisection_order(n);
            if n > 0 {
                assert_eq!(o[0], n);
            }
            o.sort_unstable();
            assert_eq!(o, (1..=n).collect::<Vec<_>>());
        }
        assert_eq!(bisection_order(8), vec![8, 4, 2, 6, 1, 3, 5, 7]);
    }

    #[test]
    fn lever_arms_decrease_along_the_chain() {
        let b = MotionBound::new(&world());
        for k in 1..DOF {
            assert!(
                b.lever_arms[k] <= b.lever_arms[k - 1] + 1e-12,
                "{:?}",
                b.lever_arms
            );
        }
        // J6 carries the bracket and sensors: about 0.2 m.
        assert!(
            b.lever_arms[5] > 0.15 && b.lever_arms[5] < 0.3,
            "{:?}",
            b.lever_arms
        );
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]

        /// Points on every primitive's bounding sphere (which the bound covers) never move
        /// farther than the bound between two configurations.
        #[test]
        fn the_bound_holds_for_random_segments(
            a in prop::array::uniform6(-1.5f64..1.5),
            d in prop::array::uniform6(-0.3f64..0.3),
        ) {
            let w = world();
            let bound = MotionBound::new(&w);
            let qa = Joints::from(a);
            let qb = qa + Joints::from(d);
            let robot = w.robot();
            let fa = robot.link_poses(&qa);
            let fb = robot.link_poses(&qb);
            let limit = bound.displacement(&qa, &qb);
            for s in &w.shapes().shapes {
                let r = s.radius;
                for corner in 0..8 {
                    let p = nalgebra::Point3::new(
                        if corner & 1 == 0 { -r } else { r },
                        if corner & 2 == 0 { -r } else { r },
                        if corner & 4 == 0 { -r } else { r },
                    ) / 3f64.sqrt();
                    let pa = fa[s.frame] * s.local * p;
                    let pb = fb[s.frame] * s.local * p;
                    prop_assert!((pa - pb).norm() <= limit + 1e-9);
                }
            }
        }
    }
}
