//! [`alignment_error`]: how far a registration leaves each view from where it belongs,
//! free of sensor noise — the rigid misalignment of every view, measured at its true
//! surface points.
//!
//! Each view, moved by its pose, is fitted to its `truth` column by rigid Procrustes over
//! all its points: the fit `E` is the view's residual misalignment (the noise, zero-mean
//! along the rays, averages out over thousands of points). The error of a point is
//! `|E⁻¹·t − t|`, how far the misalignment displaces the true point `t`. The point error
//! ([`point_error`](super::point_error)) adds the sensor noise on top; with the Dinast's
//! centimetre noise it cannot show what registration changed, this measure can.

use super::PointError;
use crate::cloud::PointCloud;
use crate::math::Pose;
use crate::registration::rigid_procrustes;

/// Mean and standard deviation over every true point of every view (views without a truth
/// column, or too few points to fit, are skipped). `poses` pairs with `views`.
///
/// ```
/// use nbv_core::cloud::PointCloud;
/// use nbv_core::evaluation::alignment_error;
/// use nalgebra::{Isometry3, Point3, Vector3};
/// let truth = vec![Point3::new(0.0, 0.0, 0.0), Point3::new(0.1, 0.0, 0.0),
///                  Point3::new(0.0, 0.1, 0.0), Point3::new(0.0, 0.0, 0.1)];
/// // A view acquired 5 mm off along x: the registration that moves it back scores 0.
/// let mut v = PointCloud::from_points(truth.iter().map(|p| p + Vector3::x() * 0.005).collect());
/// v.truth = Some(truth);
/// let fixed = alignment_error(&[v.clone()], &[Isometry3::translation(-0.005, 0.0, 0.0)]);
/// assert!(fixed.mean < 1e-12 && fixed.points == 4);
/// let left = alignment_error(&[v], &[Isometry3::identity()]);
/// assert!((left.mean - 0.005).abs() < 1e-12);
/// ```
pub fn alignment_error(views: &[PointCloud], poses: &[Pose]) -> PointError {
    let mut distances = Vec::new();
    for (view, pose) in views.iter().zip(poses) {
        let Some(truth) = &view.truth else { continue };
        let moved: Vec<_> = view.points.iter().map(|p| pose * p).collect();
        let Ok(fit) = rigid_procrustes(&moved, truth) else {
            continue;
        };
        let back = fit.inverse();
        distances.extend(truth.iter().map(|t| (back * t - t).norm()));
    }
    PointError::from_distances(&distances)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Isometry3, Point3, Vector3};

    /// Noise that averages out does not count; a rotation about the view's centroid does.
    #[test]
    fn noise_free_and_rotation_sensitive() {
        let truth: Vec<Point3<f64>> = (0..1000)
            .map(|k| {
                let (a, b) = (k as f64 * 0.37, k as f64 * 0.11);
                Point3::new(0.1 * a.cos(), 0.1 * a.sin(), 0.05 * b.sin())
            })
            .collect();
        // ±3 mm alternating noise along z.
        let noisy: Vec<_> = truth
            .iter()
            .enumerate()
            .map(|(k, p)| p + Vector3::z() * if k % 2 == 0 { 0.003 } else { -0.003 })
            .collect();
        let mut v = PointCloud::from_points(noisy);
        v.truth = Some(truth);
        let e = alignment_error(&[v.clone()], &[Isometry3::identity()]);
        assert!(e.mean < 2e-4, "{}", e.mean);
        // 1° about z through the origin: points at 0.1 m move 1.75 mm.
        let r = Isometry3::rotation(Vector3::z() * 1f64.to_radians());
        let e = alignment_error(&[v], &[r]);
        assert!(
            (e.mean - 0.1 * 1f64.to_radians()).abs() < 3e-4,
            "{}",
            e.mean
        );
    }
}
