//! [`merge_stacked_parts`]: the parts of one object that the laser saw apart become one
//! cluster again.
//!
//! A sweep from above and in front leaves gaps on an object wherever the object hides
//! itself: under a bottle's shoulder, below a horse's belly, along a vertical face seen at
//! grazing incidence, where the lines lie further apart than the clustering tolerance. The
//! parts of such an object are disjoint in 3D but stand over the same patch of the table.
//! Different objects resting on a table never do: their footprints are disjoint. So two
//! components are one object when most of the smaller one's footprint — the cells of a
//! grid on the table plane that its points project into — is also the other's.

use std::collections::HashSet;

use nalgebra::{Point3, Unit, Vector3};

use crate::cloud::Cluster;

/// Merges the clusters of `points` whose footprints on the plane of normal `up` overlap:
/// for each pair, the share of the smaller footprint's cells (side `cell`) that the other
/// footprint also covers exceeds `min_share` (at 0.5 or more, a component between two
/// objects whose footprints are disjoint can never join them: it cannot lie more than half
/// under each). Merging is transitive (connected
/// components of the overlap relation); the result is in the order of each cluster's
/// smallest point index, and the number of merges done is returned beside it.
///
/// Deterministic, and independent of the input order.
///
/// ```
/// use nbv_core::cloud::Cluster;
/// use nbv_core::perception::merge_stacked_parts;
/// use nalgebra::{Point3, Vector3};
/// // A bottle's body and, 3 cm above it, its shoulder (the laser missed what is between);
/// // a second object 6 cm to the side.
/// let mut pts = Vec::new();
/// for i in 0..5 {
///     for j in 0..5 {
///         let (x, y) = (i as f64 * 0.01, j as f64 * 0.01);
///         pts.push(Point3::new(x, y, 0.05));
///         pts.push(Point3::new(x, y, 0.12));
///         pts.push(Point3::new(x + 0.10, y, 0.05));
///     }
/// }
/// let part = |k: usize| Cluster::from_indices(&pts, (0..25).map(|n| 3 * n + k).collect());
/// let (merged, merges) =
///     merge_stacked_parts(&pts, vec![part(0), part(1), part(2)], &Vector3::z_axis(), 0.02, 0.5);
/// assert_eq!((merged.len(), merges), (2, 1));
/// assert_eq!(merged[0].len(), 50);
/// assert_eq!(merged[1].indices, part(2).indices);
/// ```
pub fn merge_stacked_parts(
    points: &[Point3<f64>],
    clusters: Vec<Cluster>,
    up: &Unit<Vector3<f64>>,
    cell: f64,
    min_share: f64,
) -> (Vec<Cluster>, usize) {
    let (u, v) = plane_basis(up);
    let footprints: Vec<HashSet<(i64, i64)>> = clusters
        .iter()
        .map(|c| {
            c.indices
                .iter()
                .map(|&i| {
                    let p = points[i].coords;
                    (
                        (p.dot(&u) / cell).floor() as i64,
                        (p.dot(&v) / cell).floor() as i64,
                    )
                })
                .collect()
        })
        .collect();
    let mut parent: Vec<usize> = (0..clusters.len()).collect();
    let mut merges = 0;
    for a in 0..clusters.len() {
        for b in a + 1..clusters.len() {
            let (small, large) = if footprints[a].len() <= footprints[b].len() {
                (&footprints[a], &footprints[b])
            } else {
                (&footprints[b], &footprints[a])
            };
            let shared = small.iter().filter(|c| large.contains(c)).count();
            if small.is_empty() || (shared as f64) <= min_share * small.len() as f64 {
                continue;
            }
            let (ra, rb) = (root(&mut parent, a), root(&mut parent, b));
            if ra != rb {
                parent[ra.max(rb)] = ra.min(rb);
                merges += 1;
            }
        }
    }
    if merges == 0 {
        return (clusters, 0);
    }
    let mut groups: Vec<Vec<usize>> = vec![Vec::new(); clusters.len()];
    for (k, c) in clusters.iter().enumerate() {
        let r = root(&mut parent, k);
        groups[r].extend_from_slice(&c.indices);
    }
    let mut merged: Vec<Cluster> = groups
        .into_iter()
        .filter(|g| !g.is_empty())
        .map(|mut g| {
            g.sort_unstable();
            Cluster::from_indices(points, g)
        })
        .collect();
    merged.sort_by_key(|c| c.indices[0]);
    (merged, merges)
}

