//! [`StatisticalOutlierFilter`]: statistical outlier removal — drop points whose mean
//! distance to their k nearest neighbours is far above the cloud's average.

use std::num::NonZeroUsize;

use rayon::prelude::*;

use super::processing_error::{ProcessingError, check_cloud};
use super::{KNearest, PointCloud};

/// Statistical outlier removal. For every point, `d_i` is the mean Euclidean distance to
/// its `neighbours` nearest other points ([`KNearest`]). With `μ` and `σ` the
/// mean and sample standard deviation of all `d_i`, a point is kept when
/// `d_i ≤ μ + std_mul·σ`.
///
/// Deterministic: the per-point distances do not depend on which of several equidistant
/// neighbours the tree returns, and `μ`, `σ` are summed in index order.
///
/// ```
/// use nbv_core::cloud::{PointCloud, StatisticalOutlierFilter};
/// use nalgebra::Point3;
/// let mut pts: Vec<_> = (0..100)
///     .map(|i| Point3::new((i % 10) as f64 * 0.01, (i / 10) as f64 * 0.01, 0.0))
///     .collect();
/// pts.push(Point3::new(5.0, 5.0, 5.0));
/// let f = StatisticalOutlierFilter { neighbours: 8, std_mul: 1.0 };
/// let kept = f.inliers(&PointCloud::from_points(pts)).unwrap();
/// assert_eq!(kept.len(), 100);
/// assert!(!kept.contains(&100));
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StatisticalOutlierFilter {
    /// Number of nearest neighbours `k` (≥ 1; the cloud needs more than `k` points).
    pub neighbours: usize,
    /// Multiplier of the standard deviation (finite; may be negative to cut harder).
    pub std_mul: f64,
}

impl StatisticalOutlierFilter {
    /// Mean distance of every point to its `k` nearest neighbours, in point order.
    pub fn mean_distances(&self, cloud: &PointCloud) -> Result<Vec<f64>, ProcessingError> {
        let k = NonZeroUsize::new(self.neighbours).ok_or(ProcessingError::InvalidParameter {
            name: "neighbours",
            value: 0.0,
            reason: "must be >= 1",
        })?;
        if !self.std_mul.is_finite() {
            return Err(ProcessingError::InvalidParameter {
                name: "std_mul",
                value: self.std_mul,
                reason: "must be finite",
            });
        }
        check_cloud(cloud)?;
        let needed = self.neighbours.saturating_add(1);
        if cloud.len() < needed {
            return Err(ProcessingError::TooFewPoints {
                needed,
                got: cloud.len(),
            });
        }
        let nearest = KNearest::of_each(&cloud.points, k.saturating_add(1))?;
        let distances = (0..cloud.len())
            .into_par_iter()
            .map(|i| {
                let found = nearest.of(i);
                // Drop the point itself; with exact duplicates it may be absent, then the
                // farthest of the k + 1 goes (sorted ascending by distance).
                let skip = found
                    .iter()
                    .position(|&(j, _)| j as usize == i)
                    .unwrap_or(found.len().saturating_sub(1));
                let sum: f64 = found
                    .iter()
                    .enumerate()
                    .filter(|&(j, _)| j != skip)
                    .map(|(_, &(_, sq))| sq.sqrt())
                    .sum();
                sum / self.neighbours as f64
            })
            .collect();
        Ok(distances)
    }

    /// Indices of the points kept, ascending.
    pub fn inliers(&self, cloud: &PointCloud) -> Result<Vec<usize>, ProcessingError> {
        let d = self.mean_distances(cloud)?;
        let threshold = Self::threshold(&d, self.std_mul);
        Ok((0..d.len()).filter(|&i| d[i] <= threshold).collect())
    }

    /// The filtered cloud (all columns kept in step).
    pub fn filter(&self, cloud: &PointCloud) -> Result<PointCloud, ProcessingError> {
        Ok(cloud.select(&self.inliers(cloud)?))
    }

