//! p-ICP-GPA (paper Figure 4; Toldo et al.'s GPA-ICP made parallel): all views are
//! registered at once against the centroids of the independent sets.
//!
//! Each outer iteration, at the current pose estimates:
//! 1. mutual nearest neighbours between every pair of views within `d_max` (parallel over
//!    points; one k-d tree per view, built once in the view's own frame);
//! 2. independent sets from that graph ([`SetRule`](super::SetRule));
//! 3. the unweighted centroid of each set (parallel over sets) and the mean squared
//!    distance of the members to their centroid (the residual);
//! 4. stop if the residual's relative change since the previous iteration (or the one
//!    before, which catches a two-state cycle of correspondences) is at most `tolerance`,
//!    or the iteration cap is reached;
//! 5. generalised Procrustes on these fixed sets (line 22, as in Toldo et al.): for every
//!    view (in parallel), the rigid transform moving its set members, in the view's own
//!    frame, onto the centroids — all views against the same centroids — then new
//!    centroids, repeated until the residual settles (same `tolerance`) or
//!    `max_inner_iterations` fits were made (1 gives a single fit per outer iteration);
//! 6. stop if that update turns no view relative to the reference view by more than
//!    `rotation_tolerance` and moves no view's point centroid by more than
//!    `translation_tolerance` (the poses of step 1 are returned), else take it.
//!
//! A view without three non-collinear set members keeps its pose for that fit. The
//! residual and the report always describe the returned poses. Afterwards the gauge is
//! fixed: every pose is expressed relative to the reference view, which keeps its initial
//! pose. Every reduction runs in a fixed order, so the result is identical at any thread
//! count.

use nalgebra::{Point3, Vector3};
use rayon::prelude::*;

use super::independent_sets::{IndependentSets, find_independent_sets};
use super::mutual_neighbours::{MutualSearch, ViewLayout};
use super::procrustes::CrossCovariance;
use super::view_tree::ViewTree;
use super::{
    GpaReport, MethodReport, Registration, RegistrationError, RegistrationParams, SetRule,
    StopReason, settled,
};
use crate::cloud::PointCloud;
use crate::math::Pose;

/// Sets (centroids) or set members (fits) per parallel work item.
const CHUNK: usize = 512;

