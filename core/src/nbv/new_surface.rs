//! [`new_surface_share`]: how much surface a view added to an object's model, measured
//! without ground truth the way the report measures coverage — the view's points farther
//! than the coverage tolerance (1 cm) from every point the object had before, as a share of
//! the surface it had. The new-surface stop rule ([`StopRule::new_surface`]) reads it.
//!
//! Counting first-hit voxels instead (2 cm cells of the grid) counts what the camera's
//! noise and a view's pose error spill into the neighbouring cells of surface already seen,
//! and the table's last millimetres around the object's base: on a bowl the laser already
//! covered, a view "added" 12–16 % of new voxels and no coverage. Here both sides are
//! taken at 5 mm cells (a density-free count of area), and a cell within 1 cm of the table
//! plane is not counted.
//!
//! A view lies where its pose error put it, up to a centimetre or two from the earlier
//! views, and the part of it that moved farther than 1 cm counted as new: on a bowl the
//! laser had covered, 0.7–1.9 % per view, over the stop's 0.5 %, for five views.
//! The view is moved onto the earlier points by the translation that lays it on them best
//! ([`settle_shift`]) before it is counted, and its own table plane moves with it: against
//! the table it was moved off, a view settled upwards showed its base above the margin (a
//! bowl the first view had covered "added" 3.3 % of its surface). Translation only: a
//! rotation lets a view of a surface of revolution (a bottle) turn onto the side already
//! seen, and its new side counted as nothing.
//!
//! The pipeline counts the view's points as the registration smooths them (an edge-gated
//! plane fit over 5 × 5 pixels, [`smooth_frame`](crate::rig::smooth_frame)): the averaged
//! frame's range noise (6 mm at 0.45 m) puts one point in eight past 1 cm off a surface
//! already seen, and a box's top the laser had covered "added" 15 % of its surface.
//! The earlier views it is counted against are read as acquired, and their noise lies
//! within 1 cm of a thin part's unseen side: a view that then sees it counts nothing (13
//! of 202 views that added 2 points of coverage or more without noise, at the scenes'
//! errors). Read smoothed too, 2 of 210; that is not the pipeline's count, because the
//! twin preset's hull mode then takes more views (docs/exploration.md, "The stop rule
//! reads the surface the views added").
//!
//! A new cell counts only beside another new cell: a flying pixel at a rim or a table
//! return past the margin is a lone cell, and on a small object (a spatula's few hundred
//! cells) a handful of them made 0.6–1.3 % per view after its coverage had reached 100 %.
//!
//! [`StopRule::new_surface`]: super::StopRule::new_surface

use std::collections::HashSet;

use kiddo::{ImmutableKdTree, SquaredEuclidean};
use nalgebra::{Matrix3, Point3, Vector3};

use crate::cloud::{PlaneFit, PointCloud, nearest_distances, neighbour_counts};
use crate::registration::estimate_normals;

/// The side of the cells surface is counted in (m).
pub const NEW_SURFACE_CELL: f64 = 0.005;

/// A view's cell is new when it lies farther than this from every earlier point (m): the
/// report's coverage tolerance, so a view that adds new surface raises coverage.
pub const NEW_SURFACE_DISTANCE: f64 = 0.01;

/// Cells this close to the table plane (m) are not counted as new: the object's base and
/// the table around it are the same surface to a noisy camera.
pub const TABLE_MARGIN: f64 = 0.01;

/// The centres of the [`NEW_SURFACE_CELL`] cells that hold a finite point of `points`, in
/// ascending cell order.
fn occupied_cells(points: &[Point3<f64>]) -> Vec<Point3<f64>> {
    let mut keys: Vec<[i64; 3]> = points
        .iter()
        .filter(|p| p.iter().all(|c| c.is_finite()))
        .map(|p| {
            p.coords
                .map(|c| (c / NEW_SURFACE_CELL).floor() as i64)
                .into()
        })
        .collect::<HashSet<[i64; 3]>>()
        .into_iter()
        .collect();
    keys.sort_unstable();
    keys.iter()
        .map(|k| Point3::from(k.map(|i| (i as f64 + 0.5) * NEW_SURFACE_CELL)))
        .collect()
}