    /// `μ + std_mul·σ` over the mean distances (sample standard deviation; σ = 0 for one
    /// point).
    fn threshold(d: &[f64], std_mul: f64) -> f64 {
        let n = d.len() as f64;
        let mean = d.iter().sum::<f64>() / n;
        let var = if d.len() > 1 {
            d.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / (n - 1.0)
        } else {
            0.0
        };
        mean + std_mul * var.sqrt()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Point3;
    use proptest::prelude::*;

    fn grid_with_outliers() -> PointCloud {
        let mut pts: Vec<_> = (0..400)
            .map(|i| Point3::new((i % 20) as f64 * 0.01, (i / 20) as f64 * 0.01, 0.0))
            .collect();
        pts.push(Point3::new(1.0, 1.0, 1.0));
        pts.push(Point3::new(-1.0, 0.5, 0.3));
        let mut c = PointCloud::from_points(pts);
        c.labels = Some((0..402).collect());
        c
    }

    #[test]
    fn removes_isolated_points_keeps_columns() {
        let c = grid_with_outliers();
        let f = StatisticalOutlierFilter {
            neighbours: 6,
            std_mul: 1.0,
        };
        let out = f.filter(&c).unwrap();
        assert_eq!(out.len(), 400);
        assert_eq!(out.labels.as_ref().unwrap()[399], 399);
        // Interior grid points have 4 neighbours at 0.01 and 2 more at sqrt(2)*0.01.
        let d = f.mean_distances(&c).unwrap();
        let expected = (4.0 * 0.01 + 2.0 * 0.01 * 2f64.sqrt()) / 6.0;
        assert!((d[21] - expected).abs() < 1e-12);
    }

    #[test]
    fn duplicates_and_errors() {
        let c = PointCloud::from_points(vec![Point3::new(1.0, 2.0, 3.0); 50]);
        let f = StatisticalOutlierFilter {
            neighbours: 4,
            std_mul: 0.0,
        };
        assert!(f.mean_distances(&c).unwrap().iter().all(|&d| d == 0.0));
        assert_eq!(f.inliers(&c).unwrap().len(), 50);
        let small = PointCloud::from_points(vec![Point3::origin(); 3]);
        assert_eq!(
            f.inliers(&small),
            Err(ProcessingError::TooFewPoints { needed: 5, got: 3 })
        );
        let bad = StatisticalOutlierFilter {
            neighbours: 0,
            std_mul: 1.0,
        };
        assert!(matches!(
            bad.inliers(&c),
            Err(ProcessingError::InvalidParameter { .. })
        ));
        let bad = StatisticalOutlierFilter {
            neighbours: 2,
            std_mul: f64::NAN,
        };
        assert!(matches!(
            bad.inliers(&c),
            Err(ProcessingError::InvalidParameter { .. })
        ));
        assert_eq!(
            f.inliers(&PointCloud::default()),
            Err(ProcessingError::EmptyCloud)
        );
    }

    #[test]
    fn independent_of_thread_count() {
        let c = grid_with_outliers();
        let f = StatisticalOutlierFilter {
            neighbours: 8,
            std_mul: 0.5,
        };
        let run = |threads| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| f.mean_distances(&c).unwrap())
        };
        assert_eq!(run(1), run(3));
    }

    proptest! {
        #[test]
        fn matches_brute_force(
            pts in prop::collection::vec((-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0), 6..80),
            k in 1usize..5,
        ) {
            let cloud = PointCloud::from_points(
                pts.iter().map(|&(x, y, z)| Point3::new(x, y, z)).collect());
            let f = StatisticalOutlierFilter { neighbours: k, std_mul: 1.0 };
            let d = f.mean_distances(&cloud).unwrap();
            for (i, p) in cloud.points.iter().enumerate() {
                let mut all: Vec<f64> = cloud.points.iter().enumerate()
                    .filter(|&(j, _)| j != i).map(|(_, q)| (p - q).norm()).collect();
                all.sort_by(f64::total_cmp);
                let brute = all[..k].iter().sum::<f64>() / k as f64;
                prop_assert!((d[i] - brute).abs() < 1e-9);
            }
        }
    }
}
