//! [`apply_movement_cost`]: Isler et al.'s utility with a movement cost,
//!
//! ```text
//! U(v) = G(v) / Σ_{v'} G(v')  −  λ · c(v) / Σ_{v'} c(v')
//! ```
//!
//! over the candidates of one round, for any objective's G (eq. (4)'s score included).
//!
//! c(v) is the joint-space length (rad) of the **planned** motion to the candidate, found
//! without planning every candidate (RRT-Connect for tens of candidates per round would cost
//! more than the rest of the round). [`apply_movement_cost`] ranks the candidates with the
//! straight joint-space distance to each one's nearest IK goal, a lower bound of any planned
//! path's length, so each utility is an upper bound of the true one; the normaliser Σc is
//! the straight distances' sum and stays fixed. [`lazy_best`] then plans best first: it
//! plans the candidate with the highest bound, replaces the bound by the true utility, and
//! stops when the best candidate is planned — its true utility is at least every other
//! bound, so it is the exact argmax of U, usually after a few plans (lazy evaluation, as in
//! lazy PRM: Bohlin & Kavraki, ICRA 2000). The path it planned is the one executed.
//!
//! With λ = 0 the utility is G itself (the same order as G/ΣG), so the default ranking is
//! untouched bit for bit.

use super::super::{Candidate, Viewpoint, compare_best_first, sort_best_first};
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
        let total_cost = finite_sum(&costs);
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

/// Σc: the straight joint-space distances from `start` to `candidates` (those with a goal).
pub fn movement_cost_total(candidates: &[Candidate], start: &Joints) -> f64 {
    let costs: Vec<f64> = candidates
        .iter()
        .map(|c| joint_distance(start, &c.viewpoint))
        .collect();
    finite_sum(&costs)
}

/// Σ of the finite costs (a candidate without a goal has c = ∞ and no share).
fn finite_sum(costs: &[f64]) -> f64 {
    costs.iter().filter(|c| c.is_finite()).sum()
}

/// The candidate of `candidates` (ranked by [`apply_movement_cost`] from `start` with
/// weight `lambda` and normaliser `total_cost`) that maximises U with c the length
/// `length` of the path `plan` finds to it, removed from the list with that path; or the
/// first candidate whose planning failed, with its error (the caller reports it and asks
/// again); `None` when no candidate is left. Candidates planned but not chosen stay in the
/// list with their true utility.
///
/// ```
/// use nbv_core::nbv::lazy_best;
/// use nbv_core::kinematics::Joints;
/// let mut none = Vec::new();
/// let best = lazy_best(&mut none, &Joints::zeros(), 1.0, 1.0, |_| Ok::<f64, ()>(0.0), |l| *l);
/// assert!(best.is_none());
/// ```
pub fn lazy_best<P, E>(
    candidates: &mut Vec<Candidate>,
    start: &Joints,
    lambda: f64,
    total_cost: f64,
    mut plan: impl FnMut(&Candidate) -> Result<P, E>,
    length: impl Fn(&P) -> f64,
) -> Option<(Candidate, Result<P, E>)> {
    let mut planned: Vec<Option<P>> = candidates.iter().map(|_| None).collect();
    loop {
        if candidates.is_empty() {
            return None;
        }
        if let Some(path) = planned[0].take() {
            return Some((candidates.remove(0), Ok(path)));
        }
        let path = match plan(&candidates[0]) {
            Ok(path) => path,
            Err(e) => return Some((candidates.remove(0), Err(e))),
        };
        let straight = joint_distance(start, &candidates[0].viewpoint);
        if total_cost > 0.0 && straight.is_finite() {
            candidates[0].utility -= lambda * (length(&path) - straight).max(0.0) / total_cost;
        }
        // Only the first candidate's utility changed (it fell): move it, with its path, to
        // its place among the rest, which stay in order.
        let c = candidates.remove(0);
        planned.remove(0);
        let at = candidates.partition_point(|o| compare_best_first(o, &c).is_lt());
        candidates.insert(at, c);
        planned.insert(at, Some(path));
    }
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
        // Back to λ = 0: utility is the score again (below).
        apply_movement_cost(&mut c, &Joints::zeros(), 0.0);
        assert_eq!((c[0].score, c[0].utility), (3.0, 3.0));
    }

    /// Planned lengths longer than the straight distances: the far-but-straight candidate
    /// wins once the near one's path turns out long, after planning only those two.
    #[test]
    fn lazy_best_plans_until_the_best_is_exact() {
        // Gains 1, 1, 1 (shares 1/3); straight distances √6·{0.1, 0.2, 0.3} (Σ = √6·0.6).
        let start = Joints::zeros();
        let mut c = vec![
            candidate(0, 1.0, 0.1),
            candidate(1, 1.0, 0.2),
            candidate(2, 1.0, 0.3),
        ];
        apply_movement_cost(&mut c, &start, 1.0);
        let total = movement_cost_total(&c, &start);
        assert!((total - 6f64.sqrt() * 0.6).abs() < 1e-12);
        // Planned lengths: candidate 0 detours (3× its straight distance), 1 and 2 are straight.
        let lengths = [6f64.sqrt() * 0.3, 6f64.sqrt() * 0.2, 6f64.sqrt() * 0.3];
        let mut plans = Vec::new();
        let best = lazy_best(
            &mut c,
            &start,
            1.0,
            total,
            |cand: &Candidate| {
                plans.push(cand.viewpoint.sample.i_theta);
                Ok::<f64, ()>(lengths[cand.viewpoint.sample.i_theta])
            },
            |l| *l,
        );
        let (chosen, path) = best.expect("a candidate");
        // U: 1/3 − 0.3/0.6, 1/3 − 0.2/0.6, 1/3 − 0.3/0.6 → candidate 1; 2 is never planned.
        assert_eq!(chosen.viewpoint.sample.i_theta, 1);
        assert_eq!(path, Ok(lengths[1]));
        assert_eq!(plans, vec![0, 1]);
        assert!((chosen.utility - (1.0 / 3.0 - 0.2 / 0.6)).abs() < 1e-12);
        // What stays: candidate 0 with its true utility, ranked below 2's bound.
        let left: Vec<_> = c.iter().map(|c| c.viewpoint.sample.i_theta).collect();
        assert_eq!(left, vec![0, 2]);
        assert!((c[0].utility - (1.0 / 3.0 - 0.3 / 0.6)).abs() < 1e-12);
        // A failed plan comes back with its candidate.
        let failed = lazy_best(
            &mut c,
            &start,
            1.0,
            total,
            |_| Err::<f64, &str>("no path"),
            |l| *l,
        );
        assert_eq!(
            failed.map(|(c, r)| (c.viewpoint.sample.i_theta, r)),
            Some((0, Err("no path")))
        );
    }
}
