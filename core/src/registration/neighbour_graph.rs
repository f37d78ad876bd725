//! [`NeighbourGraph`]: every point's `K` nearest points within its own view, and the
//! radius they cover, so that a nearest-neighbour answer that may have changed can be
//! repaired exactly from the previous one, without a k-d tree search.
//!
//! For point `b`, every other point closer to `b` than `reach(b)` is among its listed
//! neighbours. If a query point `q` is at distance `d` from `b` and `2d ≤ reach(b)`, every
//! point closer to `q` than `b` is within `2d` of `b` (triangle inequality), hence listed:
//! scanning `b`'s neighbours finds the nearest point to `q` or a closer start, and the
//! walk repeats from there until no neighbour is closer. The last point is the exact
//! nearest point; the second nearest of the scan, or `reach − d` for points outside the
//! list, bounds the distance of every other point from below. When `2d > reach` the walk
//! gives up and the caller searches the tree.

use std::num::NonZeroUsize;

use nalgebra::Point3;

use crate::cloud::{KNearest, ProcessingError};

/// Neighbours listed per point.
const K: usize = 8;

/// Steps after which a walk gives up (it ends long before on real data).
const MAX_STEPS: usize = 64;

/// The `K` nearest neighbours of every point of one view (own frame).
#[derive(Debug, Clone)]
pub(crate) struct NeighbourGraph {
    /// Point i's neighbours are `neighbours[i * K..(i + 1) * K]` (fewer are padded with
    /// i itself).
    neighbours: Vec<u32>,
    /// Every point closer than `reach[i]` to point i is listed (∞ when the view has no
    /// other point to list).
    reach: Vec<f64>,
}

/// Result of a walk: the nearest point, its squared distance, and a lower bound on the
/// distance of every other point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Walk {
    pub(crate) index: usize,
    pub(crate) sq: f64,
    pub(crate) others: f64,
}

impl NeighbourGraph {
    /// The graph of a view's points from their nearest points (at least `K + 1` per
    /// point asked of [`KNearest`], the point itself among them).
    pub(crate) fn from_nearest(nearest: &KNearest) -> Self {
        let k = nearest.k();
        Self::from_sorted((0..nearest.len()).map(|i| {
            let found = nearest.of(i);
            (found, found.len() < k)
        }))
    }

    /// The nearest points a graph of `points` needs, as [`Self::from_nearest`] takes them.
    pub(crate) fn nearest(points: &[Point3<f64>]) -> Result<KNearest, ProcessingError> {
        KNearest::of_each(
            points,
            NonZeroUsize::new(K + 1).unwrap_or(NonZeroUsize::MIN),
        )
    }

    /// The graph from each point's nearest points, nearest first, as `(index, squared
    /// distance)` (the point itself among them), and whether the list holds every point of
    /// the view; otherwise every point closer than its last one must be in it. At most
    /// `K + 1` entries of each list are used.
    pub(crate) fn from_sorted<'a>(
        lists: impl IntoIterator<Item = (&'a [(u32, f64)], bool)>,
    ) -> Self {
        let lists = lists.into_iter();
        let mut neighbours = Vec::with_capacity(lists.size_hint().0 * K);
        let mut reach = Vec::with_capacity(lists.size_hint().0);
        for (i, (found, complete)) in lists.enumerate() {
            let complete = complete && found.len() <= K + 1;
            let found = &found[..found.len().min(K + 1)];
            // Every point closer than the farthest found one was found.
            let r = match found.last() {
                Some(&(_, sq)) if !complete => sq.sqrt(),
                _ => f64::INFINITY,
            };
            let start = neighbours.len();
            neighbours.extend(
                found
                    .iter()
                    .map(|&(j, _)| j)
                    .filter(|&j| j as usize != i)
                    .take(K),
            );
            neighbours.resize(start + K, i as u32);
            reach.push(r);
        }
        Self { neighbours, reach }
    }

