//! [`TableFilter`]: takes the table out of a short-range view — every point whose range is
//! explained by the table plane within the sensor's range noise, unless it stands in the
//! object's footprint.
//!
//! A point `p` seen from `o` lies on the ray `o + r·u`. If that ray meets the table plane
//! at range `t`, the point is explained by the table when `r ≥ t − k·σ(t)`: it is on the
//! table within `k` standard deviations of the range noise `σ(d) = σ₁·d^e`, or beneath it.
//! An object's point at height `h` above the table lies `h / |n·u|` before the plane along
//! its ray, so the ray test alone keeps it only once `h > k·σ·|n·u|`: at a ToF camera's
//! noise that is the lowest centimetre of every object. A fixed height band above the
//! plane would instead keep the table's noisiest points or cut the object's lower part from
//! every view.
//!
//! The footprint rule gives the foot back: the view's own points that the ray test keeps
//! and that lie low above the table (up to `foot_height` above their ray's cut) trace the
//! object's walls where they meet the table; a point explained by the table is still the object's when its
//! projection onto the plane falls within `foot_radius` of theirs. Only footprint points
//! with a few others around them count, so the table's own noise that passes the ray test
//! restores nothing. Table points away from the object (and under an overhang higher than
//! `foot_height`) still go.

use crate::cloud::{PlaneFit, PointCloud, near_mask, neighbour_counts};
use nalgebra::Point3;

/// Other footprint points a footprint point needs within the footprint radius to count.
const FOOT_SUPPORT: usize = 3;

/// Range-noise model, rejection threshold and footprint rule of [`TableFilter::remove`].
///
/// ```
/// use nbv_core::cloud::{PlaneFit, PointCloud};
/// use nbv_core::perception::TableFilter;
/// use nalgebra::{Point3, Unit, Vector3};
/// // The table z = 0.25, seen from 0.3 m straight above; σ = 0.04 m at 1 m, so 12 mm here.
/// let table = PlaneFit { normal: Unit::new_normalize(Vector3::z()), offset: -0.25, inliers: vec![], rms: 0.0 };
/// let f = TableFilter { sigma_at_1m: 0.04, exponent: 1.0, k: 2.5, foot_height: 0.0, foot_radius: 0.0 };
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
    /// Standard deviations within which a point is explained by the table.
    pub k: f64,
    /// Height (m) above the ray test's cut (`k·σ·|n·u|` above the table) up to which kept
    /// points mark the object's footprint (0: no footprint rule).
    pub foot_height: f64,
    /// Distance along the table (m) from a footprint point within which a point explained
    /// by the table is the object's.
    pub foot_radius: f64,
}

impl TableFilter {
    /// Standard deviations of the camera's range noise within which a short-range point is
    /// the table's: 2.5σ keeps 99 % of the table out.
    pub const SIGMAS: f64 = 2.5;
    /// Height (m) of the band above the cut in which a view's points mark an object's
    /// footprint: low enough to stay under the horse's belly from steep views.
    pub const FOOT_HEIGHT: f64 = 0.02;
    /// Distance (m) along the table from the footprint within which a point explained by
    /// the table is kept as the object's foot: about the averaged range noise of a view.
    pub const FOOT_RADIUS: f64 = 0.006;

    /// The pipeline's filter for a camera whose averaged range noise is
    /// `σ(d) = sigma_at_1m · d^exponent`: [`SIGMAS`](Self::SIGMAS),
    /// [`FOOT_HEIGHT`](Self::FOOT_HEIGHT), [`FOOT_RADIUS`](Self::FOOT_RADIUS).
    ///
    /// ```
    /// let f = nbv_core::perception::TableFilter::for_camera(0.04 / 8f64.sqrt(), 1.0);
    /// assert_eq!((f.k, f.foot_height, f.foot_radius), (2.5, 0.02, 0.006));
    /// ```
    pub fn for_camera(sigma_at_1m: f64, exponent: f64) -> Self {
        Self {
            sigma_at_1m,
            exponent,
            k: Self::SIGMAS,
            foot_height: Self::FOOT_HEIGHT,
            foot_radius: Self::FOOT_RADIUS,
        }
    }

    /// Whether the point `p`, seen from `origin`, is explained by the table `plane`.
    pub fn is_table(&self, plane: &PlaneFit, origin: &Point3<f64>, p: &Point3<f64>) -> bool {
        self.ray_test(plane, origin, p).0
    }

    /// Whether `p` is explained by the table, and the height above the table below which
    /// points on its ray are (`k·σ·|n·u|`; 0 for a ray that does not go down).
    fn ray_test(&self, plane: &PlaneFit, origin: &Point3<f64>, p: &Point3<f64>) -> (bool, f64) {
        let ray = p - origin;
        let r = ray.norm();
        let n = plane.normal.into_inner();
        let towards = n.dot(&ray);
        if r.is_nan() || r <= 0.0 || towards >= 0.0 {
            // A ray that does not go down onto the plane cannot see the table (a point
            // beneath it from below would still be rejected by the signed distance).
            return (plane.signed_distance(p) < 0.0, 0.0);
        }
        let height = n.dot(&origin.coords) + plane.offset;
        let t = height * r / -towards;
        let margin = self.k * self.sigma_at_1m * t.max(0.0).powf(self.exponent);
        (r >= t - margin, margin * -towards / r)
    }

