//! The pipeline's default registration: a maximum a posteriori estimate of every view's
//! pose, the reference view fixed as the anchor (multi-view LM-ICP with priors; Fantoni et
//! al. 2012, with each sensor's range noise along its rays and a prior from the rig's pose
//! uncertainty).
//!
//! The objective is `F = Σ_pairs weight·ρ(data) + Σ_views ½·ξᵀ Λ ξ`:
//! - the data term ([`terms`]): every point of a non-reference view
//!   matched into the reference view (one way) and into each overlapping other view (both
//!   ways, half weight each), residuals weighted by both sensors' range noise along their
//!   rays, point-to-plane where the target's plane is well determined, a Cauchy kernel
//!   scaled to σ and truncated; points beyond the reference's edge judged by the laser's
//!   free space where the preparation has it
//!   ([`MapPreparation::with_free_space`](crate::registration::MapPreparation::with_free_space));
//! - the prior: each view's correction `ξ = (ω, t)` about its sensor origin, weighted by
//!   the information of its [`PosePrior`](crate::registration::PosePrior). Directions the geometry does
//!   not observe (the rotation about a bottle's axis) stay at the prior.
//!
//! Levenberg–Marquardt over all free views at once: each step solves the damped normal
//! equations, the correspondences are searched again at the new poses and the step is
//! kept only if `F` fell, else the damping grows until the step is at most half as long
//! as the rejected one in the data's metric (while the damping is small against the
//! system's diagonal, raising it barely shortens the step, and evaluating the same step
//! again only rejects it again: 26 of the 68 evaluations on a user's ring of figurine
//! scans). Each solve after a run's first starts at the damping of the last step taken
//! (a stage starts where the last one ended; from the first solve's damping every later
//! stage spent five or more rejected steps climbing back to it on the paper's Table II
//! case). It stops converged when a step would
//! turn no view by more than `rotation_tolerance` and move no view's centroid by more than
//! `translation_tolerance`, whatever the damping that shortened it, without evaluating
//! that step (it could move the poses by less than the tolerance; the data term is
//! piecewise smooth: a point changing its nearest target point or crossing an edge makes
//! `F` jump, and near the minimum every longer step crosses such a jump; creeping on by
//! ever shorter steps took two thirds of the evaluations on the paper's Table II case),
//! or at `max_iterations` accepted steps (a safety net).
//!
//! The stages: each re-selects the points that take part (those matched at the current
//! poses) and solves again, until no view moves. Points are matched to their nearest
//! target points, or with [`MapParams::along_rays`](crate::registration::MapParams::along_rays) where
//! the camera's viewing rays cross the target's surface: nearest matching captures a view
//! from farther off, matching along the rays removes the bias nearest matching leaves on
//! curved objects. The pipeline therefore matches nearest points first and refines each
//! object's final registration along the rays, started where it ended
//! ([`register_prepared_from`](crate::registration::register_prepared_from)).
//!
//! Acceptance: every view's correction must pass the χ² gate of its prior (6 degrees of
//! freedom); the view farthest beyond it is held at its prior and the rest solved again,
//! until all pass. The report says which views were held, which had no correspondence
//! (left at the prior), and whether the objective fell. Chunked sums in a fixed order make
//! the result identical at any thread count.

pub(crate) mod coarse_to_fine;
pub(crate) mod correspondences;
pub(crate) mod depth_image_free_space;
pub(crate) mod free_space;
pub(crate) mod preparation;
pub(crate) mod terms;
pub(crate) mod view;
pub(crate) mod view_model;

use nalgebra::{DMatrix, DVector, Matrix6, Point3, Translation3, UnitQuaternion, Vector6};
use rayon::prelude::*;

use std::sync::Mutex;

use crate::math::Pose;
use crate::registration::{
    MapReport, MapViewReport, MethodReport, Registration, RegistrationError, RegistrationParams,
    StopReason, ViewModel,
};
use correspondences::PairNearest;
use preparation::{CacheKey, MapPreparation};
use terms::{DataTerm, Kernel, Pair};
use view::MapView;

