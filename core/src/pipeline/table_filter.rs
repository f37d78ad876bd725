//! [`TableFilter`]: takes the table out of a short-range view — every point whose range is
//! explained by the table plane within the sensor's range noise.
//!
//! A point `p` seen from `o` lies on the ray `o + r·u`. If that ray meets the table plane
//! at range `t`, the point is the table's when `r ≥ t − k·σ(t)`: it is on the table within
//! `k` standard deviations of the range noise `σ(d) = σ₁·d^e`, or beneath it. An object's
//! point at height `h` above the table lies `h / |n·u|` before the plane along its ray, so
//! it is kept once `h > k·σ·|n·u|`: more of an object's foot stays from low, grazing views
//! than from steep ones. A fixed height band above the plane would instead keep the
//! table's noisiest points (a ToF camera at 0.3 m scatters them by a centimetre) or cut
//! the object's lower part from every view.

use crate::cloud::{PlaneFit, PointCloud};
use nalgebra::Point3;

/// Range-noise model and rejection threshold of [`TableFilter::remove`].
///
/// ```
/// use nbv_core::cloud::{PlaneFit, PointCloud};
/// use nbv_core::pipeline::TableFilter;
/// use nalgebra::{Point3, Unit, Vector3};
/// // The table z = 0.25, seen from 0.3 m straight above; σ = 0.04 m at 1 m, so 12 mm here.
/// let table = PlaneFit { normal: Unit::new_normalize(Vector3::z()), offset: -0.25, inliers: vec![], rms: 0.0 };
/// let f = TableFilter { sigma_at_1m: 0.04, exponent: 1.0, k: 2.5 };
/// let o = Point3::new(0.0, 0.0, 0.55);
/// let mut view = PointCloud::from_points(vec![
///     Point3::new(0.0, 0.0, 0.27),  // the table, 2 cm off by noise (< 2.5σ = 3 cm)
///     Point3::new(0.0, 0.0, 0.24),  // the table, beneath the plane by noise
///     Point3::new(0.0, 0.0, 0.30),  // an object 5 cm above the table
/// ]);
/// view.origins = Some(vec![o; 3]);
/// let kept = f.remove(&table, &view);
/// assert_eq!(kept.points, vec![Point3::new(0.0, 0.0, 0.30)]);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TableFilter {
    /// Range noise (one standard deviation, m) at 1 m.
    pub sigma_at_1m: f64,
    /// Exponent of the range: `σ(d) = sigma_at_1m · d^exponent`.
    pub exponent: f64,
    /// Standard deviations within which a point is the table's.
    pub k: f64,
}

impl TableFilter {
    /// Whether the point `p`, seen from `origin`, is explained by the table `plane`.
    pub fn is_table(&self, plane: &PlaneFit, origin: &Point3<f64>, p: &Point3<f64>) -> bool {
        let ray = p - origin;
        let r = ray.norm();
        let n = plane.normal.into_inner();
        let towards = n.dot(&ray);
        if r.is_nan() || r <= 0.0 || towards >= 0.0 {
            // A ray that does not go down onto the plane cannot see the table (a point
            // beneath it from below would still be rejected by the signed distance).
            return plane.signed_distance(p) < 0.0;
        }
        let height = n.dot(&origin.coords) + plane.offset;
        let t = height * r / -towards;
        let sigma = self.sigma_at_1m * t.max(0.0).powf(self.exponent);
        r >= t - self.k * sigma
    }

    /// The points of `cloud` that are not the table's (all columns). A cloud without ray
    /// origins is returned whole.
    pub fn remove(&self, plane: &PlaneFit, cloud: &PointCloud) -> PointCloud {
        let Some(origins) = cloud.origins.as_deref() else {
            return cloud.clone();
        };
        cloud.retain_indices(|i| !self.is_table(plane, &origins[i], &cloud.points[i]))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Unit, Vector3};
    use proptest::prelude::*;

    fn table(z: f64) -> PlaneFit {
        PlaneFit {
            normal: Unit::new_normalize(Vector3::z()),
            offset: -z,
            inliers: Vec::new(),
            rms: 0.0,
        }
    }

    const FILTER: TableFilter = TableFilter {
        sigma_at_1m: 0.04,
        exponent: 1.0,
        k: 2.5,
    };

    proptest! {
        /// From any viewpoint above the table looking down, a point on the table or beneath
        /// it is the table's, and a point higher than k·σ·|n·u| above it is not.
        #[test]
        fn table_points_go_and_points_clear_of_the_noise_stay(
            ox in -0.3..0.3f64, oy in -0.3..0.3f64, oz in 0.35..0.9f64,
            px in -0.2..0.2f64, py in -0.2..0.2f64, below in 0.0..0.05f64,
            extra in 0.001..0.1f64,
        ) {
            let plane = table(0.25);
            let o = Point3::new(ox, oy, oz);
            let foot = Point3::new(px, py, 0.25);
            let u = (foot - o).normalize();
            let t = (foot - o).norm();
            prop_assert!(FILTER.is_table(&plane, &o, &foot));
            prop_assert!(FILTER.is_table(&plane, &o, &(o + u * (t + below))));
            // A point on the same ray, `h` above the table.
            let margin = FILTER.k * FILTER.sigma_at_1m * t * u.z.abs();
            let h = margin + extra;
            let p = o + u * (t - h / u.z.abs());
            prop_assert!(!FILTER.is_table(&plane, &o, &p), "h {h} margin {margin}");
        }
    }

    #[test]
    fn rays_that_do_not_go_down_keep_what_is_above_the_table() {
        let plane = table(0.25);
        let o = Point3::new(0.0, 0.0, 0.3);
        assert!(!FILTER.is_table(&plane, &o, &Point3::new(0.3, 0.0, 0.3)));
        assert!(!FILTER.is_table(&plane, &o, &Point3::new(0.3, 0.0, 0.4)));
        assert!(FILTER.is_table(
            &plane,
            &Point3::new(0.0, 0.0, 0.1),
            &Point3::new(0.0, 0.0, 0.2)
        ));
    }
}
