//! [`MapView`]: one view prepared once for the maximum a posteriori registration, in its
//! own frame — its k-d tree, each point's viewing ray and range σ, and each point's local
//! surface element ([`Surfel`]: the mean of its neighbourhood, and the normal where the
//! neighbourhood determines one).
//!
//! A surfel's normal is kept only when the plane fit pins it down: the standard error of
//! a plane fitted to `k` points whose spread is `λ₁` in its narrower in-plane direction and
//! `λ₀` across is about `√(λ₀ / (k·λ₁))` rad. Laser views at their 2 mm noise pass this
//! on most of an object's surface; camera views at centimetre noise mostly do not, and
//! their residuals stay point-to-point with the noise along the rays.
//!
//! A surfel also says whether its point lies on the view's boundary (the edge of what the
//! sensor saw): there the neighbours sit on one side, so their mean is off the point, in
//! the tangent plane, by more than [`BOUNDARY_OFFSET`] of the neighbourhood's spread in
//! that direction (an edge point of a uniformly sampled surface: ≈ 1.6; an interior point:
//! ≈ 1/√k). A point of another view whose nearest point here is a boundary point lies
//! beyond what this view saw, not on it (Turk & Levoy's boundary rejection, "Zippered
//! polygon meshes from range images", SIGGRAPH 1994): matched, it would drag its view
//! towards the edge.

use std::num::NonZeroUsize;

use nalgebra::{Matrix3, Point3, Vector3};
use rayon::prelude::*;

use super::depth_image_free_space::DepthImageFreeSpace;
use super::free_space::FreeSpace;
use crate::cloud::{KNearest, PointCloud};
use crate::math::symmetric_eigen3;
use crate::registration::neighbour_graph::NeighbourGraph;
use crate::registration::view_tree::ViewTree;
use crate::registration::{RangeNoise, RegistrationError};

/// Largest standard error (rad) of a surfel's normal for it to be used (≈ 8.6°).
const MAX_NORMAL_ERROR: f64 = 0.15;

/// A point is on the boundary when its neighbourhood's mean is off it, in the tangent
/// plane, by more than this many standard deviations of the neighbourhood along the offset.
pub(crate) const BOUNDARY_OFFSET: f64 = 1.0;

/// Points per parallel work item.
const CHUNK: usize = 256;

/// A point's local surface: where its neighbourhood's mean lies, the normal if reliable,
/// and the variance of the mean along the viewing ray.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Surfel {
    /// Mean of the point's `k` nearest neighbours (view frame).
    pub position: Point3<f64>,
    /// Unit normal of the neighbourhood, when the fit determines it, facing the sensor
    /// (where the viewing ray is known).
    pub normal: Option<Vector3<f64>>,
    /// Variance of `position` along the viewing ray (m²): the points' σ² over `k`.
    pub variance: f64,
    /// How many points the surfel was fitted to (`k`, fewer in a smaller view): the
    /// divisor of its variance.
    pub fitted: f64,
    /// Where the point lies on the view's boundary (see the module doc): the unit
    /// in-plane direction out of the surface, away from its neighbours.
    pub boundary: Option<Vector3<f64>>,
}

/// One view, prepared.
pub(crate) struct MapView {
    /// The points (view frame) and their k-d tree.
    pub tree: ViewTree,
    /// Unit viewing ray per point (view frame); zero where the sensor origin is unknown
    /// (the noise is then taken as isotropic).
    pub rays: Vec<Vector3<f64>>,
    /// Range σ per point (m).
    pub sigmas: Vec<f64>,
    /// Local surface per point.
    pub surfels: Vec<Surfel>,
    /// Median distance between neighbouring points (m).
    pub spacing: f64,
    /// The sensor origin (mean of the `origins` column), else the centroid (view frame):
    /// the centre of the view's pose correction.
    pub centre: Point3<f64>,
    /// Where this view's sensor saw empty space (view frame), when known.
    pub free_space: Option<SeenEmpty>,
}

/// Where a view's sensor saw empty space: a scanner's rays marked in a grid
/// ([`FreeSpace`]) or a depth camera's image ([`DepthImageFreeSpace`]).
pub(crate) enum SeenEmpty {
    /// A scan's rays (the laser sweep).
    Rays(FreeSpace),
    /// A depth image (a camera view).
    DepthImage(DepthImageFreeSpace),
}

impl SeenEmpty {
    /// Whether `p` (view frame) lies where the sensor's rays passed.
    pub(crate) fn contains(&self, p: &Point3<f64>) -> bool {
        match self {
            Self::Rays(f) => f.contains(p),
            Self::DepthImage(f) => f.contains(p),
        }
    }
}