/// Source points sampled per pair for the overlap test.
const OVERLAP_SAMPLES: usize = 200;

/// Share of those samples with a target point within `d_max` that keeps a pair.
const MIN_OVERLAP: f64 = 0.05;

/// Damping bounds of Levenberg–Marquardt (the start of a run's first solve and of its
/// first along the rays; each other solve starts at the damping of the last step taken).
const LAMBDA_START: f64 = 1e-4;
const LAMBDA_MAX: f64 = 1e8;

/// After a rejected step, the next one is evaluated only once the damping has made it at
/// most this share of the rejected one's length (in the data's metric, `√(δᵀAδ)`): where
/// the damping is still small against the system's diagonal, raising it barely changes
/// the step, and the same step evaluated again is rejected again.
const SHRINK: f64 = 0.5;

/// The problem, fixed for a run.
struct Problem<'a> {
    views: &'a [MapView],
    pairs: Vec<Pair>,
    /// Each pair's correspondences, kept between evaluations.
    nearest: Mutex<Vec<PairNearest>>,
    initial: &'a [Pose],
    models: &'a [ViewModel],
    /// Sensor origins at the initial poses (world): the centres of the corrections.
    origins: Vec<Point3<f64>>,
    kernel: Kernel,
    reference: usize,
}

/// The state: a world-frame correction per view (`pose = correction · initial`).
struct State {
    corrections: Vec<Pose>,
    data: DataTerm,
    objective: f64,
}

/// Runs the MAP registration on checked input with one [`ViewModel`] per view, from the
/// poses `start` (the priors are centred on `initial`), each point's nearest target point
/// searched within `reach` (at most `d_max`).
pub(crate) fn run(
    prepared: &MapPreparation,
    initial: &[Pose],
    start: &[Pose],
    models: &[ViewModel],
    params: &RegistrationParams,
    reach: f64,
) -> Result<Registration, RegistrationError> {
    let (problem, keys, mut solution) = solved(prepared, initial, start, models, params, reach);
    let objective_initial = problem.objective_at_initial(solution.at_initial.take(), initial.len());
    let poses = solution.poses(initial, params.reference);
    let report = problem.report(&solution, objective_initial);
    let converged = solution.stop == StopReason::Converged;
    let rms = report.rms;
    problem.keep_caches(prepared, keys);
    Ok(Registration {
        poses,
        converged,
        rms,
        report: MethodReport::Map(Box::new(report)),
    })
}

/// The poses [`run`] ends at, without its report (a coarse-to-fine stage's): the
/// objective at the initial poses, which only the report reads, is not evaluated.
pub(crate) fn solve(
    prepared: &MapPreparation,
    initial: &[Pose],
    start: &[Pose],
    models: &[ViewModel],
    params: &RegistrationParams,
    reach: f64,
) -> Vec<Pose> {
    let (problem, keys, solution) = solved(prepared, initial, start, models, params, reach);
    problem.keep_caches(prepared, keys);
    solution.poses(initial, params.reference)
}

/// The problem, its caches' keys and its stages solved from `start`: what [`run`] and
/// [`solve`] share.
fn solved<'a>(
    prepared: &'a MapPreparation,
    initial: &'a [Pose],
    start: &[Pose],
    models: &'a [ViewModel],
    params: &RegistrationParams,
    reach: f64,
) -> (Problem<'a>, Vec<CacheKey>, Solution) {
    let (mut problem, keys) = Problem::new(prepared, initial, models, params, reach);
    let corrections = starting_corrections(initial, start, params.reference, initial.len());
    let solution = problem.solve_in_stages(corrections, params);
    (problem, keys, solution)
}

/// Each of the `w` views' correction from its initial pose to its starting pose: exactly
/// the identity for the reference and where the run starts at the initial pose.
fn starting_corrections(initial: &[Pose], start: &[Pose], reference: usize, w: usize) -> Vec<Pose> {
    (0..w)
        .map(|v| {
            if v == reference || start[v] == initial[v] {
                Pose::identity()
            } else {
                start[v] * initial[v].inverse()
            }
        })
        .collect()
}