/// The new surface `view` adds to `model` (the object's points before it, world frame):
/// the view's occupied 5 mm cells farther than [`NEW_SURFACE_DISTANCE`] from every model
/// point (and, with a `table`, farther than [`TABLE_MARGIN`] above it) that touch another
/// such cell (a lone one is a stray return), as a share of the
/// model's occupied cells. 0 for an empty view; 1 per cell for an empty model (everything
/// is new).
///
/// ```
/// use nalgebra::Point3;
/// use nbv_core::nbv::new_surface_share;
/// // A 10 × 10 cm patch, 2 mm apart, at z = 0.1.
/// let patch = |x0: f64| -> Vec<Point3<f64>> {
///     (0..50).flat_map(|i| (0..50).map(move |j| Point3::new(x0 + 0.002 * i as f64, 0.002 * j as f64, 0.1))).collect()
/// };
/// let model = patch(0.0);
/// assert_eq!(new_surface_share(&model, &model, None), 0.0); // the same surface again
/// let beside = new_surface_share(&model, &patch(0.1), None); // the next 10 cm along x
/// assert!(beside > 0.85 && beside < 1.0, "{beside}"); // all new but its first 1 cm
/// ```
pub fn new_surface_share(
    model: &[Point3<f64>],
    view: &[Point3<f64>],
    table: Option<&PlaneFit>,
) -> f64 {
    let before = occupied_cells(model).len();
    let cells: Vec<Point3<f64>> = occupied_cells(view)
        .into_iter()
        .filter(|c| table.is_none_or(|t| t.signed_distance(c) > TABLE_MARGIN))
        .collect();
    if cells.is_empty() {
        return 0.0;
    }
    let new: Vec<Point3<f64>> = nearest_distances(model, &cells)
        .iter()
        .zip(&cells)
        .filter(|&(&d, _)| d > NEW_SURFACE_DISTANCE)
        .map(|(_, c)| *c)
        .collect();
    // A new cell with no new cell beside it is a stray return, not surface.
    let beside = NEW_SURFACE_CELL * 3f64.sqrt() * 1.01;
    let surface = neighbour_counts(&new, beside)
        .into_iter()
        .filter(|&n| n > 0)
        .count();
    surface as f64 / before.max(1) as f64
}

/// Pairs farther apart than this (m) do not pull a view in [`settle_shift`]: beyond the
/// views' pose error at three times the scenes' errors.
const SETTLE_DISTANCE: f64 = 0.03;

/// Neighbours of the model's PCA normals in [`settle_shift`].
const SETTLE_NEIGHBOURS: usize = 10;

/// Iterations of [`settle_shift`].
const SETTLE_ITERATIONS: usize = 10;