impl MapView {
    /// Prepares view `index` (already checked) with its sensor noise; `k` neighbours per
    /// surfel.
    pub(crate) fn new(
        index: usize,
        cloud: &PointCloud,
        noise: &RangeNoise,
        k: usize,
    ) -> Result<Self, RegistrationError> {
        let mut tree = ViewTree::build(index, &cloud.points)?;
        let points = tree.points();
        let (rays, sigmas) = rays_and_sigmas(cloud, noise);
        let centre = cloud.origin_centroid().unwrap_or_else(|| tree.centroid());
        let k = NonZeroUsize::new(k.max(3)).unwrap_or(NonZeroUsize::MIN);
        let nearest = KNearest::of_each(points, k).map_err(|e| RegistrationError::KdTree {
            view: index,
            message: e.to_string(),
        })?;
        let per_point: Vec<(Surfel, f64)> = (0..points.len().div_ceil(CHUNK))
            .into_par_iter()
            .map(|c| {
                (c * CHUNK..((c + 1) * CHUNK).min(points.len()))
                    .map(|i| {
                        let near = nearest.of(i);
                        let surfel = fit_surfel(
                            &points[i],
                            near.iter().map(|&(j, _)| points[j as usize]),
                            sigmas[i],
                            &rays[i],
                        );
                        // The nearest point is the point itself (or a duplicate of it):
                        // the second nearest gives the gap to a neighbour.
                        let gap = near.get(1).map_or(0.0, |&(_, sq)| sq.sqrt());
                        (surfel, gap)
                    })
                    .collect::<Vec<_>>()
            })
            .flatten_iter()
            .collect();
        let (surfels, mut gaps): (Vec<Surfel>, Vec<f64>) = per_point.into_iter().unzip();
        // The nearest-point caches repair their answers by walks on this graph instead of
        // searching the tree again (`nearest_cache.rs`); it lists the surfels' neighbours.
        tree.set_graph(NeighbourGraph::from_nearest(&nearest));
        gaps.sort_by(f64::total_cmp);
        let spacing = gaps.get(gaps.len() / 2).copied().unwrap_or(0.0);
        Ok(Self {
            tree,
            rays,
            sigmas,
            surfels,
            spacing,
            centre,
            free_space: None,
        })
    }

    /// The view prepared from the same `cloud` (the one it was made from) with another
    /// sensor noise: the same tree, surfaces and neighbour graph, each point's σ and each
    /// surfel's variance as [`new`](Self::new) gives them at `noise`, without its free
    /// space. The neighbourhoods do not depend on the noise, so none is searched again.
    pub(crate) fn with_noise(self, cloud: &PointCloud, noise: &RangeNoise) -> Self {
        let (rays, sigmas) = rays_and_sigmas(cloud, noise);
        let surfels = self
            .surfels
            .iter()
            .zip(&sigmas)
            .map(|(s, sigma)| Surfel {
                variance: sigma * sigma / s.fitted,
                ..*s
            })
            .collect();
        Self {
            tree: self.tree,
            rays,
            sigmas,
            surfels,
            spacing: self.spacing,
            centre: self.centre,
            free_space: None,
        }
    }

    /// Number of points.
    pub(crate) fn len(&self) -> usize {
        self.sigmas.len()
    }
}

/// Each point's unit viewing ray (zero where its sensor origin is unknown or at the point)
/// and its range σ under `noise` (at 1 m where the range is unknown).
fn rays_and_sigmas(cloud: &PointCloud, noise: &RangeNoise) -> (Vec<Vector3<f64>>, Vec<f64>) {
    let points = &cloud.points;
    match &cloud.origins {
        Some(origins) => points
            .iter()
            .zip(origins)
            .map(|(p, o)| {
                let d = (p - o).norm();
                if d > 1e-9 {
                    ((p - o) / d, noise.sigma(d))
                } else {
                    (Vector3::zeros(), noise.sigma(1.0))
                }
            })
            .unzip(),
        None => (
            vec![Vector3::zeros(); points.len()],
            vec![noise.sigma(1.0); points.len()],
        ),
    }
}