/// The outcome of the stages: the last state and why its solve stopped, the views held
/// at their priors, the work done and the objective at the initial poses.
struct Solution {
    /// The final state.
    state: State,
    /// Why the last stage's solve stopped.
    stop: StopReason,
    /// Per view, whether the χ² gate held it at its prior.
    held: Vec<bool>,
    /// Steps accepted over all stages.
    iterations: usize,
    /// Objective evaluations over all stages.
    evaluations: usize,
    /// The correspondences at the initial poses, when the run started there.
    at_initial: Option<Vec<PairNearest>>,
}

impl Solution {
    /// Each view's pose: its correction applied to its initial pose, exactly the initial
    /// pose for the `reference`.
    fn poses(&self, initial: &[Pose], reference: usize) -> Vec<Pose> {
        (0..initial.len())
            .map(|v| {
                if v == reference {
                    initial[v]
                } else {
                    self.state.corrections[v] * initial[v]
                }
            })
            .collect()
    }
}

/// The report's verdict in words: the registration is kept when it converged and the
/// objective fell; the views the χ² gate held at their priors are named.
fn verdict(stop: StopReason, fell: bool, held_views: &[usize]) -> String {
    match (stop == StopReason::Converged, fell) {
        (false, _) => format!("not converged ({stop:?}): the reported poses are kept"),
        (true, false) => "the objective did not fall: the reported poses are kept".into(),
        (true, true) if held_views.is_empty() => {
            "converged, the objective fell, every view within the χ² gate of its prior".into()
        }
        (true, true) => format!(
            "converged, the objective fell; views {held_views:?} beyond the χ² gate kept their \
             reported poses"
        ),
    }
}

impl<'a> Problem<'a> {
    /// The problem of a run: the sensor origins at the initial poses, the kernel (nearest
    /// points searched within `reach`), the pairs of views and their nearest-point caches
    /// (the ones the last run on these views left, if any), with the caches' keys.
    fn new(
        prepared: &'a MapPreparation,
        initial: &'a [Pose],
        models: &'a [ViewModel],
        params: &RegistrationParams,
        reach: f64,
    ) -> (Self, Vec<CacheKey>) {
        let map = &params.map;
        let views: &[MapView] = &prepared.views;
        let origins: Vec<Point3<f64>> = views
            .iter()
            .zip(initial)
            .map(|(v, p)| p * v.centre)
            .collect();
        let kernel = Kernel {
            select: map.match_sigmas,
            scale: map.kernel_scale,
            cap: map.outlier_sigmas,
            floor: map.floor_sigma,
            reach,
            d_max: params.max_correspondence_distance,
            along_rays: map.along_rays,
        };
        let reference = params.reference;
        let pairs = select_pairs(
            views,
            initial,
            reference,
            &kernel,
            map.pair_points,
            map.view_to_view,
        );
        let keys: Vec<CacheKey> = pairs
            .iter()
            .map(|p| (p.source, p.target, p.stride, kernel.reach.to_bits()))
            .collect();
        let nearest = pairs
            .iter()
            .zip(&keys)
            .map(|(pair, &key)| {
                prepared
                    .take_cache(key)
                    .unwrap_or_else(|| PairNearest::new(views, pair, kernel.reach))
            })
            .collect();
        let problem = Problem {
            nearest: Mutex::new(nearest),
            views,
            pairs,
            initial,
            models,
            origins,
            kernel,
            reference,
        };
        (problem, keys)
    }
}

