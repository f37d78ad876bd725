//! [`ObjectRegion`]: where an object is for phase 2 — which points of a short-range view
//! belong to it (those inside its phase-1 bounding box grown by a margin, and above the
//! table; the box grows where the views see the object go on past it) and where the
//! centre of its viewing sphere lies.

use crate::cloud::{
    Cluster, EuclideanClustering, PlaneFit, PlaneRansac, PointCloud, ProcessingError,
};
use crate::perception::{ObjectSegmentation, TableFilter};
use nalgebra::{Point3, Vector3};

/// An axis-aligned region around an object, and the table it rests on.
///
/// ```
/// use nbv_core::pipeline::ObjectRegion;
/// use nbv_core::cloud::PointCloud;
/// use nalgebra::Point3;
/// // The laser saw the object from 0.30 m to 0.40 m; the table top is at 0.25 m.
/// let r = ObjectRegion::around(Point3::new(0.0, 0.0, 0.30), Point3::new(0.1, 0.1, 0.4), 0.05, Some(0.25));
/// let c = PointCloud::from_points(vec![
///     Point3::new(0.05, 0.05, 0.35), // on the object
///     Point3::new(0.05, 0.05, 0.27), // its lower part, which the laser did not see
///     Point3::new(0.05, 0.05, 0.25), // the table under it
///     Point3::new(0.5, 0.0, 0.3),    // elsewhere
/// ]);
/// assert_eq!(r.crop(&c).len(), 2);
/// // The viewing sphere is centred half-way between the table and the top.
/// assert!((r.viewing_centre(&Point3::new(0.05, 0.05, 0.38)).z - 0.325).abs() < 1e-12);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ObjectRegion {
    /// Lower corner.
    pub min: Point3<f64>,
    /// Upper corner.
    pub max: Point3<f64>,
    /// Height of the table top under the object, if a table was found.
    pub table: Option<f64>,
    /// Height of the object's top as phase 1 saw it.
    pub top: f64,
}

impl ObjectRegion {
    /// The margin (m) the pipeline grows each object's phase-1 bounding box by
    /// ([`ExploreConfig::object_margin`](super::ExploreConfig::object_margin)).
    pub const MARGIN: f64 = 0.03;

    /// The box `[min − margin, max + margin]` whose top is raised by the full margin plus
    /// half the object's height (the laser may not have seen its top) and whose floor is
    /// the `table` top + margin/5 (so that table points stay out) when a table was found:
    /// the object rests on it, so the region reaches down to it even where the laser saw
    /// only the object's upper part (a horse's body, not its legs).
    pub fn around(min: Point3<f64>, max: Point3<f64>, margin: f64, table: Option<f64>) -> Self {
        let height = max.z - min.z;
        let bottom = table.map_or(min.z - margin, |t| t + margin / 5.0);
        Self {
            min: Point3::new(min.x - margin, min.y - margin, bottom),
            max: Point3::new(
                max.x + margin,
                max.y + margin,
                max.z + margin + height / 2.0,
            ),
            table,
            top: max.z,
        }
    }

    /// The region of a phase-1 cluster, over the segmented `table` plane (if it is
    /// near-horizontal) evaluated under the cluster's centroid.
    pub fn of_cluster(cluster: &Cluster, table: Option<&PlaneFit>, margin: f64) -> Self {
        let c = cluster.centroid;
        let table = table
            .filter(|t| t.normal.z > 0.5)
            .map(|t| -(t.offset + t.normal.x * c.x + t.normal.y * c.y) / t.normal.z);
        Self::around(cluster.min, cluster.max, margin, table)
    }

    /// The region of every cluster of a phase-1 `segmentation`, in cluster order
    /// ([`of_cluster`](Self::of_cluster) over its table).
    pub fn of_segmentation(segmentation: &ObjectSegmentation, margin: f64) -> Vec<Self> {
        segmentation
            .clusters
            .iter()
            .map(|c| Self::of_cluster(c, segmentation.table.as_ref(), margin))
            .collect()
    }

    /// The centre of the viewing sphere (Algorithm 2, line 1) for the `centroid` of the
    /// object's points seen so far: that centroid, at the middle height between the table
    /// and the object's top when the object rests on a table. The points seen are biased
    /// to the top and the front (the laser looks down from the front), and a sphere
    /// centred on them would look down on the lower sides only steeply.
    pub fn viewing_centre(&self, centroid: &Point3<f64>) -> Point3<f64> {
        match self.table {
            Some(t) => Point3::new(centroid.x, centroid.y, (t + self.top) / 2.0),
            None => *centroid,
        }
    }

