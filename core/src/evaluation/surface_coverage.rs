//! [`surface_coverage`]: the share of a true surface (above a floor) that lies within a
//! tolerance of a model cloud, from seeded area-weighted samples of the surface;
//! [`surface_coverage_curve`]: the same for a model growing part by part (an object's
//! coverage after each view).

use crate::cloud::{PointCloud, near_mask};
use crate::mesh::TriMesh;
use nalgebra::{Point3, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// The result of [`surface_coverage`].
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Coverage {
    /// Surface samples considered (above the floor).
    pub samples: usize,
    /// Samples within the tolerance of a model point.
    pub covered: usize,
}

impl Coverage {
    /// `covered / samples` (0 without samples).
    pub fn share(&self) -> f64 {
        if self.samples == 0 {
            0.0
        } else {
            self.covered as f64 / self.samples as f64
        }
    }
}

/// `n` points on `mesh`'s surface, uniform by area, from `seed` (the same seed gives the
/// same points). An empty or degenerate mesh gives none.
///
/// ```
/// use nbv_core::evaluation::sample_surface;
/// use nbv_core::mesh::TriMesh;
/// let cube = TriMesh::cuboid([0.5, 0.5, 0.5]);
/// let pts = sample_surface(&cube, 1000, 1);
/// assert_eq!(pts.len(), 1000);
/// // Every sample lies on a face of the unit cube.
/// assert!(pts.iter().all(|p| p.iter().any(|c| (c.abs() - 0.5).abs() < 1e-12)));
/// ```
pub fn sample_surface(mesh: &TriMesh, n: usize, seed: u64) -> Vec<Point3<f64>> {
    sample_surface_with_normals(mesh, n, seed)
        .into_iter()
        .map(|(p, _)| p)
        .collect()
}

/// [`sample_surface`]'s points (the same ones, from the same draws) with the unit normal
/// of the triangle each lies on (outward for an outward-oriented mesh; zero for a
/// degenerate triangle).
///
/// ```
/// use nbv_core::evaluation::{sample_surface, sample_surface_with_normals};
/// use nbv_core::mesh::TriMesh;
/// let cube = TriMesh::cuboid([0.5, 0.5, 0.5]);
/// let with = sample_surface_with_normals(&cube, 200, 4);
/// let points: Vec<_> = with.iter().map(|(p, _)| *p).collect();
/// assert_eq!(points, sample_surface(&cube, 200, 4));
/// // On a face of the unit cube the normal is that face's axis, pointing out.
/// assert!(with.iter().all(|(p, n)| (p.coords.dot(n) - 0.5).abs() < 1e-12));
/// ```
pub fn sample_surface_with_normals(
    mesh: &TriMesh,
    n: usize,
    seed: u64,
) -> Vec<(Point3<f64>, Vector3<f64>)> {
    let mut cumulative = Vec::with_capacity(mesh.triangles.len());
    let mut total = 0.0;
    for i in 0..mesh.triangles.len() {
        let [a, b, c] = mesh.triangle(i);
        total += (b - a).cross(&(c - a)).norm() / 2.0;
        cumulative.push(total);
    }
    if total.is_nan() || total <= 0.0 {
        return Vec::new();
    }
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..n)
        .map(|_| {
            let x = rng.random::<f64>() * total;
            let i = cumulative
                .partition_point(|&c| c < x)
                .min(cumulative.len() - 1);
            let [a, b, c] = mesh.triangle(i);
            let (mut u, mut v) = (rng.random::<f64>(), rng.random::<f64>());
            if u + v > 1.0 {
                (u, v) = (1.0 - u, 1.0 - v);
            }
            (a + (b - a) * u + (c - a) * v, mesh.triangle_normal(i))
        })
        .collect()
}

