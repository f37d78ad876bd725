//! [`point_error`]: distances between registered points and the noise-free surface points
//! they sampled (the cloud's `truth` column).

use crate::cloud::PointCloud;
use crate::math::Pose;

/// Mean and standard deviation of point errors (m) over `points` points.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct PointError {
    /// Mean distance.
    pub mean: f64,
    /// Standard deviation of the distance.
    pub std: f64,
    /// Points measured.
    pub points: usize,
}

impl PointError {
    /// Mean and (population) standard deviation of `distances`; all zero when empty.
    pub fn from_distances(distances: &[f64]) -> Self {
        let n = distances.len();
        if n == 0 {
            return Self::default();
        }
        let mean = distances.iter().sum::<f64>() / n as f64;
        let var = distances.iter().map(|d| (d - mean).powi(2)).sum::<f64>() / n as f64;
        Self {
            mean,
            std: var.sqrt(),
            points: n,
        }
    }
}

/// The error of every point of every view moved by its pose against its `truth` point;
/// views without a truth column are skipped. `poses` pairs with `views`.
///
/// ```
/// use nbv_core::cloud::PointCloud;
/// use nbv_core::evaluation::point_error;
/// use nalgebra::{Isometry3, Point3};
/// let mut v = PointCloud::from_points(vec![Point3::new(0.0, 0.0, 0.0), Point3::new(1.0, 0.0, 0.0)]);
/// v.truth = Some(v.points.clone());
/// let e = point_error(&[v], &[Isometry3::translation(0.0, 0.003, 0.0)]);
/// assert!((e.mean - 0.003).abs() < 1e-12 && e.std < 1e-12 && e.points == 2);
/// ```
pub fn point_error(views: &[PointCloud], poses: &[Pose]) -> PointError {
    let mut distances = Vec::new();
    for (view, pose) in views.iter().zip(poses) {
        let Some(truth) = &view.truth else { continue };
        distances.extend(
            view.points
                .iter()
                .zip(truth)
                .map(|(p, t)| (pose * p - t).norm()),
        );
    }
    PointError::from_distances(&distances)
}
