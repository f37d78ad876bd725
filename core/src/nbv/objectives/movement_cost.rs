//! [`apply_movement_cost`]: Isler et al.'s utility with a movement cost,
//!
//! ```text
//! U(v) = G(v) / Σ_{v'} G(v')  −  λ · c(v) / Σ_{v'} c(v')
//! ```
//!
//! over the candidates of one round, for any objective's G (eq. (4)'s score included).
//!
//! c(v) is the **straight joint-space distance** (Euclidean norm of the joint differences,
//! rad) from the arm's current joints to the nearest of the candidate's IK goals — not the
//! length of a planned path: planning every candidate (RRT-Connect, tens of candidates per
//! round) would cost more than the rest of the round. The planner's path to the chosen goal
//! is at least this long; around obstacles it can be much longer.
//!
//! With λ = 0 the utility is G itself (the same order as G/ΣG), so the default ranking is
//! untouched bit for bit.

use super::super::{Candidate, Viewpoint, sort_best_first};
use crate::kinematics::Joints;

/// c(v): the straight joint-space distance from `start` to the nearest IK goal of
/// `viewpoint` (∞ without a goal).
pub fn joint_distance(start: &Joints, viewpoint: &Viewpoint) -> f64 {
    viewpoint
        .solutions
        .iter()
        .map(|s| (s.joints - start).norm())
        .fold(f64::INFINITY, f64::min)
}

/// Sets each candidate's `utility` to U(v) with weight `lambda` (λ ≥ 0) from `start` and
/// sorts them best first. λ = 0 leaves `utility = score` and the order of
/// [`sort_best_first`].
///
/// ```
/// use nbv_core::nbv::apply_movement_cost;
/// use nbv_core::kinematics::Joints;
/// let mut none = Vec::new();
/// apply_movement_cost(&mut none, &Joints::zeros(), 1.0);
/// assert!(none.is_empty());
/// ```
pub fn apply_movement_cost(candidates: &mut [Candidate], start: &Joints, lambda: f64) {
    if lambda == 0.0 {
        for c in candidates.iter_mut() {
            c.utility = c.score;
        }
    } else {
        let costs: Vec<f64> = candidates
            .iter()
            .map(|c| joint_distance(start, &c.viewpoint))
            .collect();
        let total_gain: f64 = candidates.iter().map(|c| c.score).sum();
        let total_cost: f64 = costs.iter().filter(|c| c.is_finite()).sum();
        for (c, cost) in candidates.iter_mut().zip(costs) {
            let g = if total_gain > 0.0 {
                c.score / total_gain
            } else {
                0.0
            };
            let m = if total_cost > 0.0 && cost.is_finite() {
                cost / total_cost
            } else {
                0.0
            };
            c.utility = g - lambda * m;
        }
    }
    sort_best_first(candidates);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kinematics::{Branch, Elbow, IkSolution, Shoulder, Singularity, Wrist};
    use crate::math::Pose;
    use crate::nbv::{SphereSample, VisibleVoxels};

    fn candidate(i: usize, score: f64, goal: f64) -> Candidate {
        let solution = IkSolution {
            joints: Joints::from_element(goal),
            branch: Branch {
                shoulder: Shoulder::Front,
                elbow: Elbow::Up,
                wrist: Wrist::Positive,
            },
            singularity: Singularity::default(),
        };
        Candidate {
            viewpoint: Viewpoint {
                sample: SphereSample {
                    i_theta: i,
                    i_phi: 0,
                    theta: 0.0,
                    phi: 0.0,
                },
                roll: 0.0,
                pose: Pose::identity(),
                solutions: vec![solution],
            },
            visible: VisibleVoxels::default(),
            score,
            utility: score,
        }
    }

    #[test]
    fn hand_computed_utility() {
        // Gains 3 and 1 (shares 0.75, 0.25); distances √6·1 and √6·0.2 (shares 5/6, 1/6).
        let mut c = vec![candidate(0, 3.0, 1.0), candidate(1, 1.0, 0.2)];
        apply_movement_cost(&mut c, &Joints::zeros(), 0.0);
        assert_eq!(c[0].viewpoint.sample.i_theta, 0);
        apply_movement_cost(&mut c, &Joints::zeros(), 1.0);
        // U = 0.75 − 5/6 = −0.0833 and 0.25 − 1/6 = 0.0833: the near one wins.
        assert_eq!(c[0].viewpoint.sample.i_theta, 1);
        assert!((c[0].utility - (0.25 - 1.0 / 6.0)).abs() < 1e-12);
        assert!((c[1].utility - (0.75 - 5.0 / 6.0)).abs() < 1e-12);
        assert!((joint_distance(&Joints::zeros(), &c[1].viewpoint) - 6f64.sqrt()).abs() < 1e-12);
        // Back to λ = 0: utility is the score again.
        apply_movement_cost(&mut c, &Joints::zeros(), 0.0);
        assert_eq!((c[0].score, c[0].utility), (3.0, 3.0));
    }
}
