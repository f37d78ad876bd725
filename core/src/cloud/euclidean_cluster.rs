//! [`EuclideanClustering`]: flood-fill clustering — points closer than a tolerance are
//! connected, clusters are the connected components within a size window, each with its
//! centroid and axis-aligned bounding box.

use kiddo::SquaredEuclidean;
use nalgebra::{Point3, Vector3};
use rayon::prelude::*;

use super::PointCloud;
use super::processing_error::{ProcessingError, build_kd_tree, check_cloud};

/// Euclidean clustering by flood fill over the graph linking every pair of points at
/// distance ≤ `tolerance` (kiddo radius queries, computed in parallel).
///
/// Components with fewer than `min_size` or more than `max_size` points are dropped.
/// Clusters are returned in the order of their smallest point index, with their indices
/// ascending: membership is a property of the graph, so the result is the same whatever
/// the thread count or traversal order.
///
/// ```
/// use nbv_core::cloud::{EuclideanClustering, PointCloud};
/// use nalgebra::Point3;
/// let mut pts: Vec<_> = (0..10).map(|i| Point3::new(i as f64 * 0.01, 0.0, 0.0)).collect();
/// pts.extend((0..5).map(|i| Point3::new(1.0 + i as f64 * 0.01, 0.0, 0.0)));
/// pts.push(Point3::new(5.0, 5.0, 5.0));
/// let ec = EuclideanClustering { tolerance: 0.015, min_size: 2, max_size: 100 };
/// let clusters = ec.clusters(&PointCloud::from_points(pts)).unwrap();
/// assert_eq!(clusters.len(), 2);
/// assert_eq!(clusters[1].indices, (10..15).collect::<Vec<_>>());
/// assert!((clusters[0].centroid.x - 0.045).abs() < 1e-12);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EuclideanClustering {
    /// Link distance (m), > 0.
    pub tolerance: f64,
    /// Smallest cluster kept, ≥ 1.
    pub min_size: usize,
    /// Largest cluster kept, ≥ `min_size`.
    pub max_size: usize,
}

/// One cluster: its point indices and its extent.
#[derive(Debug, Clone, PartialEq)]
pub struct Cluster {
    /// Indices of its points in the input cloud, ascending.
    pub indices: Vec<usize>,
    /// Mean of its points.
    pub centroid: Point3<f64>,
    /// Lower corner of its axis-aligned bounding box.
    pub min: Point3<f64>,
    /// Upper corner of its axis-aligned bounding box.
    pub max: Point3<f64>,
}

impl Cluster {
    /// Number of points.
    pub fn len(&self) -> usize {
        self.indices.len()
    }

    /// Whether the cluster has no point (never the case for a returned cluster).
    pub fn is_empty(&self) -> bool {
        self.indices.is_empty()
    }

    /// Its points as a cloud (all columns kept in step). `cloud` must be the clustered one.
    pub fn cloud(&self, cloud: &PointCloud) -> PointCloud {
        cloud.select(&self.indices)
    }

    /// The cluster of `points[i]` for the sorted, non-empty `indices`: their centroid and
    /// bounds.
    ///
    /// ```
    /// use nbv_core::cloud::Cluster;
    /// use nalgebra::Point3;
    /// let pts = [Point3::new(0.0, 0.0, 0.0), Point3::new(9.0, 9.0, 9.0), Point3::new(2.0, 4.0, 0.0)];
    /// let c = Cluster::from_indices(&pts, vec![0, 2]);
    /// assert_eq!((c.centroid, c.min, c.max), (Point3::new(1.0, 2.0, 0.0), pts[0], pts[2]));
    /// ```
    pub fn from_indices(points: &[Point3<f64>], indices: Vec<usize>) -> Self {
        let first = indices.first().map_or_else(Point3::origin, |&i| points[i]);
        let (sum, min, max) = indices.iter().fold(
            (Vector3::zeros(), first, first),
            |(s, lo, hi): (Vector3<f64>, Point3<f64>, Point3<f64>), &i| {
                let p = points[i];
                (s + p.coords, lo.inf(&p), hi.sup(&p))
            },
        );
        Cluster {
            centroid: Point3::from(sum / indices.len().max(1) as f64),
            indices,
            min,
            max,
        }
    }
}

impl EuclideanClustering {
    fn check(&self) -> Result<(), ProcessingError> {
        if !(self.tolerance.is_finite() && self.tolerance > 0.0) {
            return Err(ProcessingError::InvalidParameter {
                name: "tolerance",
                value: self.tolerance,
                reason: "must be finite and > 0",
            });
        }
        if self.min_size == 0 {
            return Err(ProcessingError::InvalidParameter {
                name: "min_size",
                value: 0.0,
                reason: "must be >= 1",
            });
        }
        if self.max_size < self.min_size {
            return Err(ProcessingError::InvalidParameter {
                name: "max_size",
                value: self.max_size as f64,
                reason: "must be >= min_size",
            });
        }
        Ok(())
    }