    /// The points of `cloud` that are not the table's (all columns): those the ray test
    /// keeps, and those it explains by the table that stand in the footprint of the
    /// former. A cloud without ray origins is returned whole.
    pub fn remove(&self, plane: &PlaneFit, cloud: &PointCloud) -> PointCloud {
        let keep = self.kept(plane, cloud);
        cloud.retain_indices(|i| keep[i])
    }

    /// Which points of `cloud` [`remove`](Self::remove) keeps, in cloud order (all of
    /// them without ray origins): for deciding on one cloud (a view smoothed) and cutting
    /// another of the same pixels (the view as acquired).
    pub fn kept(&self, plane: &PlaneFit, cloud: &PointCloud) -> Vec<bool> {
        let Some(origins) = cloud.origins.as_deref() else {
            return vec![true; cloud.len()];
        };
        let tests: Vec<(bool, f64)> = (0..cloud.len())
            .map(|i| self.ray_test(plane, &origins[i], &cloud.points[i]))
            .collect();
        let mut keep: Vec<bool> = tests.iter().map(|&(table, _)| !table).collect();
        if self.foot_height > 0.0 {
            let on_plane =
                |p: &Point3<f64>| p - plane.normal.into_inner() * plane.signed_distance(p);
            let band: Vec<Point3<f64>> = cloud
                .points
                .iter()
                .zip(&tests)
                .filter(|&(p, &(t, cut))| !t && plane.signed_distance(p) <= cut + self.foot_height)
                .map(|(p, _)| on_plane(p))
                .collect();
            // A wall's foot is dense in projection; the table's noise tail that passes the
            // ray test is scattered and seeds nothing.
            let footprint: Vec<Point3<f64>> = neighbour_counts(&band, self.foot_radius)
                .into_iter()
                .zip(band)
                .filter(|&(n, _)| n >= FOOT_SUPPORT)
                .map(|(_, p)| p)
                .collect();
            let explained: Vec<usize> = (0..cloud.len()).filter(|&i| !keep[i]).collect();
            let queries: Vec<Point3<f64>> = explained
                .iter()
                .map(|&i| on_plane(&cloud.points[i]))
                .collect();
            for (i, near) in
                explained
                    .into_iter()
                    .zip(near_mask(&footprint, &queries, self.foot_radius))
            {
                keep[i] = near;
            }
        }
        keep
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
        foot_height: 0.03,
        foot_radius: 0.006,
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

    proptest! {
        /// A wall standing on the table, seen from above in front of it: every wall point
        /// stays, down to the table (its foot by the footprint rule), and every table point
        /// farther from the wall than the footprint radius goes.
        #[test]
        fn the_foot_of_a_wall_stays_and_the_table_before_it_goes(
            ox in -0.3..0.0f64, oy in -0.2..0.2f64, oz in 0.45..0.9f64,
            wall in 0.15..0.35f64,
        ) {
            let plane = table(0.25);
            let o = Point3::new(ox, oy, oz);
            let mut points = Vec::new();
            let mut is_wall = Vec::new();
            for j in 0..40 {
                let y = -0.1 + 0.005 * f64::from(j);
                for i in 0..40 {
                    // The wall x = `wall` facing the camera, 1 mm to 12 cm above the table.
                    points.push(Point3::new(wall, y, 0.251 + 0.003 * f64::from(i)));
                    is_wall.push(true);
                    // The table in front of it, up to 1 mm short of the wall.
                    points.push(Point3::new(wall - 0.001 - 0.004 * f64::from(i), y, 0.25));
                    is_wall.push(false);
                }
            }
            let mut view = PointCloud::from_points(points.clone());
            view.origins = Some(vec![o; points.len()]);
            let kept = FILTER.remove(&plane, &view);
            for (p, &w) in points.iter().zip(&is_wall) {
                let stays = kept.points.contains(p);
                if w {
                    prop_assert!(stays, "wall point {p} went");
                } else if wall - p.x > FILTER.foot_radius {
                    prop_assert!(!stays, "table point {p} stayed");
                }
            }
        }
    }

    #[test]
    fn without_a_footprint_the_foot_goes_with_the_table() {
        let plane = table(0.25);
        let o = Point3::new(0.0, 0.0, 0.7);
        // 3 mm above the table; at 0.49 m the ray test explains up to 4.5 cm by the table.
        let foot = Point3::new(0.2, 0.0, 0.253);
        let mut view = PointCloud::from_points(vec![foot]);
        view.origins = Some(vec![o]);
        assert!(FILTER.remove(&plane, &view).is_empty());
        // A lone point above it (the table's noise, say) does not make it a foot ...
        let wall = |n: u32| (0..n).map(|i| Point3::new(0.2, 0.0, 0.305 + 0.002 * f64::from(i)));
        let mut view = PointCloud::from_points(std::iter::once(foot).chain(wall(1)).collect());
        view.origins = Some(vec![o; 2]);
        assert_eq!(FILTER.remove(&plane, &view).len(), 1);
        // ... a wall above it does.
        let mut view = PointCloud::from_points(std::iter::once(foot).chain(wall(4)).collect());
        view.origins = Some(vec![o; 5]);
        assert_eq!(FILTER.remove(&plane, &view).len(), 5);
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
