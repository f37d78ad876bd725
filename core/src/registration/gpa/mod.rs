//! p-ICP-GPA (paper Figure 4; Toldo et al.'s GPA-ICP made parallel): all views are
//! registered at once against the centroids of the independent sets.
//!
//! Each outer iteration, at the current pose estimates:
//! 1. mutual nearest neighbours between every pair of views within `d_max` (parallel over
//!    points; one k-d tree per view, built once in the view's own frame);
//! 2. independent sets from that graph ([`SetRule`](crate::registration::SetRule));
//! 3. the unweighted centroid of each set (parallel over sets) and the mean squared
//!    distance of the members to their centroid (the residual);
//! 4. stop if the residual's relative change since the previous iteration (or the one
//!    before, which catches a two-state cycle of correspondences) is at most `tolerance`,
//!    or the iteration cap is reached;
//! 5. generalised Procrustes on these fixed sets (line 22, as in Toldo et al.): for every
//!    view (in parallel), the rigid transform moving its set members, in the view's own
//!    frame, onto the centroids — all views against the same centroids — then new
//!    centroids, repeated until the residual settles (same `tolerance`) or
//!    `max_inner_iterations` fits were made (1 gives a single fit per outer iteration).
//!    The sets are summed once by pair of views ([`SetMoments`]), so each round costs
//!    O(views²) instead of a pass over every member;
//! 6. stop if that update turns no view relative to the reference view by more than
//!    `rotation_tolerance` and moves no view's point centroid by more than
//!    `translation_tolerance` (the poses of step 1 are returned), else take it.
//!
//! A view without three non-collinear set members keeps its pose for that fit. The
//! residual and the report always describe the returned poses. Afterwards the gauge is
//! fixed: every pose is expressed relative to the reference view, which keeps its initial
//! pose. Every reduction runs in a fixed order, so the result is identical at any thread
//! count.
//!
//! **Independent sets** ([`SetRule::Cliques`](crate::registration::SetRule::Cliques),
//! default) are the connected components of the mutual-nearest-neighbour graph that are
//! complete graphs — every member the mutual nearest neighbour of every other, as the paper
//! defines them. A point has at most one mutual nearest neighbour per view, so such a set
//! holds at most one point per view, and at least two; incomplete components are dropped
//! whole. [`SetRule::Components`](crate::registration::SetRule::Components) keeps every
//! component with at most one point per view.
//!
//! **Accuracy**: with views that sample the surface independently, point-to-point
//! correspondences are off by a fraction of the point spacing, and that sets the floor
//! (about 0.5–1 mm on an 8 cm object sampled every 2–2.5 mm, see the tests). Convergence
//! from centimetre errors takes tens to a few hundred iterations, since point-to-point
//! steps slide slowly along smooth surfaces. Views that do not overlap give a reported
//! non-convergence, never made-up poses.

pub(crate) mod independent_sets;
pub(crate) mod mutual_neighbours;
pub(crate) mod set_moments;

use nalgebra::{Point3, Vector3};
use rayon::prelude::*;

use crate::cloud::PointCloud;
use crate::math::Pose;
use crate::registration::view_tree::ViewTree;
use crate::registration::{
    GpaReport, MethodReport, Registration, RegistrationError, RegistrationParams, SetRule,
    StopReason, settled,
};
use independent_sets::{IndependentSets, find_independent_sets};
use mutual_neighbours::{MutualSearch, ViewLayout};
use set_moments::SetMoments;

/// Sets per parallel work item of the residual.
const CHUNK: usize = 512;

/// The independent sets found at one set of poses, indexed per view.
struct Correspondences {
    sets: IndependentSets,
    /// (view, local point index) of every set member, set after set.
    locals: Vec<(u32, u32)>,
    /// Set members per view.
    per_view: Vec<usize>,
}

/// Runs p-ICP-GPA on checked input.
pub(crate) fn run(
    views: &[PointCloud],
    initial: &[Pose],
    params: &RegistrationParams,
) -> Result<Registration, RegistrationError> {
    let trees: Vec<ViewTree> = views
        .par_iter()
        .enumerate()
        .map(|(v, cloud)| ViewTree::build_with_graph(v, &cloud.points))
        .collect::<Result<_, _>>()?;
    let layout = ViewLayout::new(views.iter().map(PointCloud::len));
    let reference = params.reference;
    let anchor = initial[reference];
    let anchor_inv = anchor.inverse();
    // Work in the reference view's initial frame.
    let mut poses: Vec<Pose> = initial.iter().map(|p| anchor_inv * p).collect();
    let view_centroids: Vec<Point3<f64>> = trees.iter().map(ViewTree::centroid).collect();
    let mut search = MutualSearch::new(&trees, params.max_correspondence_distance);
    let mut history = Vec::new();
    let mut iterations = 0;
    let mut inner_iterations = 0;
    let (corr, mse, stop) = loop {
        let corr = correspond(&trees, &poses, &layout, &mut search, params.set_rule);
        if corr.sets.is_empty() {
            break (corr, None, StopReason::NoCorrespondences);
        }
        let mse = residual(&trees, &corr, &poses);
        history.push(mse);
        if settled(&history, params.tolerance) {
            break (corr, Some(mse), StopReason::Converged);
        }
        if iterations == params.max_iterations {
            break (corr, Some(mse), StopReason::MaxIterations);
        }
        let mut updated = poses.clone();
        let Some(inner) = consensus(&trees, &corr, mse, &mut updated, params) else {
            break (corr, Some(mse), StopReason::Degenerate);
        };
        inner_iterations += inner;
        // The update is negligible: the poses measured above are the result.
        let (rotation, translation) = largest_step(&poses, &updated, reference, &view_centroids);
        if rotation <= params.rotation_tolerance && translation <= params.translation_tolerance {
            break (corr, Some(mse), StopReason::Converged);
        }
        poses = updated;
        iterations += 1;
    };

    let unconnected_views = unconnected_views(&corr.sets, &layout, reference);
    let rms = mse.map(f64::sqrt);
    let report = GpaReport {
        iterations,
        inner_iterations,
        stop,
        rms,
        mse_history: history,
        independent_sets: corr.sets.len(),
        linked_points: corr.sets.linked_points(),
        points_in_sets: corr.sets.points_in_sets(),
        correspondences_per_view: corr.per_view.clone(),
        unconnected_views,
    };
    // Gauge: the reference view keeps its initial pose (exactly), the others follow it.
    // Without any update the initial poses come back untouched.
    let poses = if iterations == 0 {
        initial.to_vec()
    } else {
        let gauge = anchor * poses[reference].inverse();
        poses
            .iter()
            .enumerate()
            .map(|(v, p)| if v == reference { anchor } else { gauge * p })
            .collect()
    };
    Ok(Registration {
        poses,
        converged: stop == StopReason::Converged && report.unconnected_views.is_empty(),
        rms,
        report: MethodReport::Gpa(report),
    })
}

