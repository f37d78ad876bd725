//! [`merge_fragments`]: the pieces of a small object, each too small to be an object on
//! its own, become one cluster again.
//!
//! A small object seen by the laser at a metre is a few hundred points, and where it is
//! thin or hides part of itself (a figurine's head, body and legs) the sweep leaves gaps a
//! little wider than the clustering tolerance between its pieces. Each piece alone falls
//! below `min_cluster_points`, which is there to drop noise — so the whole object was
//! dropped. The size that matters is the object's, not the piece's: a piece too small to
//! stand alone joins the nearest component within a gap of a few tolerances, and the
//! group is judged by its total size.
//!
//! Each small piece joins one neighbour only, its nearest, so a large component never
//! joins another one through the pieces between them: every group holds at most one
//! component of `min_points` or more.

use nalgebra::Point3;

use crate::cloud::Cluster;

/// Joins every cluster of `points` smaller than `min_points` (its points and its `thin`
/// parts counted) to the nearest other cluster whose closest point lies within `gap`, and
/// returns the groups, in the order of each group's smallest point index, with their thin
/// parts summed and the number of joins done. A small cluster with no neighbour within
/// `gap` stays alone (and is judged small by the caller). Ties go to the cluster listed
/// first.
///
/// Deterministic, and independent of the order of `clusters`.
///
/// ```
/// use nbv_core::cloud::Cluster;
/// use nbv_core::perception::merge_fragments;
/// use nalgebra::Point3;
/// // A figurine's head and body, 3 cm apart, each of 20 points; a 60-point object 30 cm
/// // away.
/// let blob = |x: f64, n: usize| -> Vec<Point3<f64>> {
///     (0..n).map(|k| Point3::new(x + (k % 4) as f64 * 0.005, (k / 4) as f64 * 0.005, 0.3)).collect()
/// };
/// let pts: Vec<_> = [blob(0.0, 20), blob(0.045, 20), blob(0.4, 60)].concat();
/// let part = |a: usize, b: usize| Cluster::from_indices(&pts, (a..b).collect());
/// let (groups, thin, joins) =
///     merge_fragments(&pts, vec![part(0, 20), part(20, 40), part(40, 100)], &[0, 0, 0], 30, 0.04)
///         ;
/// assert_eq!((groups.len(), joins), (2, 1));
/// assert_eq!(groups[0].len(), 40);
/// assert_eq!(thin, [0, 0]);
/// ```
pub fn merge_fragments(
    points: &[Point3<f64>],
    clusters: Vec<Cluster>,
    thin: &[usize],
    min_points: usize,
    gap: f64,
) -> (Vec<Cluster>, Vec<usize>, usize) {
    let n = clusters.len();
    let small: Vec<bool> = clusters
        .iter()
        .zip(thin)
        .map(|(c, &t)| c.len() + t < min_points)
        .collect();
    // Each small cluster points at its nearest neighbour within `gap`, if any.
    let mut parent: Vec<usize> = (0..n).collect();
    let mut joins = 0;
    for i in (0..n).filter(|&i| small[i]) {
        let nearest = (0..n)
            .filter(|&j| j != i)
            .map(|j| (j, closest_distance(points, &clusters[i], &clusters[j])))
            .filter(|&(_, d)| d <= gap)
            .min_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)));
        if let Some((j, _)) = nearest {
            parent[i] = j;
        }
    }
    // Follow each chain to its end: a large cluster, a lone small one, or a pair of small
    // clusters each other's nearest (the smaller index then names the group).
    let root = |mut i: usize| {
        let mut seen = vec![false; n];
        while parent[i] != i && !seen[i] {
            seen[i] = true;
            i = parent[i];
        }
        // On a cycle, the smallest index on it names the group.
        if parent[i] != i {
            let start = i;
            let mut m = i;
            let mut k = parent[i];
            while k != start {
                m = m.min(k);
                k = parent[k];
            }
            return m;
        }
        i
    };
    let mut groups: std::collections::BTreeMap<usize, (Vec<usize>, usize)> = Default::default();
    for (i, c) in clusters.iter().enumerate() {
        let r = root(i);
        if r != i {
            joins += 1;
        }
        let g = groups.entry(r).or_default();
        g.0.extend_from_slice(&c.indices);
        g.1 += thin[i];
    }
    let mut merged: Vec<(Cluster, usize)> = groups
        .into_values()
        .filter(|(g, _)| !g.is_empty())
        .map(|(mut g, t)| {
            g.sort_unstable();
            (Cluster::from_indices(points, g), t)
        })
        .collect();
    merged.sort_by_key(|(c, _)| c.indices[0]);
    let (clusters, thin) = merged.into_iter().unzip();
    (clusters, thin, joins)
}

