//! [`PointCloud`]: points with optional per-point columns (sensor origin, normal, label,
//! view index, noise-free ground-truth point), kept in step by every operation.

use nalgebra::{Isometry3, Point3, Vector3};
use thiserror::Error;

/// Errors of cloud construction and column bookkeeping.
#[derive(Debug, Error, PartialEq)]
pub enum CloudError {
    /// An optional column does not have one entry per point.
    #[error("column `{column}` has {len} entries but the cloud has {points} points")]
    ColumnLength {
        /// Column name.
        column: &'static str,
        /// Entries in the column.
        len: usize,
        /// Points in the cloud.
        points: usize,
    },
    /// A point (or origin/normal) is NaN or infinite.
    #[error("{column} {index} is not finite")]
    NotFinite {
        /// Column name.
        column: &'static str,
        /// Index of the offending entry.
        index: usize,
    },
}

/// A point cloud in some frame (the frame is the caller's to know), with optional
/// per-point columns. Every `Some` column has exactly one entry per point.
///
/// ```
/// use nbv_core::cloud::PointCloud;
/// use nalgebra::Point3;
/// let mut c = PointCloud::from_points(vec![Point3::new(0.0, 0.0, 1.0), Point3::new(1.0, 0.0, 1.0)]);
/// c.labels = Some(vec![7, 8]);
/// let first = c.select(&[1]);
/// assert_eq!(first.points[0].x, 1.0);
/// assert_eq!(first.labels.as_deref(), Some(&[8][..]));
/// ```
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PointCloud {
    /// The measured points.
    pub points: Vec<Point3<f64>>,
    /// Sensor origin of each point's ray (needed to update an occupancy grid).
    pub origins: Option<Vec<Point3<f64>>>,
    /// Surface normal estimate per point.
    pub normals: Option<Vec<Vector3<f64>>>,
    /// Ground-truth label per point: what the ray hit (the scene defines the numbering).
    pub labels: Option<Vec<u32>>,
    /// Index of the view each point came from (merged models).
    pub views: Option<Vec<u32>>,
    /// Noise-free point, in the same frame as `points` would be under the *true* sensor pose.
    pub truth: Option<Vec<Point3<f64>>>,
}