impl Problem<'_> {
    /// The stages from `corrections`: each re-selects the points matched at the current
    /// poses and solves (with the χ² gate) until no view moves, `max_stages` or a solve
    /// that did not converge. The objective at the initial poses is left to the caller
    /// ([`objective_at_initial`](Self::objective_at_initial)).
    fn solve_in_stages(
        &mut self,
        mut corrections: Vec<Pose>,
        params: &RegistrationParams,
    ) -> Solution {
        let map = &params.map;
        let w = corrections.len();
        let mut held = vec![false; w];
        let (mut iterations, mut evaluations) = (0, 0);
        let mut stages = 0;
        let mut lambda = LAMBDA_START;
        // The correspondences at the initial poses, for the objective there at the end (a
        // copy of the caches after the first evaluation, when it is at the initial poses:
        // that evaluation then costs next to nothing again).
        let mut at_initial: Option<Vec<PairNearest>> = None;
        let mut first = corrections.iter().all(|c| *c == Pose::identity());
        let (state, stop) = loop {
            // Which points take part: those matched at the current poses.
            self.unmask();
            let matched = self.data(&corrections, false).matched;
            if std::mem::take(&mut first) {
                at_initial = Some(self.caches().clone());
            }
            self.mask(matched);
            let (state, stop, its, evals) = self.solve_gated(
                self.state(corrections.clone()),
                &mut held,
                &mut lambda,
                params,
            );
            iterations += its;
            evaluations += evals + 2;
            stages += 1;
            let moved = self.moved(&corrections, &state.corrections, params);
            corrections = state.corrections.clone();
            if !moved || stages == map.max_stages || stop != StopReason::Converged {
                break (state, stop);
            }
        };
        Solution {
            state,
            stop,
            held,
            iterations,
            evaluations,
            at_initial,
        }
    }

    /// Keeps the pairs' nearest-point caches in `prepared` for its next run.
    fn keep_caches(self, prepared: &MapPreparation, keys: Vec<CacheKey>) {
        let caches = self
            .nearest
            .into_inner()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        prepared.keep_caches(keys.into_iter().zip(caches));
    }

    /// Whether a stage moved any view from `before` to `after` by more than ten times the
    /// convergence tolerances (about its sensor origin).
    fn moved(&self, before: &[Pose], after: &[Pose], params: &RegistrationParams) -> bool {
        let map = &params.map;
        (0..before.len()).any(|v| {
            let d = after[v] * before[v].inverse();
            let o = before[v] * self.origins[v];
            d.rotation.angle() > map.rotation_tolerance * 10.0
                || (d * o - o).norm() > map.translation_tolerance * 10.0
        })
    }

    /// The objective at the initial poses of the `w` views: with the correspondences kept
    /// from there (`at_initial`) if any, else searched again.
    fn objective_at_initial(&self, at_initial: Option<Vec<PairNearest>>, w: usize) -> f64 {
        let identity = vec![Pose::identity(); w];
        match at_initial {
            Some(mut caches) => {
                self.data_using(&identity, &mut caches, false).cost + self.prior_cost(&identity)
            }
            None => self.data(&identity, false).cost + self.prior_cost(&identity),
        }
    }

    /// The report of `solution`, whose objective at the initial poses is
    /// `objective_initial` (its evaluation counted among the work done): the work done,
    /// the objective before and after, the verdict and per view its correction, χ² and
    /// data information.
    fn report(&self, solution: &Solution, objective_initial: f64) -> MapReport {
        let Solution {
            state,
            stop,
            held,
            iterations,
            evaluations,
            ..
        } = solution;
        let rms = (state.data.inlier_count > 0)
            .then(|| (state.data.sum_sq / state.data.inlier_count as f64).sqrt());
        let views: Vec<MapViewReport> = (0..held.len())
            .map(|v| {
                let xi = self.correction(&state.corrections, v);
                let h = state
                    .data
                    .hessian()
                    .fixed_view::<6, 6>(6 * v, 6 * v)
                    .into_owned();
                MapViewReport {
                    inliers: state.data.inliers[v],
                    correction: xi.into(),
                    chi2: self.chi2(&state.corrections, v),
                    held_at_prior: held[v],
                    unconstrained: v != self.reference && state.data.inliers[v] == 0,
                    data_information: h,
                }
            })
            .collect();
        let converged = *stop == StopReason::Converged;
        let fell = state.objective <= objective_initial;
        let held_views: Vec<usize> = (0..held.len()).filter(|&v| held[v]).collect();
        MapReport {
            iterations: *iterations,
            evaluations: evaluations + 1,
            stop: *stop,
            objective_initial,
            objective_final: state.objective,
            pairs: self.pairs.len(),
            inliers: state.data.inlier_count,
            rms,
            accepted: converged && fell,
            verdict: verdict(*stop, fell, &held_views),
            views,
        }
    }

    /// Every used point takes part.
    fn unmask(&mut self) {
        for pair in &mut self.pairs {
            pair.mask = None;
        }
    }

    /// Only the points flagged in `matched` (per pair) take part.
    fn mask(&mut self, matched: Vec<Vec<bool>>) {
        for (pair, m) in self.pairs.iter_mut().zip(matched) {
            // A contradiction may arise anywhere as the views move.
            if !pair.contradictions_only {
                pair.mask = Some(m);
            }
        }
    }

    /// [`solve`](Self::solve), then the χ² gate: the worst view beyond it is held at its
    /// prior (its flag set in `held`) and the rest solved again, until every view passes.
    fn solve_gated(
        &self,
        mut state: State,
        held: &mut [bool],
        lambda: &mut f64,
        params: &RegistrationParams,
    ) -> (State, StopReason, usize, usize) {
        let (mut iterations, mut evaluations) = (0, 0);
        loop {
            let (next, stop, its, evals) = self.solve(state, held, lambda, params);
            state = next;
            iterations += its;
            evaluations += evals;
            let worst = (0..held.len())
                .filter(|&v| v != self.reference && !held[v])
                .filter_map(|v| self.chi2(&state.corrections, v).map(|c| (v, c)))
                .filter(|&(_, c)| c > params.map.gate_chi2)
                .max_by(|a, b| a.1.total_cmp(&b.1));
            match worst {
                Some((v, _)) => {
                    held[v] = true;
                    let mut corrections = state.corrections;
                    corrections[v] = Pose::identity();
                    state = self.state(corrections);
                    evaluations += 1;
                }
                None => return (state, stop, iterations, evaluations),
            }
        }
    }

    /// The state at `corrections`, its data term evaluated.
    fn state(&self, corrections: Vec<Pose>) -> State {
        let data = self.data(&corrections, true);
        let objective = data.cost + self.prior_cost(&corrections);
        State {
            corrections,
            data,
            objective,
        }
    }

    /// The data term at `corrections` ([`data_using`](Self::data_using)) with the
    /// problem's own caches.
    fn data(&self, corrections: &[Pose], normal_equations: bool) -> DataTerm {
        self.data_using(corrections, &mut self.caches(), normal_equations)
    }

    /// The pairs' nearest-point caches. Evaluations never overlap; a poisoned lock only
    /// means an earlier panic.
    fn caches(&self) -> std::sync::MutexGuard<'_, Vec<PairNearest>> {
        self.nearest
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
    }

    /// The data term at `corrections`, with the nearest-point caches `nearest`, its normal
    /// equations summed only with `normal_equations`.
    fn data_using(
        &self,
        corrections: &[Pose],
        nearest: &mut [PairNearest],
        normal_equations: bool,
    ) -> DataTerm {
        let poses: Vec<Pose> = corrections
            .iter()
            .zip(self.initial)
            .map(|(c, p)| c * p)
            .collect();
        let centres: Vec<Point3<f64>> = corrections
            .iter()
            .zip(&self.origins)
            .map(|(c, o)| c * o)
            .collect();
        terms::evaluate(
            self.views,
            &self.pairs,
            nearest,
            &poses,
            &centres,
            &self.kernel,
            normal_equations,
        )
    }

    /// `ξ = (ω, t)` of view `v`'s correction about its sensor origin.
    fn correction(&self, corrections: &[Pose], v: usize) -> Vector6<f64> {
        let c = &corrections[v];
        let o = self.origins[v];
        let w = c.rotation.scaled_axis();
        let t = c * o - o;
        Vector6::new(w.x, w.y, w.z, t.x, t.y, t.z)
    }

    /// The prior's χ² of view `v`'s correction (`None` without a prior or for the
    /// reference).
    fn chi2(&self, corrections: &[Pose], v: usize) -> Option<f64> {
        if v == self.reference {
            return None;
        }
        let prior = self.models[v].prior?;
        Some(prior.chi2(&self.correction(corrections, v)))
    }

    fn prior_cost(&self, corrections: &[Pose]) -> f64 {
        (0..corrections.len())
            .filter_map(|v| self.chi2(corrections, v))
            .map(|c| 0.5 * c)
            .sum()
    }

    /// Levenberg–Marquardt over the views that are neither the reference nor `held`, from
    /// `state`, with damping `damping` at first; `damping` is left at that of the last step
    /// taken. Returns the final state, why it stopped, accepted steps and evaluations.
    fn solve(
        &self,
        mut state: State,
        held: &[bool],
        damping: &mut f64,
        params: &RegistrationParams,
    ) -> (State, StopReason, usize, usize) {
        let free: Vec<usize> = (0..held.len())
            .filter(|&v| v != self.reference && !held[v])
            .collect();
        if free.is_empty() {
            return (state, StopReason::Converged, 0, 0);
        }
        let n = 6 * free.len();
        let mut lambda = *damping;
        let (mut iterations, mut evaluations) = (0, 0);
        loop {
            if iterations == params.map.max_iterations {
                return (state, StopReason::MaxIterations, iterations, evaluations);
            }
            let (a, b) = self.normal_equations(&state, &free, n);
            // The length of the last rejected step, in the data's metric.
            let mut rejected: Option<f64> = None;
            let step = loop {
                let mut damped = a.clone();
                for k in 0..n {
                    damped[(k, k)] += lambda * a[(k, k)].max(1e-12);
                }
                let Some(chol) = damped.cholesky() else {
                    lambda *= 10.0;
                    if lambda > LAMBDA_MAX {
                        return (state, StopReason::Degenerate, iterations, evaluations);
                    }
                    continue;
                };
                let delta = -chol.solve(&b);
                let corrections = self.apply(&state.corrections, &free, &delta);
                // Within the tolerance at any damping: the damping only grew because no
                // longer step lowered F, so descending from here reaches nothing farther
                // than the tolerance (the trust region has shrunk below it). Converged
                // here, without evaluating the step.
                if self.is_small(&state.corrections, &free, &delta, params) {
                    break None;
                }
                let length = delta.dot(&(&a * &delta)).max(0.0).sqrt();
                if rejected.is_some_and(|r| length > SHRINK * r) {
                    if lambda > LAMBDA_MAX {
                        break None;
                    }
                    lambda *= 5.0;
                    continue;
                }
                let trial = self.state(corrections);
                evaluations += 1;
                if trial.objective < state.objective {
                    lambda = (lambda / 3.0).max(1e-9);
                    *damping = lambda;
                    break Some(trial);
                }
                if lambda > LAMBDA_MAX {
                    break None;
                }
                rejected = Some(length);
                lambda *= 5.0;
            };
            match step {
                Some(trial) => {
                    state = trial;
                    iterations += 1;
                }
                // No step lowers F: the poses are a minimum to within the tolerance.
                None => return (state, StopReason::Converged, iterations, evaluations),
            }
        }
    }

    /// The undamped system `A δ = −b` of the free views (data plus prior).
    fn normal_equations(
        &self,
        state: &State,
        free: &[usize],
        n: usize,
    ) -> (DMatrix<f64>, DVector<f64>) {
        let mut a = DMatrix::zeros(n, n);
        let mut b = DVector::zeros(n);
        for (i, &v) in free.iter().enumerate() {
            for (j, &u) in free.iter().enumerate() {
                a.fixed_view_mut::<6, 6>(6 * i, 6 * j)
                    .copy_from(&state.data.hessian().fixed_view::<6, 6>(6 * v, 6 * u));
            }
            let mut bi = b.fixed_rows_mut::<6>(6 * i);
            bi.copy_from(&state.data.gradient().fixed_rows::<6>(6 * v));
            if let Some(prior) = self.models[v].prior {
                let info: Matrix6<f64> = prior.information();
                let mut block = a.fixed_view_mut::<6, 6>(6 * i, 6 * i);
                block += info;
                bi += info * self.correction(&state.corrections, v);
            }
        }
        (a, b)
    }

    /// The corrections after the perturbation `delta` of the free views, each about its
    /// current centre: `x ↦ R(δω)·(x − c) + c + δt`.
    fn apply(&self, corrections: &[Pose], free: &[usize], delta: &DVector<f64>) -> Vec<Pose> {
        let mut out = corrections.to_vec();
        for (i, &v) in free.iter().enumerate() {
            let d = delta.fixed_rows::<6>(6 * i);
            let c = corrections[v] * self.origins[v];
            let rotation = UnitQuaternion::from_scaled_axis(d.fixed_rows::<3>(0).into_owned());
            let step = Translation3::from(c.coords + d.fixed_rows::<3>(3).into_owned())
                * rotation
                * Translation3::from(-c.coords);
            out[v] = step * corrections[v];
        }
        out
    }

    /// Whether a perturbation turns no free view by more than the rotation tolerance and
    /// moves no free view's centroid by more than the translation tolerance.
    fn is_small(
        &self,
        corrections: &[Pose],
        free: &[usize],
        delta: &DVector<f64>,
        params: &RegistrationParams,
    ) -> bool {
        free.iter().enumerate().all(|(i, &v)| {
            let d = delta.fixed_rows::<6>(6 * i);
            let w = d.fixed_rows::<3>(0).into_owned();
            let c = corrections[v] * self.origins[v];
            let centroid = corrections[v] * (self.initial[v] * self.views[v].tree.centroid());
            let moved = w.cross(&(centroid - c)) + d.fixed_rows::<3>(3);
            w.norm() <= params.map.rotation_tolerance
                && moved.norm() <= params.map.translation_tolerance
        })
    }
}