/// Coverage of `surface` (world frame) by `model`: of `samples` area-weighted samples of
/// the surface (seeded) those with `z > floor`, the share within `tolerance` of a model
/// point.
///
/// ```
/// use nbv_core::cloud::PointCloud;
/// use nbv_core::evaluation::{sample_surface, surface_coverage};
/// use nbv_core::mesh::TriMesh;
/// let cube = TriMesh::cuboid([0.5, 0.5, 0.5]);
/// // A model of the top face only: 1/6 of the surface, 1/5 of it above z = -0.499.
/// let top: Vec<_> = sample_surface(&cube, 20_000, 9).into_iter().filter(|p| p.z > 0.499).collect();
/// let c = surface_coverage(&cube, &PointCloud::from_points(top), 0.02, -0.499, 5000, 3);
/// assert!((c.share() - 0.2).abs() < 0.02, "{}", c.share());
/// ```
pub fn surface_coverage(
    surface: &TriMesh,
    model: &PointCloud,
    tolerance: f64,
    floor: f64,
    samples: usize,
    seed: u64,
) -> Coverage {
    let points: Vec<Point3<f64>> = sample_surface(surface, samples, seed)
        .into_iter()
        .filter(|p| p.z > floor)
        .collect();
    Coverage {
        samples: points.len(),
        covered: count_near(&model.points, &points, tolerance),
    }
}

/// [`surface_coverage`] of the models `parts[0]`, `parts[0] ∪ parts[1]`, …: element `k`
/// is the coverage by the first `k + 1` parts, exactly as `surface_coverage` of their
/// union gives it. A sample is covered by a union when some part has a point within the
/// tolerance, so the surface is sampled once and each part is searched only for the
/// samples the earlier parts left uncovered.
///
/// ```
/// use nbv_core::cloud::PointCloud;
/// use nbv_core::evaluation::{sample_surface, surface_coverage, surface_coverage_curve};
/// use nbv_core::mesh::TriMesh;
/// let cube = TriMesh::cuboid([0.5, 0.5, 0.5]);
/// let dense = sample_surface(&cube, 20_000, 9);
/// let top = PointCloud::from_points(dense.iter().copied().filter(|p| p.z > 0.499).collect());
/// let side = PointCloud::from_points(dense.iter().copied().filter(|p| p.x > 0.499).collect());
/// let curve = surface_coverage_curve(&cube, &[&top, &PointCloud::default(), &side], 0.02, -0.499, 5000, 3);
/// let mut both = top.clone();
/// both.extend(&side);
/// assert_eq!(curve[0], surface_coverage(&cube, &top, 0.02, -0.499, 5000, 3));
/// assert_eq!(curve[1], curve[0]); // an empty part adds nothing
/// assert_eq!(curve[2], surface_coverage(&cube, &both, 0.02, -0.499, 5000, 3));
/// ```
pub fn surface_coverage_curve(
    surface: &TriMesh,
    parts: &[&PointCloud],
    tolerance: f64,
    floor: f64,
    samples: usize,
    seed: u64,
) -> Vec<Coverage> {
    let mut uncovered: Vec<Point3<f64>> = sample_surface(surface, samples, seed)
        .into_iter()
        .filter(|p| p.z > floor)
        .collect();
    let total = uncovered.len();
    parts
        .iter()
        .map(|part| {
            if !part.is_empty() && !uncovered.is_empty() {
                let near = near_mask(&part.points, &uncovered, tolerance);
                let mut near = near.into_iter();
                uncovered.retain(|_| !near.next().unwrap_or(false));
            }
            Coverage {
                samples: total,
                covered: total - uncovered.len(),
            }
        })
        .collect()
}

/// How many of `queries` lie within `tolerance` of a finite point of `reference` (0 when
/// it has none).
pub(crate) fn count_near(
    reference: &[Point3<f64>],
    queries: &[Point3<f64>],
    tolerance: f64,
) -> usize {
    near_mask(reference, queries, tolerance)
        .into_iter()
        .filter(|&near| near)
        .count()
}