fn root(parent: &mut [usize], mut k: usize) -> usize {
    while parent[k] != k {
        parent[k] = parent[parent[k]];
        k = parent[k];
    }
    k
}

/// Two unit vectors spanning the plane normal to `up`.
fn plane_basis(up: &Unit<Vector3<f64>>) -> (Vector3<f64>, Vector3<f64>) {
    let helper = if up.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    let u = up.cross(&helper).normalize();
    (u, up.cross(&u))
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn disc(centre: (f64, f64), radius: f64, z: f64, pts: &mut Vec<Point3<f64>>) -> Vec<usize> {
        let start = pts.len();
        for i in -10..=10 {
            for j in -10..=10 {
                let (x, y) = (i as f64 * radius / 10.0, j as f64 * radius / 10.0);
                if x * x + y * y <= radius * radius {
                    pts.push(Point3::new(centre.0 + x, centre.1 + y, z));
                }
            }
        }
        (start..pts.len()).collect()
    }

    proptest! {
        /// Objects at least a cell apart on the table are never merged, however their
        /// parts are ordered and however high each stands.
        #[test]
        fn separate_objects_stay_apart(
            gap in 0.03f64..0.2,
            heights in proptest::collection::vec(0.0f64..0.3, 3),
            angle in 0.0f64..std::f64::consts::TAU,
        ) {
            let mut pts = Vec::new();
            let r = 0.04;
            let d = 2.0 * r + gap;
            let (c, s) = (angle.cos(), angle.sin());
            let a = disc((0.0, 0.0), r, heights[0], &mut pts);
            let b = disc((d * c, d * s), r, heights[1], &mut pts);
            let top = disc((0.0, 0.0), r * 0.6, heights[0] + 0.1 + heights[2], &mut pts);
            let clusters = vec![
                Cluster::from_indices(&pts, b.clone()),
                Cluster::from_indices(&pts, top.clone()),
                Cluster::from_indices(&pts, a.clone()),
            ];
            let (merged, merges) = merge_stacked_parts(&pts, clusters, &Vector3::z_axis(), 0.02, 0.5);
            prop_assert_eq!(merges, 1);
            prop_assert_eq!(merged.len(), 2);
            // The first object (its parts a and top) is one cluster; b is alone.
            let mut first: Vec<usize> = a.iter().chain(&top).copied().collect();
            first.sort_unstable();
            prop_assert_eq!(&merged[0].indices, &first);
            prop_assert_eq!(&merged[1].indices, &b);
        }
    }

    #[test]
    fn a_tilted_table_uses_its_own_plane() {
        // The same stacked pair on a table tilted 30° about x: merged along the normal.
        let mut pts = Vec::new();
        let low = disc((0.0, 0.0), 0.03, 0.0, &mut pts);
        let high = disc((0.0, 0.0), 0.03, 0.15, &mut pts);
        let tilt = nalgebra::Rotation3::from_axis_angle(&Vector3::x_axis(), 0.5);
        let pts: Vec<_> = pts.iter().map(|p| tilt * p).collect();
        let up = Unit::new_normalize(tilt * Vector3::z());
        let clusters = vec![
            Cluster::from_indices(&pts, low),
            Cluster::from_indices(&pts, high),
        ];
        let (merged, merges) = merge_stacked_parts(&pts, clusters.clone(), &up, 0.02, 0.5);
        assert_eq!((merged.len(), merges), (1, 1));
        assert_eq!(merged[0].len(), clusters[0].len() + clusters[1].len());
        // Seen along world z instead, the two discs are offset by 7 cm: not merged.
        let (apart, merges) = merge_stacked_parts(&pts, clusters, &Vector3::z_axis(), 0.02, 0.5);
        assert_eq!((apart.len(), merges), (2, 0));
    }
}