/// The independent sets found at one set of poses, indexed per view.
struct Correspondences {
    sets: IndependentSets,
    /// (view, local point index) of every entry of `sets.members()`.
    locals: Vec<(u32, u32)>,
    /// Per view: (local point index, set index) of its set members, in set order.
    members_of: Vec<Vec<(u32, u32)>>,
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
        let (centroids, mse) = centroids(&trees, &corr, &poses);
        history.push(mse);
        if settled(&history, params.tolerance) {
            break (corr, Some(mse), StopReason::Converged);
        }
        if iterations == params.max_iterations {
            break (corr, Some(mse), StopReason::MaxIterations);
        }
        let mut updated = poses.clone();
        let Some(inner) = consensus(&trees, &corr, centroids, mse, &mut updated, params) else {
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
        correspondences_per_view: corr.members_of.iter().map(Vec::len).collect(),
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
/// fits were made. Updates `poses`; returns the number of fits, or `None` if no view
/// could be fitted at all.
fn consensus(
    trees: &[ViewTree],
    corr: &Correspondences,
    mut centroids: Vec<Point3<f64>>,
    mut mse: f64,
    poses: &mut [Pose],
    params: &RegistrationParams,
) -> Option<usize> {
    let mut fitted = 0;
    while fitted < params.max_inner_iterations {
        let fits = fit_views(trees, corr, &centroids);
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
        (centroids, mse) = self::centroids(trees, corr, poses);
        if settled(&[previous, mse], params.tolerance) {
            break;
        }
    }
    (fitted > 0).then_some(fitted)
}

/// For every view, the rigid transform moving its set members (own frame) onto their
/// centroids, or `None` if they do not determine one. Sums run in parallel over fixed
/// chunks of each view's members and merge in chunk order.
fn fit_views(
    trees: &[ViewTree],
    corr: &Correspondences,
    centroids: &[Point3<f64>],
) -> Vec<Option<Pose>> {
    let w = trees.len();
    let work: Vec<(usize, usize)> = (0..w)
        .flat_map(|v| {
            let n = corr.members_of[v].len();
            (0..n.div_ceil(CHUNK)).map(move |c| (v, c * CHUNK))
        })
        .collect();
    let partial: Vec<(usize, CrossCovariance)> = work
        .par_iter()
        .map(|&(v, start)| {
            let points = trees[v].points();
            let members = &corr.members_of[v];
            let (i0, s0) = members[0];
            let mut acc = CrossCovariance::new(points[i0 as usize], centroids[s0 as usize]);
            for &(i, s) in &members[start..(start + CHUNK).min(members.len())] {
                acc.add(&points[i as usize], &centroids[s as usize]);
            }
            (v, acc)
        })
        .collect();
    let mut per_view: Vec<Option<CrossCovariance>> = vec![None; w];
    for (v, acc) in partial {
        match &mut per_view[v] {
            Some(sum) => sum.merge(&acc),
            None => per_view[v] = Some(acc),
        }
    }
    per_view
        .into_iter()
        .map(|acc| acc.and_then(|a| a.solve().ok()))
        .collect()
}

/// Mutual nearest neighbours and independent sets at `poses`.
fn correspond(
    trees: &[ViewTree],
    poses: &[Pose],
    layout: &ViewLayout,
    search: &mut MutualSearch,
    rule: SetRule,
) -> Correspondences {
    let edges = search.edges(trees, poses, layout);
    let sets = find_independent_sets(layout, &edges, rule);
    let locals: Vec<(u32, u32)> = sets
        .members()
        .par_iter()
        .map(|&m| {
            let (v, i) = layout.local(m as usize);
            (v as u32, i as u32)
        })
        .collect();
    let mut members_of = vec![Vec::new(); layout.views()];
    for s in 0..sets.len() {
        for &(v, i) in &locals[sets.range(s)] {
            members_of[v as usize].push((i, s as u32));
        }
    }
    Correspondences {
        sets,
        locals,
        members_of,
    }
}

/// Centroid of every set at `poses` (parallel over sets) and the mean squared distance of
/// the members to their centroid (0 without sets).
fn centroids(
    trees: &[ViewTree],
    corr: &Correspondences,
    poses: &[Pose],
) -> (Vec<Point3<f64>>, f64) {
    let sets = &corr.sets;
    let position =
        |&(v, i): &(u32, u32)| poses[v as usize] * trees[v as usize].points()[i as usize];
    let chunks: Vec<Vec<(Point3<f64>, f64)>> = (0..sets.len().div_ceil(CHUNK))
        .into_par_iter()
        .map(|c| {
            (c * CHUNK..((c + 1) * CHUNK).min(sets.len()))
                .map(|s| {
                    let members = &corr.locals[sets.range(s)];
                    let sum = members
                        .iter()
                        .fold(Vector3::zeros(), |acc, m| acc + position(m).coords);
                    let centroid = Point3::from(sum / members.len() as f64);
                    let sq: f64 = members
                        .iter()
                        .map(|m| (position(m) - centroid).norm_squared())
                        .sum();
                    (centroid, sq)
                })
                .collect()
        })
        .collect();
    let mut centroids = Vec::with_capacity(sets.len());
    let mut sum_sq = 0.0;
    for (c, sq) in chunks.into_iter().flatten() {
        centroids.push(c);
        sum_sq += sq;
    }
    let mse = if sets.is_empty() {
        0.0
    } else {
        sum_sq / sets.points_in_sets() as f64
    };
    (centroids, mse)
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
