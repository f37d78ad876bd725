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
/// let cube = TriMesh::cuboid([0.05, 0.05, 0.05]); // a 10 cm cube
/// // 300 points on the surface, drawn independently of the samples precision is measured
/// // against (another seed), then 3 mm and 3 cm off it along the top face's normal.
/// let on = sample_surface(&cube, 300, 7);
/// let lift = |p: &Point3<f64>, d: f64| if p.z > 0.0499 { p + nalgebra::Vector3::z() * d } else { *p };
/// let near: Vec<_> = on.iter().map(|p| lift(p, 0.003)).collect();
/// let far: Vec<_> = on.iter().map(|p| lift(p, 0.03)).collect();
/// let top = on.iter().filter(|p| p.z > 0.0499).count() as f64;
/// let precision = |pts: Vec<Point3<f64>>| {
///     model_precision(&cube, &PointCloud::from_points(pts), 0.01, 50_000, 2).unwrap()
/// };
/// assert_eq!(precision(near), 1.0); // 3 mm off: within 1 cm
/// assert!((precision(far) - (300.0 - top) / 300.0).abs() < 1e-12); // the top's points out
/// assert!(top > 20.0);
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
