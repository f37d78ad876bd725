//! Fixed-radius neighbourhoods of point sets: [`near_mask`] (which query points lie within
//! a distance of a reference set — behind coverage, precision and the table filter's
//! footprint rule) and [`neighbour_counts`] (how dense a set is around each of its points).

use kiddo::{ImmutableKdTree, SquaredEuclidean};
use nalgebra::Point3;

/// For each of `queries`, whether a finite point of `reference` lies within `tolerance`
/// of it (all `false` when `reference` has none).
///
/// ```
/// use nbv_core::cloud::near_mask;
/// use nalgebra::Point3;
/// let reference = [Point3::origin(), Point3::new(1.0, 0.0, 0.0)];
/// let queries = [Point3::new(0.0, 0.05, 0.0), Point3::new(0.5, 0.0, 0.0)];
/// assert_eq!(near_mask(&reference, &queries, 0.1), vec![true, false]);
/// ```
pub fn near_mask(reference: &[Point3<f64>], queries: &[Point3<f64>], tolerance: f64) -> Vec<bool> {
    let coords: Vec<[f64; 3]> = reference
        .iter()
        .filter(|p| p.iter().all(|c| c.is_finite()))
        .map(|p| [p.x, p.y, p.z])
        .collect();
    if coords.is_empty() {
        return vec![false; queries.len()];
    }
    let Ok(tree) = ImmutableKdTree::<f64, 3>::builder().build_from_slice(&coords) else {
        return vec![false; queries.len()];
    };
    let limit = tolerance * tolerance;
    queries
        .iter()
        .map(|p| {
            tree.query(&[p.x, p.y, p.z])
                .nearest_one::<SquaredEuclidean<f64>>()
                .execute()
                .distance
                <= limit
        })
        .collect()
}

/// For each point of `points`, how many other points of the set lie within `radius` of it
/// (non-finite points count 0 and are nobody's neighbour).
///
/// ```
/// use nbv_core::cloud::neighbour_counts;
/// use nalgebra::Point3;
/// let pts = [Point3::origin(), Point3::new(0.01, 0.0, 0.0), Point3::new(1.0, 0.0, 0.0)];
/// assert_eq!(neighbour_counts(&pts, 0.05), vec![1, 1, 0]);
/// ```
pub fn neighbour_counts(points: &[Point3<f64>], radius: f64) -> Vec<usize> {
    let finite = |p: &Point3<f64>| p.iter().all(|c| c.is_finite());
    let coords: Vec<[f64; 3]> = points
        .iter()
        .filter(|p| finite(p))
        .map(|p| [p.x, p.y, p.z])
        .collect();
    let Ok(tree) = ImmutableKdTree::<f64, 3>::builder().build_from_slice(&coords) else {
        return vec![0; points.len()];
    };
    points
        .iter()
        .map(|p| {
            if !finite(p) {
                return 0;
            }
            tree.query(&[p.x, p.y, p.z])
                .within::<SquaredEuclidean<f64>>(radius * radius)
                .unsorted()
                .execute()
                .len()
                .saturating_sub(1)
        })
        .collect()
}