/// Generalised Procrustes on fixed correspondences (Figure 4, line 22, after Toldo et
/// al.): alternately fit every view onto the current centroids and recompute the
/// centroids, until the mean squared distance to them settles or `max_inner_iterations`
/// fits were made, both from the sets' [`SetMoments`]. Updates `poses`; returns the
/// number of fits, or `None` if no view could be fitted at all.
fn consensus(
    trees: &[ViewTree],
    corr: &Correspondences,
    mut mse: f64,
    poses: &mut [Pose],
    params: &RegistrationParams,
) -> Option<usize> {
    let moments = SetMoments::new(trees, &corr.sets, &corr.locals);
    let mut fitted = 0;
    while fitted < params.max_inner_iterations {
        let fits = moments.fits(poses);
        if fits.iter().all(Option::is_none) {
            break;
        }
        for (pose, fit) in poses.iter_mut().zip(fits) {
            if let Some(fit) = fit {
                *pose = fit;
            }
        }
        fitted += 1;
        let previous = mse;
        mse = moments.mean_squared_residual(poses);
        if settled(&[previous, mse], params.tolerance) {
            break;
        }
    }
    (fitted > 0).then_some(fitted)
}

/// Mutual nearest neighbours and independent sets at `poses`.
fn correspond(
    trees: &[ViewTree],
    poses: &[Pose],
    layout: &ViewLayout,
    search: &mut MutualSearch,
    rule: SetRule,
) -> Correspondences {
    let partners = search.partners(trees, poses, layout);
    let sets = find_independent_sets(layout, &partners, rule);
    let locals = sets.locals(layout);
    let mut per_view = vec![0; layout.views()];
    for &(v, _) in &locals {
        per_view[v as usize] += 1;
    }
    Correspondences {
        sets,
        locals,
        per_view,
    }
}

/// The mean squared distance of the sets' members to their centroids at `poses` (0
/// without sets), member by member (parallel over sets, summed in chunk order).
fn residual(trees: &[ViewTree], corr: &Correspondences, poses: &[Pose]) -> f64 {
    let sets = &corr.sets;
    if sets.is_empty() {
        return 0.0;
    }
    let position =
        |&(v, i): &(u32, u32)| poses[v as usize] * trees[v as usize].points()[i as usize];
    let chunks: Vec<f64> = (0..sets.len().div_ceil(CHUNK))
        .into_par_iter()
        .map(|c| {
            (c * CHUNK..((c + 1) * CHUNK).min(sets.len()))
                .map(|s| {
                    let members = &corr.locals[sets.range(s)];
                    let sum = members
                        .iter()
                        .fold(Vector3::zeros(), |acc, m| acc + position(m).coords);
                    let centroid = Point3::from(sum / members.len() as f64);
                    members
                        .iter()
                        .map(|m| (position(m) - centroid).norm_squared())
                        .sum::<f64>()
                })
                .sum()
        })
        .collect();
    chunks.iter().sum::<f64>() / sets.points_in_sets() as f64
}

/// Largest rotation (radians) and displacement of a view's point centroid (metres) of
/// any view relative to the reference view between `before` and `after`.
fn largest_step(
    before: &[Pose],
    after: &[Pose],
    reference: usize,
    centroids: &[Point3<f64>],
) -> (f64, f64) {
    let (ref_before, ref_after) = (before[reference].inverse(), after[reference].inverse());
    let mut worst = (0.0f64, 0.0f64);
    for (v, c) in centroids.iter().enumerate() {
        let d = (ref_before * before[v]).inverse() * (ref_after * after[v]);
        worst = (
            worst.0.max(d.rotation.angle()),
            worst.1.max((d * c - c).norm()),
        );
    }
    worst
}

/// Views not linked to the reference view through shared independent sets.
fn unconnected_views(sets: &IndependentSets, layout: &ViewLayout, reference: usize) -> Vec<usize> {
    let w = layout.views();
    let mut group: Vec<usize> = (0..w).collect();
    fn root(group: &mut [usize], mut v: usize) -> usize {
        while group[v] != v {
            group[v] = group[group[v]];
            v = group[v];
        }
        v
    }
    for s in 0..sets.len() {
        let members = sets.set(s);
        let (first, _) = layout.local(members[0] as usize);
        for &m in &members[1..] {
            let (v, _) = layout.local(m as usize);
            let (a, b) = (root(&mut group, first), root(&mut group, v));
            group[a.max(b)] = a.min(b);
        }
    }
    let r = root(&mut group, reference);
    (0..w).filter(|&v| root(&mut group, v) != r).collect()
}
