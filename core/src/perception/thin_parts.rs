//! [`merge_bridged_parts`]: the parts of one object that only its thin parts join become
//! one cluster again.
//!
//! The statistical outlier filter judges a point by the mean distance to its `k` nearest
//! neighbours. On a surface those lie in a small disc around it; along a thin part — a
//! vessel's rim, a figurine's leg or tail, a handle — they lie along a line, several times
//! further away, so the filter takes a one-voxel-wide part for outliers and drops it. The
//! parts it joined fall apart: the near wall of an open vessel and its far wall seen
//! through the opening, a figurine's body and its head or hind quarters. These parts do not
//! stand over one patch of the table ([`merge_stacked_parts`](super::merge_stacked_parts)
//! does not join them), but the points the filter removed still link them within the
//! clustering tolerance. Components linked that way are one object; the removed points stay
//! out of the clusters, but they count as the object's points where its size is judged (a
//! small figurine is mostly thin parts).

use nalgebra::Point3;

use crate::cloud::{Cluster, EuclideanClustering, PointCloud, ProcessingError};

/// Merges the clusters of `points` that a chain of `removed` points links: two clusters
/// are one object when the Euclidean clustering (link distance `tolerance`) of their points
/// together with `removed` puts them in one component. The clusters keep only their own
/// points; the result is in the order of each cluster's smallest point index, with, for
/// each, the number of removed points its component holds (its thin parts), and the number
/// of merges done.
///
/// Deterministic, and independent of the order of `clusters` and `removed`.
///
/// ```
/// use nbv_core::cloud::Cluster;
/// use nbv_core::perception::merge_bridged_parts;
/// use nalgebra::Point3;
/// // Two walls 6 cm apart, joined by a rim of points the outlier filter removed; a third
/// // wall beyond a gap of 6 cm with nothing between.
/// let wall = |x: f64| -> Vec<Point3<f64>> {
///     (0..25).map(|k| Point3::new(x, (k % 5) as f64 * 0.01, (k / 5) as f64 * 0.01)).collect()
/// };
/// let pts: Vec<_> = [wall(0.0), wall(0.06), wall(0.16)].concat();
/// let rim: Vec<_> = (1..6).map(|k| Point3::new(k as f64 * 0.01, 0.0, 0.04)).collect();
/// let part = |k: usize| Cluster::from_indices(&pts, (25 * k..25 * k + 25).collect());
/// let (merged, thin, merges) =
///     merge_bridged_parts(&pts, vec![part(0), part(1), part(2)], &rim, 0.02).unwrap();
/// assert_eq!((merged.len(), merges), (2, 1));
/// assert_eq!(thin, [5, 0]);
/// assert_eq!(merged[0].len(), 50);
/// assert_eq!(merged[1].indices, part(2).indices);
/// ```
pub fn merge_bridged_parts(
    points: &[Point3<f64>],
    clusters: Vec<Cluster>,
    removed: &[Point3<f64>],
    tolerance: f64,
) -> Result<(Vec<Cluster>, Vec<usize>, usize), ProcessingError> {
    if clusters.is_empty() || removed.is_empty() {
        let none = vec![0; clusters.len()];
        return Ok((clusters, none, 0));
    }
    // Only the clusters' own points and the removed ones take part.
    let own: Vec<usize> = clusters
        .iter()
        .flat_map(|c| c.indices.iter().copied())
        .collect();
    let mut all: Vec<Point3<f64>> = own.iter().map(|&i| points[i]).collect();
    all.extend_from_slice(removed);
    let components = EuclideanClustering {
        tolerance,
        min_size: 1,
        max_size: usize::MAX,
    }
    .clusters(&PointCloud::from_points(all))?;
    let mut component_of = vec![usize::MAX; own.len()];
    let mut thin = vec![0; components.len()];
    for (k, c) in components.iter().enumerate() {
        for &i in &c.indices {
            if i < own.len() {
                component_of[i] = k;
            } else {
                thin[k] += 1;
            }
        }
    }
    // Each cluster's first point (its position in `own`) names its component.
    let mut starts = Vec::with_capacity(clusters.len());
    let mut at = 0;
    for c in &clusters {
        starts.push(at);
        at += c.len();
    }
    let mut groups: std::collections::BTreeMap<usize, Vec<usize>> = Default::default();
    for (c, &s) in clusters.iter().zip(&starts) {
        if c.is_empty() {
            continue;
        }
        groups
            .entry(component_of[s])
            .or_default()
            .extend_from_slice(&c.indices);
    }
    let merges = clusters.iter().filter(|c| !c.is_empty()).count() - groups.len();
    let mut merged: Vec<(Cluster, usize)> = groups
        .into_iter()
        .map(|(k, mut g)| {
            g.sort_unstable();
            (Cluster::from_indices(points, g), thin[k])
        })
        .collect();
    merged.sort_by_key(|(c, _)| c.indices[0]);
    let (merged, thin) = merged.into_iter().unzip();
    Ok((merged, thin, merges))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cloud::StatisticalOutlierFilter;

    /// A hollow cup seen from one side and above, as the sweep leaves it after the
    /// outlier filter: the near outer wall, the far inner wall seen through the opening,
    /// and between them only the thin rim, which the filter removes.
    #[test]
    fn an_open_vessels_walls_joined_by_the_rim_the_filter_removed_are_one_object() {
        let (r, h, step) = (0.055, 0.18, 0.005);
        let mut pts = Vec::new();
        // A table around, every 5 mm, so that the filter's statistics are a sweep's.
        for i in -60..60 {
            for j in -60..60 {
                let (x, y) = (f64::from(i) * step, f64::from(j) * step);
                if x.hypot(y) > r + 0.03 {
                    pts.push(Point3::new(x, y, 0.0));
                }
            }
        }
        let n_table = pts.len();
        // Near wall: 126° facing −x, z from 2 to 18 cm; far inner wall: 126° facing +x,
        // z from 8 to 18 cm (the rest is hidden by the near rim); 5 cm apart at the sides.
        let span = 0.7 * std::f64::consts::PI;
        let arc = |from: f64, radius: f64, z0: f64, pts: &mut Vec<Point3<f64>>| {
            let n = (span * radius / step) as usize;
            for a in 0..=n {
                let t = from + span * a as f64 / n as f64;
                let mut z = z0;
                while z < h - 0.01 {
                    pts.push(Point3::new(radius * t.cos(), radius * t.sin(), z));
                    z += step;
                }
            }
        };
        let near_start = pts.len();
        arc(std::f64::consts::PI - 0.5 * span, r, 0.02, &mut pts);
        let far_start = pts.len();
        arc(-0.5 * span, r - 0.004, 0.08, &mut pts);
        let rim_start = pts.len();
        // The rim: one row of points all around at the top.
        let n = (std::f64::consts::TAU * r / step) as usize;
        for a in 0..n {
            let t = std::f64::consts::TAU * a as f64 / n as f64;
            pts.push(Point3::new((r - 0.002) * t.cos(), (r - 0.002) * t.sin(), h));
        }
        let cloud = PointCloud::from_points(pts.clone());
        let filter = StatisticalOutlierFilter {
            neighbours: 50,
            std_mul: 3.0,
        };
        let kept = filter.inliers(&cloud).unwrap();
        let is_kept = {
            let mut v = vec![false; pts.len()];
            kept.iter().for_each(|&i| v[i] = true);
            v
        };
        // The filter takes the rim: the two walls no longer touch.
        let rim_kept = (rim_start..pts.len()).filter(|&i| is_kept[i]).count();
        assert!(
            rim_kept < (pts.len() - rim_start) / 4,
            "rim kept {rim_kept}"
        );
        let above: Vec<usize> = (n_table..pts.len()).filter(|&i| is_kept[i]).collect();
        let removed: Vec<Point3<f64>> = (n_table..pts.len())
            .filter(|&i| !is_kept[i])
            .map(|i| pts[i])
            .collect();
        let above_pts: Vec<Point3<f64>> = above.iter().map(|&i| pts[i]).collect();
        let parts = EuclideanClustering {
            tolerance: 0.02,
            min_size: 1,
            max_size: usize::MAX,
        }
        .clusters(&PointCloud::from_points(above_pts.clone()))
        .unwrap();
        assert!(parts.len() >= 2, "{} parts", parts.len());
        let n_parts = parts.len();
        let (merged, thin, merges) =
            merge_bridged_parts(&above_pts, parts, &removed, 0.02).unwrap();
        assert_eq!(merged.len(), 1);
        assert_eq!(thin, [removed.len()]);
        assert_eq!(merges, n_parts - 1);
        assert_eq!(merged[0].len(), above_pts.len());
        // Both walls are in it.
        let near = above
            .iter()
            .filter(|&&i| (near_start..far_start).contains(&i))
            .count();
        let far = above
            .iter()
            .filter(|&&i| (far_start..rim_start).contains(&i))
            .count();
        assert!(near > 100 && far > 50, "{near} {far}");
    }

    #[test]
    fn objects_apart_stay_apart_and_order_does_not_matter() {
        // Two blocks 5 cm apart, removed specks around each but none between.
        let block = |x: f64| -> Vec<Point3<f64>> {
            (0..27)
                .map(|k| {
                    Point3::new(
                        x + (k % 3) as f64 * 0.01,
                        (k / 3 % 3) as f64 * 0.01,
                        (k / 9) as f64 * 0.01,
                    )
                })
                .collect()
        };
        let pts = [block(0.0), block(0.07)].concat();
        let specks = [Point3::new(-0.015, 0.0, 0.0), Point3::new(0.105, 0.0, 0.02)];
        let a = Cluster::from_indices(&pts, (0..27).collect());
        let b = Cluster::from_indices(&pts, (27..54).collect());
        let (m1, t1, n1) =
            merge_bridged_parts(&pts, vec![a.clone(), b.clone()], &specks, 0.02).unwrap();
        let (m2, t2, n2) = merge_bridged_parts(&pts, vec![b, a], &specks, 0.02).unwrap();
        assert_eq!((m1.len(), n1, n2), (2, 0, 0));
        assert_eq!(t2, [1, 1]);
        assert_eq!((m1, t1), (m2, t2));
    }
}
