//! [`VoxelFilter`]: voxel-grid downsampling — one point per occupied voxel, at the centroid
//! of the points that fall in it.

use nalgebra::{Point3, Vector3};

use super::PointCloud;
use super::processing_error::{ProcessingError, check_cloud};

/// Voxel-grid downsampling with cubic voxels of edge `leaf_size` on a lattice anchored at
/// the frame origin (voxel key `floor(p / leaf_size)` per axis).
///
/// Every occupied voxel gives one output point, in ascending `(kx, ky, kz)` key order, so
/// the result does not depend on the input order's accidents nor on thread count.
/// Columns are kept in step:
/// - `points`, `origins` and `truth` are the mean over the voxel's points (summed in input
///   order);
/// - `normals` is the normalised mean normal (the representative's normal if the mean
///   vanishes);
/// - `labels` and `views` come from the voxel's representative point, the member nearest
///   to the centroid (lowest input index on ties), taken with [`PointCloud::select`].
///
/// ```
/// use nbv_core::cloud::{PointCloud, VoxelFilter};
/// use nalgebra::Point3;
/// let cloud = PointCloud::from_points(vec![
///     Point3::new(0.01, 0.01, 0.01),
///     Point3::new(0.03, 0.01, 0.01),
///     Point3::new(0.25, 0.0, 0.0),
/// ]);
/// let down = VoxelFilter { leaf_size: 0.1 }.filter(&cloud).unwrap();
/// assert_eq!(down.len(), 2);
/// assert!((down.points[0].x - 0.02).abs() < 1e-12);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VoxelFilter {
    /// Voxel edge length (m), > 0.
    pub leaf_size: f64,
}

impl VoxelFilter {
    /// Downsamples `cloud`; errors on an empty or malformed cloud or a bad leaf size.
    pub fn filter(&self, cloud: &PointCloud) -> Result<PointCloud, ProcessingError> {
        let (order, starts) = self.sorted_members(cloud)?;
        let groups: Vec<&[usize]> = starts.windows(2).map(|w| &order[w[0]..w[1]]).collect();
        let (representatives, centroids): (Vec<usize>, Vec<Point3<f64>>) = groups
            .iter()
            .map(|members| representative(cloud, members))
            .unzip();
        let mut out = cloud.select(&representatives);
        out.points = centroids;
        if let Some(origins) = &cloud.origins {
            out.origins = Some(
                groups
                    .iter()
                    .map(|m| mean_point(m.iter().map(|&i| origins[i])))
                    .collect(),
            );
        }
        if let Some(truth) = &cloud.truth {
            out.truth = Some(
                groups
                    .iter()
                    .map(|m| mean_point(m.iter().map(|&i| truth[i])))
                    .collect(),
            );
        }
        if let (Some(normals), Some(out_normals)) = (&cloud.normals, out.normals.as_mut()) {
            for (members, n_out) in groups.iter().zip(out_normals.iter_mut()) {
                let sum = members
                    .iter()
                    .fold(Vector3::zeros(), |s: Vector3<f64>, &i| s + normals[i]);
                let norm = sum.norm();
                if norm > 1e-12 {
                    *n_out = sum / norm;
                }
            }
        }
        Ok(out)
    }

    /// The input indices grouped by voxel: groups in ascending voxel-key order, indices
    /// ascending within a group.
    pub fn voxel_groups(&self, cloud: &PointCloud) -> Result<Vec<Vec<usize>>, ProcessingError> {
        let (order, starts) = self.sorted_members(cloud)?;
        Ok(starts
            .windows(2)
            .map(|w| order[w[0]..w[1]].to_vec())
            .collect())
    }

    fn check_leaf(&self) -> Result<(), ProcessingError> {
        if self.leaf_size.is_finite() && self.leaf_size > 0.0 {
            Ok(())
        } else {
            Err(ProcessingError::InvalidParameter {
                name: "leaf_size",
                value: self.leaf_size,
                reason: "must be finite and > 0",
            })
        }
    }

    /// The voxel key `floor(p / leaf_size)` of point `index`.
    fn key(&self, p: &Point3<f64>, index: usize) -> Result<[i64; 3], ProcessingError> {
        // |key| < 2^52 keeps floor() exact and far from i64 overflow.
        const LIMIT: f64 = 4_503_599_627_370_496.0;
        let mut key = [0i64; 3];
        for (k, c) in key.iter_mut().zip([p.x, p.y, p.z]) {
            let f = (c / self.leaf_size).floor();
            if f.is_nan() || f.abs() >= LIMIT {
                return Err(ProcessingError::VoxelKeyOverflow {
                    index,
                    leaf_size: self.leaf_size,
                });
            }
            *k = f as i64;
        }
        Ok(key)
    }

    /// Point indices sorted by (voxel key, index), and the start of each voxel's run in
    /// that order (with a final entry equal to the number of points).
    fn sorted_members(
        &self,
        cloud: &PointCloud,
    ) -> Result<(Vec<usize>, Vec<usize>), ProcessingError> {
        self.check_leaf()?;
        check_cloud(cloud)?;
        let mut keyed = Vec::with_capacity(cloud.len());
        for (index, p) in cloud.points.iter().enumerate() {
            keyed.push((self.key(p, index)?, index));
        }
        // (key, index) pairs are unique: the sort order is total and deterministic.
        keyed.sort_unstable();
        let mut starts: Vec<usize> = (0..keyed.len())
            .filter(|&i| i == 0 || keyed[i].0 != keyed[i - 1].0)
            .collect();
        starts.push(keyed.len());
        Ok((keyed.into_iter().map(|(_, i)| i).collect(), starts))
    }
}

