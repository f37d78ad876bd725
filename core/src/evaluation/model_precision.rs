//! [`model_precision`]: the share of a model's points that lie within a tolerance of the
//! true surface — the other half of [`surface_coverage`](super::surface_coverage) (recall):
//! a model padded with table points or noise covers more and is worse. The precision of
//! [`model_quality`](super::model_quality), which says how it is measured.

use crate::cloud::PointCloud;
use crate::mesh::TriMesh;

use super::model_quality;

/// Of the finite points of `model`, the share within `tolerance` of `surface`, measured
/// against `samples` area-weighted samples of the surface (seeded; take them dense
/// against the tolerance: [`quality_samples`](super::quality_samples)). `None` for an
/// empty model or surface.
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
    model_quality(surface, model, tolerance, f64::NEG_INFINITY, samples, seed).map(|q| q.precision)
}