    /// The clusters of `cloud`.
    pub fn clusters(&self, cloud: &PointCloud) -> Result<Vec<Cluster>, ProcessingError> {
        self.check()?;
        check_cloud(cloud)?;
        let tree = build_kd_tree(cloud)?;
        let r2 = self.tolerance * self.tolerance;
        // Neighbour lists in compressed rows, computed in parallel, concatenated in order.
        let lists: Vec<Vec<u32>> = cloud
            .points
            .par_iter()
            .map(|p| {
                tree.query(&[p.x, p.y, p.z])
                    .within::<SquaredEuclidean<f64>>(r2)
                    .unsorted()
                    .execute()
                    .into_iter()
                    .map(|r| r.item)
                    .collect()
            })
            .collect();
        let n = cloud.len();
        let mut visited = vec![false; n];
        let mut clusters = Vec::new();
        let mut stack = Vec::new();
        for seed in 0..n {
            if visited[seed] {
                continue;
            }
            visited[seed] = true;
            stack.push(seed);
            let mut members = Vec::new();
            while let Some(i) = stack.pop() {
                members.push(i);
                for &j in &lists[i] {
                    let j = j as usize;
                    if !visited[j] {
                        visited[j] = true;
                        stack.push(j);
                    }
                }
            }
            if members.len() < self.min_size || members.len() > self.max_size {
                continue;
            }
            members.sort_unstable();
            clusters.push(Cluster::from_indices(&cloud.points, members));
        }
        Ok(clusters)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn size_window_and_boxes() {
        let mut pts = Vec::new();
        // A 5x5x5 block of points 1 cm apart, a 3-point line, and a single point.
        for i in 0..125 {
            pts.push(Point3::new(
                (i % 5) as f64 * 0.01,
                ((i / 5) % 5) as f64 * 0.01,
                (i / 25) as f64 * 0.01,
            ));
        }
        for i in 0..3 {
            pts.push(Point3::new(1.0, i as f64 * 0.01, 0.0));
        }
        pts.push(Point3::new(-1.0, 0.0, 0.0));
        let mut cloud = PointCloud::from_points(pts);
        cloud.labels = Some((0..129).collect());
        let ec = EuclideanClustering {
            tolerance: 0.0105,
            min_size: 2,
            max_size: 1000,
        };
        let c = ec.clusters(&cloud).unwrap();
        assert_eq!(c.len(), 2);
        assert_eq!(c[0].len(), 125);
        assert_eq!(c[0].min, Point3::new(0.0, 0.0, 0.0));
        assert!((c[0].max - Point3::new(0.04, 0.04, 0.04)).norm() < 1e-12);
        assert!((c[0].centroid - Point3::new(0.02, 0.02, 0.02)).norm() < 1e-12);
        assert_eq!(c[1].cloud(&cloud).labels, Some(vec![125, 126, 127]));
        let small_only = EuclideanClustering {
            max_size: 100,
            ..ec
        };
        assert_eq!(small_only.clusters(&cloud).unwrap().len(), 1);
        let singles = EuclideanClustering { min_size: 1, ..ec };
        assert_eq!(singles.clusters(&cloud).unwrap().len(), 3);
    }

    #[test]
    fn bad_input() {
        let cloud = PointCloud::from_points(vec![Point3::origin()]);
        let ok = EuclideanClustering {
            tolerance: 0.1,
            min_size: 1,
            max_size: 10,
        };
        assert_eq!(
            ok.clusters(&PointCloud::default()),
            Err(ProcessingError::EmptyCloud)
        );
        for bad in [
            EuclideanClustering {
                tolerance: -1.0,
                ..ok
            },
            EuclideanClustering {
                tolerance: f64::NAN,
                ..ok
            },
            EuclideanClustering { min_size: 0, ..ok },
            EuclideanClustering { max_size: 0, ..ok },
        ] {
            assert!(matches!(
                bad.clusters(&cloud),
                Err(ProcessingError::InvalidParameter { .. })
            ));
        }
    }

    /// Connected components by an O(n²) union-find, as a reference.
    fn brute_components(pts: &[Point3<f64>], tol: f64) -> Vec<Vec<usize>> {
        let n = pts.len();
        let mut parent: Vec<usize> = (0..n).collect();
        fn find(p: &mut [usize], mut i: usize) -> usize {
            while p[i] != i {
                p[i] = p[p[i]];
                i = p[i];
            }
            i
        }
        for i in 0..n {
            for j in i + 1..n {
                if (pts[i] - pts[j]).norm_squared() <= tol * tol {
                    let (a, b) = (find(&mut parent, i), find(&mut parent, j));
                    parent[a.max(b)] = a.min(b);
                }
            }
        }
        let mut groups: std::collections::BTreeMap<usize, Vec<usize>> = Default::default();
        for i in 0..n {
            let r = find(&mut parent, i);
            groups.entry(r).or_default().push(i);
        }
        let mut g: Vec<Vec<usize>> = groups.into_values().collect();
        g.sort_by_key(|m| m[0]);
        g
    }

    proptest! {
        #[test]
        fn matches_brute_force_components(
            pts in prop::collection::vec((0.0f64..1.0, 0.0f64..1.0, 0.0f64..0.2), 1..150),
            tol in 0.02f64..0.2,
        ) {
            let pts: Vec<_> = pts.iter().map(|&(x, y, z)| Point3::new(x, y, z)).collect();
            let cloud = PointCloud::from_points(pts.clone());
            let ec = EuclideanClustering { tolerance: tol, min_size: 1, max_size: usize::MAX };
            let got: Vec<Vec<usize>> =
                ec.clusters(&cloud).unwrap().into_iter().map(|c| c.indices).collect();
            prop_assert_eq!(got, brute_components(&pts, tol));
        }
    }

    #[test]
    fn independent_of_thread_count() {
        let pts: Vec<_> = (0..2000)
            .map(|i| {
                let t = i as f64 * 0.37;
                Point3::new(
                    t.sin() * (i % 7) as f64 * 0.1,
                    t.cos(),
                    (i % 13) as f64 * 0.02,
                )
            })
            .collect();
        let cloud = PointCloud::from_points(pts);
        let ec = EuclideanClustering {
            tolerance: 0.05,
            min_size: 3,
            max_size: 1500,
        };
        let run = |threads| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| ec.clusters(&cloud).unwrap())
        };
        assert_eq!(run(1), run(4));
    }
}