/// The member of a voxel (indices ascending) nearest to the members' centroid (the first
/// on ties), and the centroid.
fn representative(cloud: &PointCloud, members: &[usize]) -> (usize, Point3<f64>) {
    let c = mean_point(members.iter().map(|&i| cloud.points[i]));
    let mut best = members[0];
    let mut best_d = (cloud.points[best] - c).norm_squared();
    for &i in &members[1..] {
        let d = (cloud.points[i] - c).norm_squared();
        if d < best_d {
            best = i;
            best_d = d;
        }
    }
    (best, c)
}

/// Mean of a non-empty sequence of points, summed in iteration order.
fn mean_point(points: impl Iterator<Item = Point3<f64>>) -> Point3<f64> {
    let (sum, n) = points.fold((Vector3::zeros(), 0usize), |(s, n), p| {
        (s + p.coords, n + 1)
    });
    Point3::from(sum / n.max(1) as f64)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn centroids_and_columns_in_step() {
        let cloud = PointCloud {
            points: vec![
                Point3::new(0.5, 0.5, 0.5),
                Point3::new(-0.5, 0.5, 0.5),
                Point3::new(0.1, 0.1, 0.1),
                Point3::new(0.9, 0.9, 0.9),
                Point3::new(0.45, 0.5, 0.5),
            ],
            origins: Some(vec![
                Point3::new(0.0, 0.0, 2.0),
                Point3::new(0.0, 0.0, 2.0),
                Point3::new(0.0, 0.0, 4.0),
                Point3::new(0.0, 0.0, 2.0),
                Point3::new(0.0, 0.0, 2.0),
            ]),
            normals: Some(vec![Vector3::z(); 5]),
            labels: Some(vec![10, 11, 12, 13, 14]),
            ..PointCloud::default()
        };
        let down = VoxelFilter { leaf_size: 1.0 }.filter(&cloud).unwrap();
        assert_eq!(down.validate(), Ok(()));
        // Voxel (-1,0,0) first, then (0,0,0).
        assert_eq!(down.len(), 2);
        assert_eq!(down.points[0], Point3::new(-0.5, 0.5, 0.5));
        let c = down.points[1];
        assert!((c - Point3::new(0.4875, 0.5, 0.5)).norm() < 1e-12);
        // Representatives: point 1 alone, and point 0 (nearest to the centroid) for (0,0,0).
        assert_eq!(down.labels.as_deref(), Some(&[11, 10][..]));
        let o = down.origins.as_ref().unwrap()[1];
        assert!((o.z - 2.5).abs() < 1e-12);
        assert_eq!(down.normals.as_ref().unwrap()[1], Vector3::z());
    }

    #[test]
    fn bad_input_is_a_typed_error() {
        let f = VoxelFilter { leaf_size: 0.1 };
        assert_eq!(
            f.filter(&PointCloud::default()),
            Err(ProcessingError::EmptyCloud)
        );
        let c = PointCloud::from_points(vec![Point3::new(f64::NAN, 0.0, 0.0)]);
        assert!(matches!(f.filter(&c), Err(ProcessingError::Cloud(_))));
        let c = PointCloud::from_points(vec![Point3::new(1e300, 0.0, 0.0)]);
        assert!(matches!(
            f.filter(&c),
            Err(ProcessingError::VoxelKeyOverflow { index: 0, .. })
        ));
        for leaf_size in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            assert!(matches!(
                VoxelFilter { leaf_size }.filter(&c),
                Err(ProcessingError::InvalidParameter { .. })
            ));
        }
    }

    proptest! {
        #[test]
        fn one_point_per_voxel_inside_its_voxel(
            pts in prop::collection::vec((-2.0f64..2.0, -2.0f64..2.0, -2.0f64..2.0), 1..200),
            leaf in 0.05f64..1.0,
        ) {
            let cloud = PointCloud::from_points(
                pts.iter().map(|&(x, y, z)| Point3::new(x, y, z)).collect());
            let f = VoxelFilter { leaf_size: leaf };
            let down = f.filter(&cloud).unwrap();
            let groups = f.voxel_groups(&cloud).unwrap();
            prop_assert_eq!(down.len(), groups.len());
            let mut all: Vec<usize> = groups.iter().flatten().copied().collect();
            all.sort_unstable();
            prop_assert_eq!(all, (0..cloud.len()).collect::<Vec<_>>());
            let key = |p: &Point3<f64>| [(p.x / leaf).floor(), (p.y / leaf).floor(), (p.z / leaf).floor()];
            let mut prev = None;
            for (g, c) in groups.iter().zip(&down.points) {
                let k = key(&cloud.points[g[0]]);
                for &i in g { prop_assert_eq!(key(&cloud.points[i]), k); }
                // The centroid lies in the closed voxel.
                for a in 0..3 {
                    prop_assert!(c[a] >= k[a] * leaf - 1e-9 && c[a] <= (k[a] + 1.0) * leaf + 1e-9);
                }
                if let Some(p) = prev { prop_assert!(p < k); }
                prev = Some(k);
            }
            // Order independence: reversing the input gives the same points.
            let rev = PointCloud::from_points(cloud.points.iter().rev().copied().collect());
            let down_rev = f.filter(&rev).unwrap();
            for (a, b) in down.points.iter().zip(&down_rev.points) {
                prop_assert!((a - b).norm() < 1e-12);
            }
        }
    }
}