    /// The exact nearest point to `q` by a walk from point `start`, or `None` if the
    /// listed neighbours cannot prove it.
    #[inline]
    pub(crate) fn walk(
        &self,
        points: &[Point3<f64>],
        q: &Point3<f64>,
        start: usize,
    ) -> Option<Walk> {
        let mut best = start;
        let mut best_sq = (q - points[start]).norm_squared();
        for _ in 0..MAX_STEPS {
            let reach = self.reach[best];
            if 4.0 * best_sq > reach * reach {
                return None;
            }
            let mut next = best;
            let mut next_sq = best_sq;
            let mut second_sq = f64::INFINITY;
            for &c in &self.neighbours[best * K..(best + 1) * K] {
                let c = c as usize;
                if c == best {
                    continue;
                }
                let sq = (q - points[c]).norm_squared();
                if sq < next_sq || (sq == next_sq && c < next) {
                    second_sq = second_sq.min(next_sq);
                    next = c;
                    next_sq = sq;
                } else {
                    second_sq = second_sq.min(sq);
                }
            }
            if next == best {
                let d = best_sq.sqrt();
                return Some(Walk {
                    index: best,
                    sq: best_sq,
                    others: second_sq.sqrt().min(reach - d),
                });
            }
            best = next;
            best_sq = next_sq;
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn build(points: &[Point3<f64>]) -> NeighbourGraph {
        NeighbourGraph::from_nearest(&NeighbourGraph::nearest(points).unwrap())
    }

    proptest! {
        /// A walk that succeeds finds the brute-force nearest point, and its bound holds
        /// for every other point — on the graph of its `K + 1` nearest points, and on one made from
        /// lists of any length `k` (as the MAP's views make it from their surfels'
        /// neighbours).
        #[test]
        fn walk_is_exact(
            coords in prop::collection::vec(prop::array::uniform3(-1.0f64..1.0), 2..60),
            q in prop::array::uniform3(-1.2f64..1.2),
            start in 0usize..60,
            k in 1usize..20,
            from_lists in any::<bool>(),
        ) {
            let points: Vec<Point3<f64>> = coords.iter().map(|c| Point3::from(*c)).collect();
            let graph = if from_lists {
                let lists: Vec<(Vec<(u32, f64)>, bool)> = points.iter().map(|p| {
                    let mut all: Vec<(u32, f64)> = points
                        .iter()
                        .enumerate()
                        .map(|(j, o)| (j as u32, (o - p).norm_squared()))
                        .collect();
                    all.sort_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)));
                    let complete = k >= all.len();
                    all.truncate(k);
                    (all, complete)
                }).collect();
                NeighbourGraph::from_sorted(lists.iter().map(|(l, c)| (l.as_slice(), *c)))
            } else {
                build(&points)
            };
            let q = Point3::from(q);
            let start = start % points.len();
            if let Some(w) = graph.walk(&points, &q, start) {
                let sq: Vec<f64> = points.iter().map(|p| (q - p).norm_squared()).collect();
                let min = sq.iter().copied().fold(f64::INFINITY, f64::min);
                prop_assert_eq!(w.sq, min);
                prop_assert_eq!(sq[w.index], min);
                for (i, s) in sq.iter().enumerate() {
                    if i != w.index {
                        prop_assert!(s.sqrt() >= w.others - 1e-12, "{} < {}", s.sqrt(), w.others);
                    }
                }
            }
        }
    }

    #[test]
    fn walks_along_a_line() {
        // Points every 1 cm on a line, each listing the 4 on either side (reach 4 cm): a
        // walk to a query near x = 0.2 succeeds from 1.1 cm away, not from 2.1 cm or 20 cm.
        let points: Vec<_> = (0..40)
            .map(|i| Point3::new(i as f64 * 0.01, 0.0, 0.0))
            .collect();
        let graph = build(&points);
        let q = Point3::new(0.2012, 0.001, 0.0);
        let w = graph.walk(&points, &q, 19).unwrap();
        assert_eq!(w.index, 20);
        assert!((w.others - (q - points[21]).norm()).abs() < 1e-15);
        assert!(graph.walk(&points, &q, 18).is_none());
        assert!(graph.walk(&points, &q, 0).is_none());
        // A view too small to fill the list: every point is listed, the reach is infinite.
        let few = &points[..3];
        let small = build(few);
        assert_eq!(
            small
                .walk(few, &Point3::new(5.0, 0.0, 0.0), 0)
                .unwrap()
                .index,
            2
        );
    }
}