/// The distance between the closest points of two clusters (infinite if one is empty);
/// their boxes first, so far clusters cost nothing.
fn closest_distance(points: &[Point3<f64>], a: &Cluster, b: &Cluster) -> f64 {
    if a.is_empty() || b.is_empty() {
        return f64::INFINITY;
    }
    let box_gap = (0..3)
        .map(|k| (a.min[k] - b.max[k]).max(b.min[k] - a.max[k]).max(0.0))
        .map(|d| d * d)
        .sum::<f64>()
        .sqrt();
    if box_gap > 0.5 {
        return box_gap;
    }
    let mut best = f64::INFINITY;
    for &i in &a.indices {
        for &j in &b.indices {
            best = best.min((points[i] - points[j]).norm_squared());
        }
    }
    best.sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn blob(x: f64, y: f64, n: usize) -> Vec<Point3<f64>> {
        (0..n)
            .map(|k| Point3::new(x + (k % 5) as f64 * 0.004, y + (k / 5) as f64 * 0.004, 0.3))
            .collect()
    }

    /// Two large objects 3 cm apart with a small piece between them: the piece joins the
    /// nearer one, and the two objects stay apart.
    #[test]
    fn a_piece_between_two_objects_joins_one_only() {
        let a = blob(0.0, 0.0, 150); // x 0..0.016
        let piece = blob(0.030, 0.0, 10); // x 0.030..0.046
        let b = blob(0.065, 0.0, 150); // x 0.065..
        let pts = [a, piece, b].concat();
        let cl = |r: std::ops::Range<usize>| Cluster::from_indices(&pts, r.collect());
        let clusters = vec![cl(0..150), cl(150..160), cl(160..310)];
        let (groups, _, joins) = merge_fragments(&pts, clusters, &[0, 0, 0], 100, 0.04);
        assert_eq!(joins, 1);
        assert_eq!(groups.len(), 2);
        // The piece is 14 mm from a's edge and 19 mm from b's.
        assert_eq!(groups[0].len(), 160);
        assert_eq!(groups[1].len(), 150);
    }

    /// A lone small piece far from everything stays alone.
    #[test]
    fn a_far_piece_stays_alone() {
        let pts = [blob(0.0, 0.0, 150), blob(0.3, 0.0, 10)].concat();
        let cl = |r: std::ops::Range<usize>| Cluster::from_indices(&pts, r.collect());
        let (groups, thin, joins) =
            merge_fragments(&pts, vec![cl(0..150), cl(150..160)], &[2, 3], 100, 0.04);
        assert_eq!((groups.len(), joins), (2, 0));
        assert_eq!(thin, [2, 3]);
    }

    proptest! {
        /// Whatever the layout: no point is lost or doubled, and no group holds two
        /// clusters of `min_points` or more.
        #[test]
        fn large_clusters_never_join(xs in proptest::collection::vec((0.0f64..0.5, 0.0f64..0.5, 1usize..40), 1..10)) {
            let mut pts = Vec::new();
            let mut clusters = Vec::new();
            for &(x, y, n) in &xs {
                let start = pts.len();
                pts.extend(blob(x, y, n));
                clusters.push((start, pts.len()));
            }
            let cl: Vec<Cluster> = clusters
                .iter()
                .map(|&(a, b)| Cluster::from_indices(&pts, (a..b).collect()))
                .collect();
            let large: Vec<bool> = xs.iter().map(|&(_, _, n)| n >= 20).collect();
            let thin = vec![0; cl.len()];
            let (groups, _, _) = merge_fragments(&pts, cl, &thin, 20, 0.05);
            let mut all: Vec<usize> = groups.iter().flat_map(|g| g.indices.clone()).collect();
            all.sort_unstable();
            prop_assert_eq!(all, (0..pts.len()).collect::<Vec<_>>());
            for g in &groups {
                let holds = clusters
                    .iter()
                    .zip(&large)
                    .filter(|((a, _), l)| **l && g.indices.binary_search(a).is_ok())
                    .count();
                prop_assert!(holds <= 1);
            }
        }
    }
}