    /// Whether `p` lies in the region.
    pub fn contains(&self, p: &Point3<f64>) -> bool {
        (0..3).all(|k| p[k] >= self.min[k] && p[k] <= self.max[k])
    }

    /// Whether `p` lies over or under the region's footprint (its extent along x and y,
    /// at any height).
    ///
    /// ```
    /// use nbv_core::pipeline::ObjectRegion;
    /// use nalgebra::Point3;
    /// let r = ObjectRegion::around(Point3::new(0.0, 0.0, 0.3), Point3::new(0.1, 0.1, 0.4), 0.0, Some(0.25));
    /// let below = Point3::new(0.05, 0.05, 0.2);
    /// assert!(r.covers(&below) && !r.contains(&below));
    /// assert!(!r.covers(&Point3::new(0.15, 0.05, 0.25)));
    /// ```
    pub fn covers(&self, p: &Point3<f64>) -> bool {
        (0..2).all(|k| p[k] >= self.min[k] && p[k] <= self.max[k])
    }

    /// The points of `cloud` in the region (all columns).
    pub fn crop(&self, cloud: &PointCloud) -> PointCloud {
        cloud.retain_indices(|i| self.contains(&cloud.points[i]))
    }

    /// Height (m) above the table under which a view's points do not grow a region.
    pub const GROW_LIFT: f64 = 0.01;

    /// Standard deviations of the camera's range noise within which a view's point is its
    /// table's when it grows a region: at [`TableFilter::SIGMAS`] the noise tail left over
    /// on a wide stretch of table links into strips a few centimetres long.
    pub const GROW_SIGMAS: f64 = 4.0;

    /// Band (m) about the table's height in which a view's own table is fitted.
    pub const TABLE_BAND: f64 = 0.03;

    /// Fewest points outside the region a linked part needs to grow it: a stray return or
    /// two is no side of the object.
    const MIN_GROWTH_POINTS: usize = 10;

    /// Grows the region over what a view saw of the object past its sides or top. The
    /// laser sees an object from one side, and its phase-1 box can fall short of the far
    /// side by more than the margin (a box turned on the table: 5 cm); the crop then cuts
    /// that end off every view, and the grid around it counts as free.
    ///
    /// Of the `view`'s points (world frame, with their ray origins) within `reach` of the
    /// region and not `blocked` (another object's region, a known obstacle), those that
    /// are not the view's own table are kept: over [`view_table`](Self::view_table)
    /// (else the table), [`GROW_LIFT`] above it and, with a `table_filter`,
    /// clear of its ray test at [`GROW_SIGMAS`]. They are linked at `tolerance`
    /// ([`EuclideanClustering`]); each part with a point in the region and at least 10
    /// outside widens it to the part's bounds plus `margin`, and raises its top. Whether
    /// the region grew.
    ///
    /// ```
    /// use nbv_core::cloud::PointCloud;
    /// use nbv_core::pipeline::ObjectRegion;
    /// use nalgebra::Point3;
    /// // The laser saw 6 cm of a 12 cm long box standing on a table at 0.25 m.
    /// let mut r = ObjectRegion::around(Point3::new(0.0, 0.0, 0.26), Point3::new(0.06, 0.04, 0.3), 0.01, Some(0.25));
    /// // A view sees its whole side, points 5 mm apart, and a neighbour 4 cm further on...
    /// let mut seen: Vec<_> = (0..=24).map(|i| Point3::new(0.005 * i as f64, 0.0, 0.28)).collect();
    /// seen.extend((0..20).map(|i| Point3::new(0.16, 0.0, 0.27 + 0.001 * i as f64)));
    /// // ...and the table, tilted by its pose error: 2 cm higher 20 cm away.
    /// for i in 0..1600 {
    ///     let (x, y) = (-0.1 + 0.01 * (i % 40) as f64, -0.1 + 0.01 * (i / 40) as f64);
    ///     seen.push(Point3::new(x, y, 0.25 + 0.1 * x));
    /// }
    /// let view = PointCloud::from_points(seen);
    /// assert!(r.grow(&view, 0.015, 0.1, 0.01, None, |_| false)?);
    /// assert!((r.max.x - 0.13).abs() < 1e-9 && r.min.x == -0.01);
    /// assert!(r.contains(&view.points[24]) && !r.contains(&view.points[25]));
    /// # Ok::<(), nbv_core::cloud::ProcessingError>(())
    /// ```
    ///
    /// [`GROW_LIFT`]: Self::GROW_LIFT
    /// [`GROW_SIGMAS`]: Self::GROW_SIGMAS
    pub fn grow(
        &mut self,
        view: &PointCloud,
        tolerance: f64,
        reach: f64,
        margin: f64,
        table_filter: Option<&TableFilter>,
        blocked: impl Fn(&Point3<f64>) -> bool,
    ) -> Result<bool, ProcessingError> {
        let window = view.retain_indices(|i| {
            let p = &view.points[i];
            p.z >= self.min.z - Self::TABLE_BAND
                && p.z <= self.max.z + reach
                && (0..2).all(|k| p[k] >= self.min[k] - reach && p[k] <= self.max[k] + reach)
                && !blocked(p)
        });
        let level = |height: f64| PlaneFit {
            normal: Vector3::z_axis(),
            offset: -height,
            inliers: Vec::new(),
            rms: 0.0,
        };
        let table = self
            .view_table(&window.points, reach)
            .unwrap_or_else(|| level(self.table.unwrap_or(self.min.z - Self::GROW_LIFT)));
        let mut near =
            window.retain_indices(|i| table.signed_distance(&window.points[i]) > Self::GROW_LIFT);
        if let Some(filter) = table_filter {
            let strict = TableFilter {
                k: filter.k.max(Self::GROW_SIGMAS),
                foot_height: 0.0,
                ..*filter
            };
            near = strict.remove(&table, &near);
        }
        if near.is_empty() {
            return Ok(false);
        }
        let linked = EuclideanClustering {
            tolerance,
            min_size: 1,
            max_size: usize::MAX,
        };
        let before = *self;
        for part in linked.clusters(&near)? {
            let inside = part
                .indices
                .iter()
                .filter(|&&i| before.contains(&near.points[i]))
                .count();
            if inside == 0 || part.len() - inside < Self::MIN_GROWTH_POINTS {
                continue;
            }
            for k in 0..2 {
                self.min[k] = self.min[k].min(part.min[k] - margin);
                self.max[k] = self.max[k].max(part.max[k] + margin);
            }
            self.top = self.top.max(part.max.z);
            self.max.z = self.max.z.max(part.max.z + margin);
        }
        Ok(*self != before)
    }

