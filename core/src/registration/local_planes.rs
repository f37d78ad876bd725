//! [`sampled_local_planes`]: the best-fit plane of the `k` nearest neighbours around an even
//! sample of a view's points, the one neighbourhood analysis the estimates of views that
//! come without a sensor model share (their range noise, their viewing direction).

use kiddo::{ImmutableKdTree, SquaredEuclidean};
use nalgebra::{Matrix3, Point3, Vector3};

use crate::cloud::PointCloud;
use crate::math::symmetric_eigen3;

/// Neighbours of each sampled point's plane.
pub const NOISE_NEIGHBOURS: usize = 16;

/// One sampled point's neighbourhood.
#[derive(Debug, Clone, Copy)]
pub(crate) struct LocalPlane {
    /// The sampled point.
    pub point: Point3<f64>,
    /// The unit normal of its neighbours' plane (either sign).
    pub normal: Vector3<f64>,
    /// The smallest eigenvalue of its neighbours' covariance (m²): their spread across
    /// the plane.
    pub spread: f64,
}

/// The planes of [`NOISE_NEIGHBOURS`] neighbours around about `samples` evenly spaced
/// finite points of `view`; `None` with fewer than twice that many finite points.
pub(crate) fn sampled_local_planes(view: &PointCloud, samples: usize) -> Option<Vec<LocalPlane>> {
    let points: Vec<[f64; 3]> = view
        .points
        .iter()
        .filter(|p| p.iter().all(|c| c.is_finite()))
        .map(|p| [p.x, p.y, p.z])
        .collect();
    if points.len() < NOISE_NEIGHBOURS * 2 {
        return None;
    }
    let tree = ImmutableKdTree::<f64, 3>::builder()
        .build_from_slice(&points)
        .ok()?;
    let k = std::num::NonZeroUsize::new(NOISE_NEIGHBOURS)?;
    let step = points.len().div_ceil(samples.max(1)).max(1);
    let planes = points
        .iter()
        .step_by(step)
        .filter_map(|p| {
            let near = tree
                .query(p)
                .nearest_n::<SquaredEuclidean<f64>>(k)
                .execute();
            let mean = near
                .iter()
                .map(|n| Vector3::from(points[n.item as usize]))
                .sum::<Vector3<f64>>()
                / near.len() as f64;
            let cov = near
                .iter()
                .map(|n| {
                    let d = Vector3::from(points[n.item as usize]) - mean;
                    d * d.transpose()
                })
                .sum::<Matrix3<f64>>()
                / near.len() as f64;
            let (values, vectors) = symmetric_eigen3(&cov);
            let i = values.imin();
            let normal = vectors.column(i).normalize();
            let spread = values[i];
            (spread.is_finite() && normal.iter().all(|c| c.is_finite())).then(|| LocalPlane {
                point: Point3::from(*p),
                normal,
                spread: spread.max(0.0),
            })
        })
        .collect();
    Some(planes)
}
