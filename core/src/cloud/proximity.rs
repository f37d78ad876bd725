//! Neighbourhoods of point sets: [`nearest_distances`] (how far each query point lies from
//! a reference set — behind the model-quality figures and the Chamfer distance),
//! [`near_mask`] (which query points lie within a distance of it — behind coverage,
//! precision and the table filter's footprint rule) and [`neighbour_counts`] (how dense a
//! set is around each of its points).

use kiddo::{ImmutableKdTree, SquaredEuclidean};
use nalgebra::Point3;
use rayon::prelude::*;

/// For each of `queries`, whether a finite point of `reference` lies within `tolerance`
/// of it (all `false` when `reference` has none): [`nearest_distances`] against the
/// tolerance.
///
/// ```
/// use nbv_core::cloud::near_mask;
/// use nalgebra::Point3;
/// let reference = [Point3::origin(), Point3::new(1.0, 0.0, 0.0)];
/// let queries = [Point3::new(0.0, 0.05, 0.0), Point3::new(0.5, 0.0, 0.0)];
/// assert_eq!(near_mask(&reference, &queries, 0.1), vec![true, false]);
/// ```
pub fn near_mask(reference: &[Point3<f64>], queries: &[Point3<f64>], tolerance: f64) -> Vec<bool> {
    nearest_distances(reference, queries)
        .into_iter()
        .map(|d| d <= tolerance)
        .collect()
}

/// For each of `queries`, the distance to the nearest finite point of `reference`
/// (a k-d tree over the reference); infinite for a non-finite query, and for every query
/// when `reference` has no finite point.
///
/// ```
/// use nbv_core::cloud::nearest_distances;
/// use nalgebra::Point3;
/// let reference = [Point3::origin(), Point3::new(1.0, 0.0, 0.0)];
/// let queries = [Point3::new(0.0, 0.05, 0.0), Point3::new(0.7, 0.0, 0.0)];
/// let d = nearest_distances(&reference, &queries);
/// assert!((d[0] - 0.05).abs() < 1e-15 && (d[1] - 0.3).abs() < 1e-15);
/// assert!(nearest_distances(&[], &queries).iter().all(|d| d.is_infinite()));
/// ```
pub fn nearest_distances(reference: &[Point3<f64>], queries: &[Point3<f64>]) -> Vec<f64> {
    let finite = |p: &Point3<f64>| p.iter().all(|c| c.is_finite());
    let coords: Vec<[f64; 3]> = reference
        .iter()
        .filter(|p| finite(p))
        .map(|p| [p.x, p.y, p.z])
        .collect();
    let tree = if coords.is_empty() {
        None
    } else {
        ImmutableKdTree::<f64, 3>::builder()
            .build_from_slice(&coords)
            .ok()
    };
    let Some(tree) = tree else {
        return vec![f64::INFINITY; queries.len()];
    };
    // Each query alone: in parallel, in order, the same at any thread count.
    queries
        .par_iter()
        .map(|p| {
            if !finite(p) {
                return f64::INFINITY;
            }
            tree.query(&[p.x, p.y, p.z])
                .nearest_one::<SquaredEuclidean<f64>>()
                .execute()
                .distance
                .sqrt()
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