/// The directed pairs of the data term: every non-reference view into the reference view
/// (weight 1, all points); the reference into every view that knows its free space, for
/// contradictions only (weight 1, all points); and, with `view_to_view`, every
/// non-reference view into every other one (weight ½ per direction, at most `pair_points`
/// points); each kept when at least 5 % of a sample of the source's points has a
/// target point within `d_max` at the initial poses.
fn select_pairs(
    views: &[MapView],
    initial: &[Pose],
    reference: usize,
    kernel: &Kernel,
    pair_points: usize,
    view_to_view: bool,
) -> Vec<Pair> {
    let w = views.len();
    let candidates: Vec<(usize, usize)> = (0..w)
        .flat_map(|v| (0..w).filter(move |&t| t != v).map(move |t| (v, t)))
        .filter(|&(v, t)| v != reference || views[t].free_space.is_some())
        .collect();
    let overlapping: Vec<bool> = candidates
        .par_iter()
        .map(|&(v, t)| {
            let to_target = initial[t].inverse() * initial[v];
            let points = views[v].tree.points();
            let step = points.len().div_ceil(OVERLAP_SAMPLES).max(1);
            let all = points.len().div_ceil(step);
            // The hits only grow: the search stops at the share that keeps the pair.
            let mut hits = 0usize;
            points.iter().step_by(step).any(|p| {
                let hit = views[t]
                    .tree
                    .nearest_within(&(to_target * p), kernel.d_max)
                    .is_some();
                hits += usize::from(hit);
                hits as f64 / all as f64 >= MIN_OVERLAP
            })
        })
        .collect();
    candidates
        .into_iter()
        .zip(overlapping)
        .filter(|&((v, t), overlapping)| {
            overlapping && (view_to_view || t == reference || v == reference)
        })
        .map(|((v, t), _)| {
            if t == reference || v == reference {
                Pair {
                    source: v,
                    target: t,
                    weight: 1.0,
                    stride: 1,
                    mask: None,
                    contradictions_only: v == reference,
                }
            } else {
                Pair {
                    source: v,
                    target: t,
                    weight: 0.5,
                    stride: views[v].len().div_ceil(pair_points.max(1)).max(1),
                    mask: None,
                    contradictions_only: false,
                }
            }
        })
        .collect()
}