impl PointCloud {
    /// A cloud of bare points.
    pub fn from_points(points: Vec<Point3<f64>>) -> Self {
        Self {
            points,
            ..Self::default()
        }
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// Whether the cloud has no point.
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// Checks that every column has one entry per point and every coordinate is finite.
    pub fn validate(&self) -> Result<(), CloudError> {
        let n = self.points.len();
        let check = |column: &'static str, len: Option<usize>| match len {
            Some(len) if len != n => Err(CloudError::ColumnLength {
                column,
                len,
                points: n,
            }),
            _ => Ok(()),
        };
        check("origins", self.origins.as_ref().map(Vec::len))?;
        check("normals", self.normals.as_ref().map(Vec::len))?;
        check("labels", self.labels.as_ref().map(Vec::len))?;
        check("views", self.views.as_ref().map(Vec::len))?;
        check("truth", self.truth.as_ref().map(Vec::len))?;
        let finite = |column: &'static str, it: &mut dyn Iterator<Item = [f64; 3]>| {
            for (index, v) in it.enumerate() {
                if !v.iter().all(|c| c.is_finite()) {
                    return Err(CloudError::NotFinite { column, index });
                }
            }
            Ok(())
        };
        finite("point", &mut self.points.iter().map(|p| [p.x, p.y, p.z]))?;
        if let Some(o) = &self.origins {
            finite("origin", &mut o.iter().map(|p| [p.x, p.y, p.z]))?;
        }
        if let Some(nr) = &self.normals {
            finite("normal", &mut nr.iter().map(|p| [p.x, p.y, p.z]))?;
        }
        Ok(())
    }

    /// At most `n` of the points, evenly spread over the cloud's order (columns
    /// included); 0, or a cloud of at most `n` points, keeps all.
    ///
    /// ```
    /// use nbv_core::cloud::PointCloud;
    /// use nalgebra::Point3;
    /// let c = PointCloud::from_points((0..10).map(|i| Point3::new(i as f64, 0.0, 0.0)).collect());
    /// let xs: Vec<f64> = c.thinned(4).points.iter().map(|p| p.x).collect();
    /// assert_eq!(xs, vec![0.0, 2.0, 5.0, 7.0]);
    /// assert_eq!(c.thinned(0).len(), 10);
    /// ```
    pub fn thinned(&self, n: usize) -> Self {
        if n == 0 || self.len() <= n {
            return self.clone();
        }
        let indices: Vec<usize> = (0..n).map(|k| k * self.len() / n).collect();
        self.select(&indices)
    }

    /// A new cloud made of the points at `indices` (in that order), columns included.
    pub fn select(&self, indices: &[usize]) -> Self {
        fn pick<T: Clone>(col: &Option<Vec<T>>, indices: &[usize]) -> Option<Vec<T>> {
            col.as_ref()
                .map(|c| indices.iter().map(|&i| c[i].clone()).collect())
        }
        Self {
            points: indices.iter().map(|&i| self.points[i]).collect(),
            origins: pick(&self.origins, indices),
            normals: pick(&self.normals, indices),
            labels: pick(&self.labels, indices),
            views: pick(&self.views, indices),
            truth: pick(&self.truth, indices),
        }
    }

    /// Keeps the points for which `keep(i)` is true.
    pub fn retain_indices(&self, mut keep: impl FnMut(usize) -> bool) -> Self {
        let idx: Vec<usize> = (0..self.len()).filter(|&i| keep(i)).collect();
        self.select(&idx)
    }

    /// Appends `other` to `self`. A column survives only if both clouds have it
    /// (or `self` is empty, in which case `other`'s columns are taken).
    pub fn extend(&mut self, other: &PointCloud) {
        if self.is_empty() {
            *self = other.clone();
            return;
        }
        fn join<T: Clone>(a: &mut Option<Vec<T>>, b: &Option<Vec<T>>) {
            match (a.as_mut(), b) {
                (Some(a), Some(b)) => a.extend_from_slice(b),
                _ => *a = None,
            }
        }
        self.points.extend_from_slice(&other.points);
        join(&mut self.origins, &other.origins);
        join(&mut self.normals, &other.normals);
        join(&mut self.labels, &other.labels);
        join(&mut self.views, &other.views);
        join(&mut self.truth, &other.truth);
    }

    /// Applies a rigid transform to points, origins and normals (not to `truth`, which
    /// stays in the frame it was recorded in).
    pub fn transform(&mut self, t: &Isometry3<f64>) {
        for p in &mut self.points {
            *p = t * *p;
        }
        if let Some(o) = &mut self.origins {
            for p in o {
                *p = t * *p;
            }
        }
        if let Some(nr) = &mut self.normals {
            for v in nr {
                *v = t.rotation * *v;
            }
        }
    }

    /// Mean of the points, or `None` for an empty cloud.
    pub fn centroid(&self) -> Option<Point3<f64>> {
        if self.is_empty() {
            return None;
        }
        let sum = self
            .points
            .iter()
            .fold(Vector3::zeros(), |s, p| s + p.coords);
        Some(Point3::from(sum / self.len() as f64))
    }

    /// Mean of the sensor origins (where the sensor stood, on average), or `None` without
    /// an `origins` column or points.
    ///
    /// ```
    /// use nbv_core::cloud::PointCloud;
    /// use nalgebra::Point3;
    /// let mut c = PointCloud::from_points(vec![Point3::origin(); 2]);
    /// assert_eq!(c.origin_centroid(), None);
    /// c.origins = Some(vec![Point3::new(0.0, 0.0, 1.0), Point3::new(0.0, 0.0, 3.0)]);
    /// assert_eq!(c.origin_centroid(), Some(Point3::new(0.0, 0.0, 2.0)));
    /// ```
    pub fn origin_centroid(&self) -> Option<Point3<f64>> {
        let o = self.origins.as_ref().filter(|o| !o.is_empty())?;
        let sum = o.iter().fold(Vector3::zeros(), |s, p| s + p.coords);
        Some(Point3::from(sum / o.len() as f64))
    }

    /// Axis-aligned bounds `(min, max)`, or `None` for an empty cloud.
    pub fn bounds(&self) -> Option<(Point3<f64>, Point3<f64>)> {
        let first = *self.points.first()?;
        Some(
            self.points
                .iter()
                .fold((first, first), |(lo, hi), p| (lo.inf(p), hi.sup(p))),
        )
    }

    /// The shortest and the longest distance of a point from its sensor origin:
    /// `(∞, 0)` without origins or points.
    ///
    /// ```
    /// use nbv_core::cloud::PointCloud;
    /// use nalgebra::Point3;
    /// let mut c = PointCloud::from_points(vec![Point3::new(0.0, 0.0, 1.0), Point3::new(0.0, 0.0, 3.0)]);
    /// assert_eq!(c.range_extent(), (f64::INFINITY, 0.0));
    /// c.origins = Some(vec![Point3::origin(); 2]);
    /// assert_eq!(c.range_extent(), (1.0, 3.0));
    /// ```
    pub fn range_extent(&self) -> (f64, f64) {
        self.points
            .iter()
            .zip(self.origins.iter().flatten())
            .map(|(p, o)| (p - o).norm())
            .fold((f64::INFINITY, 0.0f64), |(a, b), r| (a.min(r), b.max(r)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cloud3() -> PointCloud {
        PointCloud {
            points: vec![
                Point3::new(0.0, 0.0, 0.0),
                Point3::new(1.0, 2.0, 3.0),
                Point3::new(-1.0, 0.5, 0.0),
            ],
            origins: Some(vec![Point3::origin(); 3]),
            labels: Some(vec![1, 2, 3]),
            ..PointCloud::default()
        }
    }

    #[test]
    fn validate_catches_short_columns_and_nan() {
        let mut c = cloud3();
        assert_eq!(c.validate(), Ok(()));
        c.labels = Some(vec![1]);
        assert_eq!(
            c.validate(),
            Err(CloudError::ColumnLength {
                column: "labels",
                len: 1,
                points: 3
            })
        );
        let mut c = cloud3();
        c.points[2].y = f64::NAN;
        assert_eq!(
            c.validate(),
            Err(CloudError::NotFinite {
                column: "point",
                index: 2
            })
        );
    }

    #[test]
    fn centroid_bounds_and_extend() {
        let mut c = cloud3();
        let m = c.centroid().unwrap();
        assert!((m - Point3::new(0.0, 2.5 / 3.0, 1.0)).norm() < 1e-12);
        let (lo, hi) = c.bounds().unwrap();
        assert_eq!(lo, Point3::new(-1.0, 0.0, 0.0));
        assert_eq!(hi, Point3::new(1.0, 2.0, 3.0));
        let other = PointCloud::from_points(vec![Point3::new(5.0, 5.0, 5.0)]);
        c.extend(&other);
        assert_eq!(c.len(), 4);
        assert!(c.labels.is_none() && c.origins.is_none());
        assert_eq!(c.validate(), Ok(()));
    }

    #[test]
    fn transform_moves_points_and_origins() {
        let mut c = cloud3();
        let t = Isometry3::translation(1.0, 0.0, 0.0);
        c.transform(&t);
        assert_eq!(c.points[0], Point3::new(1.0, 0.0, 0.0));
        assert_eq!(c.origins.as_ref().unwrap()[2], Point3::new(1.0, 0.0, 0.0));
    }
}
