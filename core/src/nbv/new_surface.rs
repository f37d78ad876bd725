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
//! [`StopRule::new_surface`]: super::StopRule::new_surface

use std::collections::HashSet;

use nalgebra::Point3;

use crate::cloud::{PlaneFit, nearest_distances};

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
/// point (and, with a `table`, farther than [`TABLE_MARGIN`] above it), as a share of the
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
    let new = nearest_distances(model, &cells)
        .iter()
        .filter(|&&d| d > NEW_SURFACE_DISTANCE)
        .count();
    new as f64 / before.max(1) as f64
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Unit, Vector3};
    use proptest::prelude::*;

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