/// The translation that lays `view` onto `model`: it minimises the point-to-plane
/// distances of the view's points to their nearest model points (within 3 cm; the model's
/// normals by PCA of 10 neighbours), ten Gauss–Newton steps from where the view lies. The
/// directions the pairs do not constrain (along a cylinder's axis) are damped and stay as
/// they are. Zero when the model is too small for normals. What moves with the view, its
/// own table plane ([`PlaneFit::translated`]), moves by it too.
///
/// ```
/// use nalgebra::{Point3, Vector3};
/// use nbv_core::nbv::{new_surface_share, settle_shift};
/// // A 5 cm dome seen again 2 cm higher: counted as new until settled onto the first.
/// let dome: Vec<Point3<f64>> = (0..40).flat_map(|i| (0..120).map(move |j| {
///     let (t, f) = (1.5 * i as f64 / 40.0, std::f64::consts::TAU * j as f64 / 120.0);
///     Point3::new(0.05 * t.sin() * f.cos(), 0.05 * t.sin() * f.sin(), 0.05 * t.cos())
/// })).collect();
/// let moved: Vec<_> = dome.iter().map(|p| p + Vector3::new(0.005, 0.0, 0.02)).collect();
/// assert!(new_surface_share(&dome, &moved, None) > 0.05);
/// let shift = settle_shift(&moved, &dome);
/// let settled: Vec<_> = moved.iter().map(|p| p + shift).collect();
/// assert!(new_surface_share(&dome, &settled, None) < 0.005);
/// ```
pub fn settle_shift(view: &[Point3<f64>], model: &[Point3<f64>]) -> Vector3<f64> {
    let finite = |p: &&Point3<f64>| p.iter().all(|c| c.is_finite());
    let model = PointCloud::from_points(model.iter().filter(finite).copied().collect());
    if model.len() <= SETTLE_NEIGHBOURS {
        return Vector3::zeros();
    }
    let Ok(normals) = estimate_normals(&model, SETTLE_NEIGHBOURS) else {
        return Vector3::zeros();
    };
    let coords: Vec<[f64; 3]> = model.points.iter().map(|p| [p.x, p.y, p.z]).collect();
    let Ok(tree) = ImmutableKdTree::<f64, 3>::builder().build_from_slice(&coords) else {
        return Vector3::zeros();
    };
    let mut shift = Vector3::zeros();
    for _ in 0..SETTLE_ITERATIONS {
        let mut normal_matrix = Matrix3::identity() * 1e-3;
        let mut rhs = Vector3::zeros();
        let mut pairs = 0usize;
        for p in view.iter().filter(finite) {
            let q = p + shift;
            let nearest = tree
                .query(&[q.x, q.y, q.z])
                .nearest_one::<SquaredEuclidean<f64>>()
                .execute();
            if nearest.distance > SETTLE_DISTANCE * SETTLE_DISTANCE {
                continue;
            }
            let i = nearest.item as usize;
            let n = normals[i];
            normal_matrix += n * n.transpose();
            rhs += n * n.dot(&(model.points[i] - q));
            pairs += 1;
        }
        if pairs == 0 {
            break;
        }
        let Some(step) = normal_matrix.lu().solve(&rhs) else {
            break;
        };
        shift += step;
        if step.norm() < 1e-5 {
            break;
        }
    }
    shift
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Unit, Vector3};
    use proptest::prelude::*;

    /// `view` moved by [`settle_shift`] onto `model`.
    fn settled_onto(view: &[Point3<f64>], model: &[Point3<f64>]) -> Vec<Point3<f64>> {
        let shift = settle_shift(view, model);
        view.iter().map(|p| p + shift).collect()
    }

    /// Points of a w × h patch 2 mm apart in the plane z = `z`, from (x0, 0).
    fn patch(x0: f64, w: f64, h: f64, z: f64) -> Vec<Point3<f64>> {
        let (nx, ny) = ((w / 0.002) as usize, (h / 0.002) as usize);
        (0..nx)
            .flat_map(|i| {
                (0..ny).map(move |j| Point3::new(x0 + 0.002 * i as f64, 0.002 * j as f64, z))
            })
            .collect()
    }

    /// A table at z = 0.
    fn table() -> PlaneFit {
        PlaneFit {
            normal: Unit::new_normalize(Vector3::z()),
            offset: 0.0,
            inliers: Vec::new(),
            rms: 0.0,
        }
    }

    /// Points 3 mm apart on a vertical cylinder of radius 4 cm, 12 cm tall, about
    /// (0.8, 0, ·), between azimuths `from` and `to` (rad).
    fn cylinder(from: f64, to: f64) -> Vec<Point3<f64>> {
        let n = ((to - from) * 0.04 / 0.003).ceil() as usize;
        (0..n)
            .flat_map(|i| {
                let a = from + (to - from) * i as f64 / n as f64;
                (0..40).map(move |j| {
                    Point3::new(0.8 + 0.04 * a.cos(), 0.04 * a.sin(), 0.003 * j as f64)
                })
            })
            .collect()
    }

    #[test]
    fn a_surface_seen_again_through_the_range_noise_adds_nothing_once_smoothed() {
        use crate::math::Pose;
        use crate::rig::{DepthCameraSpec, DepthFrame, depth_frame_to_cloud, smooth_frame};
        // The 15 × 10 cm top of a box, which the laser saw, 0.45 m below the camera.
        let model = patch(-0.075, 0.15, 0.1, 0.45)
            .iter()
            .map(|p| p - Vector3::y() * 0.05)
            .collect::<Vec<_>>();
        // The camera sees it again, through a burst of eight frames' range noise.
        let spec = DepthCameraSpec::ipa1110();
        let sigma = DepthFrame::burst_sigma;
        let frame = DepthFrame::averaged_burst(&spec, 3, |ray| {
            let (x, y) = (0.45 * ray.x, 0.45 * ray.y);
            (x.abs() < 0.075 && y.abs() < 0.05).then_some(0.45)
        });
        let points = |f: &DepthFrame| {
            depth_frame_to_cloud(f, &spec, &Pose::identity())
                .unwrap()
                .points
        };
        // As acquired, the noise's tails past 1 cm make new "surface"; smoothed, none.
        let raw = new_surface_share(&model, &points(&frame), None);
        let smoothed = new_surface_share(&model, &points(&smooth_frame(frame, 2, sigma)), None);
        assert!(raw > 0.05, "{raw}");
        assert!(smoothed < 0.005, "{smoothed}");
    }

    #[test]
    fn lone_cells_are_stray_returns_and_a_patch_is_surface() {
        let model = patch(0.0, 0.1, 0.1, 0.1);
        // Ten stray returns 3 cm above the model, 2 cm apart: no new surface.
        let strays: Vec<Point3<f64>> = (0..10)
            .map(|i| Point3::new(0.02 * i as f64, 0.05, 0.13))
            .collect();
        assert_eq!(new_surface_share(&model, &strays, None), 0.0);
        // A 2 × 2 cm patch there: its 16 cells, each beside another.
        let lid = patch(0.04, 0.02, 0.02, 0.13);
        let cells = occupied_cells(&model).len() as f64;
        assert_eq!(new_surface_share(&model, &lid, None), 16.0 / cells);
    }

    #[test]
    fn settling_takes_out_the_pose_error_and_keeps_a_new_side() {
        use std::f64::consts::PI;
        let seen = cylinder(-PI / 2.0, PI / 2.0);
        let shift = Vector3::new(-0.012, 0.008, 0.01);
        // The same side again, moved by a pose error: nothing new once settled.
        let again: Vec<Point3<f64>> = cylinder(-PI / 3.0, PI / 3.0)
            .iter()
            .map(|p| p + shift)
            .collect();
        assert!(new_surface_share(&seen, &again, None) > 0.05);
        assert!(new_surface_share(&seen, &settled_onto(&again, &seen), None) < 0.005);
        // The far side, half of it unseen: a rotation about the axis would lay it on the
        // seen side; the translation leaves it new.
        let far: Vec<Point3<f64>> = cylinder(PI / 4.0, 5.0 * PI / 4.0)
            .iter()
            .map(|p| p + shift)
            .collect();
        let truth = new_surface_share(&seen, &cylinder(PI / 4.0, 5.0 * PI / 4.0), None);
        let settled = new_surface_share(&seen, &settled_onto(&far, &seen), None);
        assert!(truth > 0.3 && settled > 0.9 * truth, "{truth} {settled}");
        // Too small a model: the view as it is.
        assert!(settled_onto(&again, &seen[..5]) == again);
    }

    /// A 10 × 10 cm model; a view of the next 5 × 10 cm strip: by hand, the strip's cells
    /// past 1 cm from the model are 4/5 of its 10 columns of cells (its first 2 columns lie
    /// within 1 cm), 8 × 20 = 160 cells over the model's 20 × 20 = 400: 0.4 (a cell's centre
    /// is 2.5 mm in, so the third column, 1.25 cm from the edge, is new).
    #[test]
    fn a_strip_beside_the_model_by_hand() {
        let model = patch(0.0, 0.1, 0.1, 0.1);
        let strip = patch(0.1, 0.05, 0.1, 0.1);
        let share = new_surface_share(&model, &strip, None);
        assert!((share - 0.4).abs() < 0.03, "{share}");
    }

    /// Noise and a pose error under 1 cm add nothing; the table's margin hides a skirt.
    #[test]
    fn noise_pose_error_and_the_table_skirt_are_not_new() {
        let model = patch(0.0, 0.1, 0.1, 0.05);
        let shifted: Vec<Point3<f64>> = model
            .iter()
            .enumerate()
            .map(|(i, p)| p + Vector3::new(0.004, -0.003, 0.002 * ((i % 7) as f64 / 7.0 - 0.5)))
            .collect();
        assert_eq!(new_surface_share(&model, &shifted, None), 0.0);
        let skirt = patch(0.12, 0.05, 0.1, 0.004);
        assert!(new_surface_share(&model, &skirt, None) > 0.2);
        assert_eq!(new_surface_share(&model, &skirt, Some(&table())), 0.0);
    }

    /// A view lies 6 mm low with its own table: settled up onto the model, its table moves
    /// with it, and the base the margin hides stays hidden (the same share as the view
    /// without the error); against its table left behind, the base counts as new.
    #[test]
    fn the_table_moves_with_the_settled_view() {
        use std::f64::consts::PI;
        let lid: Vec<Point3<f64>> = patch(0.76, 0.08, 0.08, 0.117)
            .into_iter()
            .map(|p| p - Vector3::new(0.0, 0.04, 0.0))
            .filter(|p| (p.x - 0.8).hypot(p.y) < 0.04)
            .collect();
        let model: Vec<Point3<f64>> = cylinder(-PI / 2.0, PI / 2.0)
            .into_iter()
            .filter(|p| p.z >= 0.03)
            .chain(lid.iter().copied())
            .collect();
        let view: Vec<Point3<f64>> = cylinder(-PI / 2.0, PI / 2.0)
            .into_iter()
            .chain(lid)
            .collect();
        let error = Vector3::new(0.0, 0.0, -0.006);
        let low: Vec<Point3<f64>> = view.iter().map(|p| p + error).collect();
        let low_table = table().translated(&error);
        let truth = new_surface_share(&model, &view, Some(&table()));
        let shift = settle_shift(&low, &model);
        assert!((shift + error).norm() < 0.001, "{shift:?}");
        let settled: Vec<Point3<f64>> = low.iter().map(|p| p + shift).collect();
        let moved = new_surface_share(&model, &settled, Some(&low_table.translated(&shift)));
        let left = new_surface_share(&model, &settled, Some(&low_table));
        assert!(truth > 0.05, "{truth}");
        assert!((moved - truth).abs() < 0.1 * truth, "{moved} {truth}");
        assert!(left > 1.3 * truth, "{left} {truth}");
    }

    #[test]
    fn empty_view_adds_nothing_and_empty_model_takes_everything_as_new() {
        let model = patch(0.0, 0.02, 0.02, 0.1);
        assert_eq!(new_surface_share(&model, &[], None), 0.0);
        let non_finite = [Point3::new(f64::NAN, 0.0, 0.0)];
        assert_eq!(new_surface_share(&model, &non_finite, None), 0.0);
        assert!(new_surface_share(&[], &model, None) >= 1.0);
    }

    proptest! {
        /// A view made of the model's own points adds nothing; adding points to the model
        /// never makes a view add more.
        #[test]
        fn a_view_of_the_model_adds_nothing_and_more_model_never_adds_more(
            pts in proptest::collection::vec((-0.2f64..0.2, -0.2f64..0.2, 0.0f64..0.3), 1..200),
            split in 0usize..200,
        ) {
            let pts: Vec<Point3<f64>> = pts.into_iter().map(|(x, y, z)| Point3::new(x, y, z)).collect();
            prop_assert_eq!(new_surface_share(&pts, &pts, None), 0.0);
            let k = split.min(pts.len());
            let (model, view) = pts.split_at(k);
            let small = new_surface_share(model, view, None) * occupied_cells(model).len().max(1) as f64;
            let larger_model: Vec<Point3<f64>> = model.iter().chain(view.iter().take(1)).copied().collect();
            let large = new_surface_share(&larger_model, view, None) * occupied_cells(&larger_model).len().max(1) as f64;
            prop_assert!(large <= small + 1e-9, "{large} > {small}");
        }
    }
}
