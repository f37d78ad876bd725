//! [`model_precision`]: the share of a model's points that lie within a tolerance of the
//! true surface — the other half of [`surface_coverage`](super::surface_coverage) (recall):
//! a model padded with table points or noise covers more and is worse.

use crate::cloud::PointCloud;
use crate::mesh::TriMesh;
use nalgebra::Point3;

use super::sample_surface;
use super::surface_coverage::count_near;

/// Of the finite points of `model`, the share within `tolerance` of `surface`, measured
/// against `samples` area-weighted samples of the surface (seeded; take them dense
/// against the tolerance). `None` for an empty model or surface.
///
/// ```
/// use nbv_core::cloud::PointCloud;
/// use nbv_core::evaluation::{model_precision, sample_surface};
/// use nbv_core::mesh::TriMesh;
/// use nalgebra::Point3;
/// let cube = TriMesh::cuboid([0.5, 0.5, 0.5]);
/// // 300 points on the surface (the first of the samples precision is measured against).
/// let mut points = sample_surface(&cube, 300, 2);
/// points.push(Point3::new(0.0, 0.0, 0.0)); // the cube's centre, 0.5 from every face
/// let p = model_precision(&cube, &PointCloud::from_points(points), 0.01, 50_000, 2).unwrap();
/// assert!((p - 300.0 / 301.0).abs() < 1e-12);
/// ```
pub fn model_precision(
    surface: &TriMesh,
    model: &PointCloud,
    tolerance: f64,
    samples: usize,
    seed: u64,
) -> Option<f64> {
    let surface = sample_surface(surface, samples, seed);
    let finite: Vec<Point3<f64>> = model
        .points
        .iter()
        .filter(|p| p.iter().all(|c| c.is_finite()))
        .copied()
        .collect();
    if surface.is_empty() || finite.is_empty() {
        return None;
    }
    let near = count_near(&surface, &finite, tolerance);
    Some(near as f64 / finite.len() as f64)
}