    /// The table as a `view` (world frame, at its reported pose) sees it around the
    /// region: the plane fitted to its points within `reach` of the region but outside its
    /// footprint (a flat object's top would pass for the table) and within
    /// [`TABLE_BAND`](Self::TABLE_BAND) of the table's height, when it holds a third of
    /// them or more and is near-horizontal. The views' pose error tilts and lifts each
    /// view's table off phase 1's plane by up to a couple of centimetres, and a view that
    /// looks along the table then keeps a band of it as the object's. `None` without a
    /// table or such a plane.
    pub fn view_table(&self, view: &[Point3<f64>], reach: f64) -> Option<PlaneFit> {
        let table = self.table?;
        let band: Vec<Point3<f64>> = view
            .iter()
            .filter(|p| {
                (p.z - table).abs() <= Self::TABLE_BAND
                    && (0..2).all(|k| p[k] >= self.min[k] - reach && p[k] <= self.max[k] + reach)
                    && !self.covers(p)
            })
            .copied()
            .collect();
        if band.len() < 3 {
            return None;
        }
        let band = PointCloud::from_points(band);
        let ransac = PlaneRansac {
            distance_threshold: 0.004,
            iterations: 200,
            max_tilt: Some(0.2),
            seed: 0,
        };
        // No plane in degenerate points (all on a line).
        ransac
            .fit(&band)
            .ok()
            .filter(|fit| 3 * fit.inliers.len() >= band.len())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn without_a_table_the_region_hangs_below_the_cluster_and_the_centre_is_the_centroid() {
        let r = ObjectRegion::around(
            Point3::new(0.0, 0.0, 0.3),
            Point3::new(0.1, 0.1, 0.5),
            0.05,
            None,
        );
        assert!((r.min.z - 0.25).abs() < 1e-12);
        assert!((r.max.z - 0.65).abs() < 1e-12);
        let c = Point3::new(0.05, 0.05, 0.45);
        assert_eq!(r.viewing_centre(&c), c);
    }

    /// Grows `r` over `points` linked at 1.5 cm with a 1 cm margin, outside `blocked`.
    fn grow(
        r: &mut ObjectRegion,
        points: &[Point3<f64>],
        reach: f64,
        blocked: impl Fn(&Point3<f64>) -> bool,
    ) -> bool {
        r.grow(
            &PointCloud::from_points(points.to_vec()),
            0.015,
            reach,
            0.01,
            None,
            blocked,
        )
        .unwrap()
    }

    fn box_region() -> ObjectRegion {
        ObjectRegion::around(
            Point3::new(0.0, 0.0, 0.26),
            Point3::new(0.06, 0.04, 0.3),
            0.01,
            Some(0.25),
        )
    }

    /// A line of points 5 mm apart along x from `x0` to `x1` at height `z`.
    fn line(x0: f64, x1: f64, z: f64) -> Vec<Point3<f64>> {
        let n = ((x1 - x0) / 0.005).round() as usize;
        (0..=n)
            .map(|i| Point3::new(x0 + 0.005 * i as f64, 0.02, z))
            .collect()
    }

    /// The table at 0.25 m seen 1 cm apart from x = −0.1 to 0.3, `rise` higher per metre
    /// along x (a view's pose error), with ±2 mm of alternating noise.
    fn table(rise: f64) -> Vec<Point3<f64>> {
        (0..40 * 20)
            .map(|i| {
                let (x, y) = (
                    -0.1 + 0.01 * (i % 40) as f64,
                    -0.05 + 0.01 * (i / 40) as f64,
                );
                let noise = if i % 2 == 0 { 0.002 } else { -0.002 };
                Point3::new(x, y, 0.25 + rise * x + noise)
            })
            .collect()
    }

    #[test]
    fn the_table_and_blocked_space_do_not_grow_a_region() {
        // A tilted, noisy table around the object: up to 3.2 cm above its height.
        let mut r = box_region();
        let mut seen = line(0.0, 0.06, 0.28);
        seen.extend(table(0.1));
        assert!(!grow(&mut r, &seen, 0.1, |_| false));
        assert_eq!(r, box_region());
        // The object's points going on past the box, but into another object's region.
        let other = ObjectRegion::around(
            Point3::new(0.065, 0.0, 0.26),
            Point3::new(0.2, 0.04, 0.3),
            0.0,
            Some(0.25),
        );
        let seen = line(0.0, 0.2, 0.28);
        assert!(!grow(&mut r, &seen, 0.1, |p| other.contains(p)));
        // Unblocked, it grows by at most the reach per call.
        assert!(grow(&mut r, &seen, 0.06, |_| false));
        assert!((r.max.x - (0.07 + 0.06 + 0.01)).abs() < 1e-9);
        assert!(grow(&mut r, &seen, 0.06, |_| false));
        assert!((r.max.x - 0.21).abs() < 1e-9);
        // Fewer than ten points past it are strays.
        let mut r = box_region();
        assert!(!grow(&mut r, &line(0.0, 0.11, 0.28), 0.1, |_| false));
    }

    #[test]
    fn a_views_table_is_the_plane_it_sees_around_the_region() {
        // Tilted by 0.1 m/m and noisy: the fit finds the tilt, not phase 1's level table.
        let mut seen = table(0.1);
        seen.extend(line(0.0, 0.06, 0.28));
        let fit = box_region().view_table(&seen, 0.1).unwrap();
        let tilt = fit.normal.x / fit.normal.z;
        assert!((tilt + 0.1).abs() < 0.01, "{tilt}");
        assert!((fit.signed_distance(&Point3::new(0.2, 0.0, 0.27))).abs() < 0.005);
        // A flat object's top, wider than the table seen around it, is not the table.
        let mut flat: Vec<_> = (0..400)
            .map(|i| {
                Point3::new(
                    -0.005 + 0.004 * (i % 20) as f64,
                    -0.005 + 0.0025 * (i / 20) as f64,
                    0.27,
                )
            })
            .collect();
        flat.extend(table(0.0).into_iter().filter(|p| !box_region().covers(p)));
        let fit = box_region().view_table(&flat, 0.1).unwrap();
        assert!(fit.signed_distance(&Point3::new(0.0, 0.0, 0.25)).abs() < 0.005);
        // No table under the region, or nothing near its height: no plane.
        let floating = ObjectRegion {
            table: None,
            ..box_region()
        };
        assert!(floating.view_table(&seen, 0.1).is_none());
        assert!(
            box_region()
                .view_table(&line(0.0, 0.06, 0.35), 0.1)
                .is_none()
        );
    }

    #[test]
    fn a_region_grows_up_to_a_part_seen_above_it() {
        // A handle rising 8 cm above the laser's top, points 5 mm apart.
        let mut r = box_region();
        let seen: Vec<_> = (0..=16)
            .map(|i| Point3::new(0.03, 0.02, 0.3 + 0.005 * i as f64))
            .collect();
        let max_z = r.max.z;
        assert!(grow(&mut r, &seen, 0.1, |_| false));
        assert!((r.top - 0.38).abs() < 1e-9);
        assert!(r.max.z >= max_z && r.max.z >= 0.39 - 1e-9);
        assert_eq!((r.min.x, r.max.x), (box_region().min.x, box_region().max.x));
    }
}
