//! Surface normals by PCA of the k nearest neighbours: the eigenvector of the smallest
//! eigenvalue of the neighbourhood covariance, oriented towards the sensor (the point's
//! `origins` entry if the cloud has one, else the cloud frame's origin, which is the
//! sensor for a view kept in its own frame). Point-to-plane ICP uses them on its target.

use std::num::NonZeroUsize;

use nalgebra::{Matrix3, Point3, Vector3};
use rayon::prelude::*;

use super::RegistrationError;
use super::view_tree::check_view;
use crate::cloud::{KNearest, PointCloud};

/// Points per parallel work item.
const CHUNK: usize = 256;

/// Unit normal per point of `cloud`, from its `k` nearest neighbours (the point included).
///
/// ```
/// use nbv_core::cloud::PointCloud;
/// use nbv_core::registration::estimate_normals;
/// use nalgebra::Point3;
/// // A grid on the plane z = 1, seen from the origin: normals point down, towards it.
/// let pts = (0..25).map(|i| Point3::new((i % 5) as f64, (i / 5) as f64, 1.0)).collect();
/// let n = estimate_normals(&PointCloud::from_points(pts), 8).unwrap();
/// assert!(n.iter().all(|v| (v.z + 1.0).abs() < 1e-9));
/// ```
pub fn estimate_normals(
    cloud: &PointCloud,
    k: usize,
) -> Result<Vec<Vector3<f64>>, RegistrationError> {
    let k = NonZeroUsize::new(k).filter(|k| k.get() >= 3).ok_or(
        RegistrationError::InvalidParameter {
            name: "normal_neighbours",
            value: k as f64,
            reason: "must be at least 3",
        },
    )?;
    check_view(0, cloud)?;
    normals_of(0, &cloud.points, cloud.origins.as_deref(), k)
}

/// Normals of the points of view `view` (checked; see [`estimate_normals`]).
pub(crate) fn normals_of(
    view: usize,
    points: &[Point3<f64>],
    origins: Option<&[Point3<f64>]>,
    k: NonZeroUsize,
) -> Result<Vec<Vector3<f64>>, RegistrationError> {
    let nearest = KNearest::of_each(points, k).map_err(|e| RegistrationError::KdTree {
        view,
        message: e.to_string(),
    })?;
    let chunks: Vec<Vec<Vector3<f64>>> = (0..points.len().div_ceil(CHUNK))
        .into_par_iter()
        .map(|c| {
            (c * CHUNK..((c + 1) * CHUNK).min(points.len()))
                .map(|i| {
                    let neighbours = nearest.of(i);
                    let n = pca_normal(neighbours.iter().map(|&(j, _)| points[j as usize]));
                    let sensor = origins.map_or(Point3::origin(), |o| o[i]);
                    if n.dot(&(sensor - points[i])) < 0.0 {
                        -n
                    } else {
                        n
                    }
                })
                .collect()
        })
        .collect();
    Ok(chunks.concat())
}

/// Direction of least spread of a set of points.
fn pca_normal(points: impl Iterator<Item = Point3<f64>> + Clone) -> Vector3<f64> {
    let (sum, n) = points
        .clone()
        .fold((Vector3::zeros(), 0usize), |(s, n), p| {
            (s + p.coords, n + 1)
        });
    let mean = sum / n.max(1) as f64;
    let cov = points.fold(Matrix3::zeros(), |c, p| {
        let d = p.coords - mean;
        c + d * d.transpose()
    });
    let eig = cov.symmetric_eigen();
    let smallest = eig.eigenvalues.imin();
    eig.eigenvectors.column(smallest).normalize()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sphere_normals_are_radial() {
        // Fibonacci points on a unit sphere centred at (0, 0, 3); sensor at the origin.
        let n = 2000;
        let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
        let pts: Vec<_> = (0..n)
            .map(|i| {
                let z = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
                let r = (1.0 - z * z).sqrt();
                let a = golden * i as f64;
                Point3::new(r * a.cos(), r * a.sin(), z + 3.0)
            })
            .collect();
        let normals = estimate_normals(&PointCloud::from_points(pts.clone()), 10).unwrap();
        for (p, nrm) in pts.iter().zip(&normals) {
            let radial = (p - Point3::new(0.0, 0.0, 3.0)).normalize();
            assert!(nrm.dot(&radial).abs() > 0.995, "{nrm} vs {radial}");
            assert!((nrm.norm() - 1.0).abs() < 1e-12);
        }
        // Every normal faces the sensor at the origin.
        for (p, nrm) in pts.iter().zip(&normals) {
            assert!(nrm.dot(&(Point3::origin() - p)) >= 0.0);
        }
    }

    #[test]
    fn rejects_small_k_and_bad_clouds() {
        let c = PointCloud::from_points(vec![Point3::origin(); 4]);
        assert!(matches!(
            estimate_normals(&c, 2),
            Err(RegistrationError::InvalidParameter { .. })
        ));
        assert_eq!(
            estimate_normals(&PointCloud::default(), 5),
            Err(RegistrationError::EmptyView(0))
        );
        // Fewer points than k, all coincident: still finite unit vectors, no panic.
        let n = estimate_normals(&c, 10).unwrap();
        assert!(n.iter().all(|v| v.iter().all(|c| c.is_finite())));
    }
}