/// The surfel of `point`'s neighbourhood `points`, whose points have range σ `sigma`, its
/// normal facing back along the viewing ray `ray` (kept as fitted where the ray is
/// unknown).
fn fit_surfel(
    point: &Point3<f64>,
    points: impl Iterator<Item = Point3<f64>> + Clone,
    sigma: f64,
    ray: &Vector3<f64>,
) -> Surfel {
    let (sum, n) = points
        .clone()
        .fold((Vector3::zeros(), 0usize), |(s, n), p| {
            (s + p.coords, n + 1)
        });
    let n = n.max(1) as f64;
    let mean = sum / n;
    let cov = points.fold(Matrix3::zeros(), |c, p| {
        let d = p.coords - mean;
        c + d * d.transpose()
    }) / n;
    let (eigenvalues, eigenvectors) = symmetric_eigen3(&cov);
    let mut order = [0usize, 1, 2];
    order.sort_by(|&a, &b| eigenvalues[a].total_cmp(&eigenvalues[b]));
    let (l0, l1) = (
        eigenvalues[order[0]].max(0.0),
        eigenvalues[order[1]].max(0.0),
    );
    let reliable = l1 > 0.0 && l0 / (n * l1) < MAX_NORMAL_ERROR * MAX_NORMAL_ERROR;
    // The mean's offset from the point along each in-plane axis, in that axis's σ.
    let offset = mean - point.coords;
    let on_edge = order[1..].iter().any(|&a| {
        let spread = eigenvalues[a].max(0.0).sqrt();
        let along = offset.dot(&eigenvectors.column(a)).abs();
        spread > 0.0 && along > BOUNDARY_OFFSET * spread
    });
    let across = eigenvectors.column(order[0]).into_owned();
    let boundary = on_edge
        .then(|| -(offset - across * offset.dot(&across)))
        .and_then(|out| out.try_normalize(1e-12));
    Surfel {
        position: Point3::from(mean),
        normal: reliable.then(|| {
            let n = eigenvectors.column(order[0]).normalize();
            if n.dot(ray) > 0.0 { -n } else { n }
        }),
        variance: sigma * sigma / n,
        fitted: n,
        boundary,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_flat_laser_patch_has_normals_and_a_noisy_one_does_not() {
        // A 4 cm square sampled every 2 mm on z = 0.5, seen from the origin.
        let grid: Vec<Point3<f64>> = (0..400)
            .map(|k| Point3::new((k % 20) as f64 * 0.002, (k / 20) as f64 * 0.002, 0.5))
            .collect();
        let mut cloud = PointCloud::from_points(grid.clone());
        cloud.origins = Some(vec![Point3::origin(); grid.len()]);
        let view = MapView::new(0, &cloud, &RangeNoise::constant(0.0005), 16).unwrap();
        assert!((view.spacing - 0.002).abs() < 1e-9);
        let with_normal = view.surfels.iter().filter(|s| s.normal.is_some()).count();
        assert_eq!(with_normal, 400);
        assert!(view.surfels.iter().all(|s| s.normal.unwrap().z < -0.999));

        assert!((view.rays[0] - Vector3::z()).norm() < 1e-12);
        // The square's rim is its boundary, its inside is not: every point of the outer
        // ring is flagged, no point three or more rows in is.
        for (k, s) in view.surfels.iter().enumerate() {
            let p = view.tree.points()[k];
            let (i, j) = (
                (p.x / 0.002).round() as usize,
                (p.y / 0.002).round() as usize,
            );
            let ring = i.min(j).min(19 - i).min(19 - j);
            if ring == 0 {
                let out = s.boundary.expect("rim point");
                // Outwards: away from the square's centre.
                let from_centre = view.tree.points()[k] - Point3::new(0.019, 0.019, 0.5);
                assert!(out.dot(&from_centre) > 0.0, "rim point {i},{j}");
            }
            if ring >= 3 {
                assert!(s.boundary.is_none(), "inner point {i},{j}");
            }
        }
        // The same patch with depth noise of about the neighbourhood's size (pseudo-random,
        // uniform in ±4 mm): the fit cannot pin the normal down.
        let noisy: Vec<_> = grid
            .iter()
            .enumerate()
            .map(|(k, p)| {
                let u = ((k as u64).wrapping_mul(2654435761) % 1000) as f64 / 1000.0;
                p + Vector3::z() * (u - 0.5) * 0.008
            })
            .collect();
        let mut cloud = PointCloud::from_points(noisy);
        cloud.origins = Some(vec![Point3::origin(); grid.len()]);
        let view = MapView::new(0, &cloud, &RangeNoise::constant(0.0023), 16).unwrap();
        let with_normal = view.surfels.iter().filter(|s| s.normal.is_some()).count();
        assert!(with_normal < 100, "{with_normal}"); // most are left point-to-point
        assert!((view.centre - Point3::origin()).norm() < 1e-12);
    }
}
