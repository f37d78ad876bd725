//! [`ObjectRegion`]: which points of a short-range view belong to an object — those inside
//! its phase-1 bounding box grown by a margin, and above the table.

use crate::cloud::PointCloud;
use nalgebra::Point3;

/// An axis-aligned region around an object.
///
/// ```
/// use nbv_core::pipeline::ObjectRegion;
/// use nbv_core::cloud::PointCloud;
/// use nalgebra::Point3;
/// let r = ObjectRegion::around(Point3::new(0.0, 0.0, 0.25), Point3::new(0.1, 0.1, 0.4), 0.05, 0.25);
/// let c = PointCloud::from_points(vec![
///     Point3::new(0.05, 0.05, 0.3),  // on the object
///     Point3::new(0.05, 0.05, 0.25), // the table under it
///     Point3::new(0.5, 0.0, 0.3),    // elsewhere
/// ]);
/// assert_eq!(r.crop(&c).len(), 1);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ObjectRegion {
    /// Lower corner.
    pub min: Point3<f64>,
    /// Upper corner.
    pub max: Point3<f64>,
}

impl ObjectRegion {
    /// The box `[min − margin, max + margin]`, whose floor is raised to `floor` + margin/5
    /// (the table top plus a little, so that table points stay out) when that is higher,
    /// and whose top is raised by the full margin plus half the object's height (the laser
    /// may not have seen its top).
    pub fn around(min: Point3<f64>, max: Point3<f64>, margin: f64, floor: f64) -> Self {
        let height = max.z - min.z;
        Self {
            min: Point3::new(
                min.x - margin,
                min.y - margin,
                (min.z - margin).max(floor + margin / 5.0),
            ),
            max: Point3::new(
                max.x + margin,
                max.y + margin,
                max.z + margin + height / 2.0,
            ),
        }
    }

    /// Whether `p` lies in the region.
    pub fn contains(&self, p: &Point3<f64>) -> bool {
        (0..3).all(|k| p[k] >= self.min[k] && p[k] <= self.max[k])
    }

    /// The points of `cloud` in the region (all columns).
    pub fn crop(&self, cloud: &PointCloud) -> PointCloud {
        cloud.retain_indices(|i| self.contains(&cloud.points[i]))
    }
}
