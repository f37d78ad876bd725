//! [`ObjectRegion`]: where an object is for phase 2 — which points of a short-range view
//! belong to it (those inside its phase-1 bounding box grown by a margin, and above the
//! table) and where the centre of its viewing sphere lies.

use crate::cloud::{Cluster, PlaneFit, PointCloud};
use crate::perception::ObjectSegmentation;
use nalgebra::Point3;

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
}
