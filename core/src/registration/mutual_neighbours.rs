//! Mutual nearest neighbours between every pair of views (Figure 4, lines 3–16): point `p`
//! of view i and point `q` of view j (i < j) are linked when `q` is the nearest point of
//! view j to `p`, lies within `d_max`, and `p` is the nearest point of view i to `q`, all
//! at the current pose estimates.
//!
//! Points are numbered globally (view 0 first); [`ViewLayout`] maps between global ids and
//! (view, index). The search runs in parallel over fixed chunks of points and the chunks
//! are concatenated in order, so the edge list is the same at any thread count.

use nalgebra::Point3;
use rayon::prelude::*;

use super::view_tree::ViewTree;
use crate::math::Pose;

/// Points per parallel work item.
const CHUNK: usize = 256;

/// Global numbering of the points of several views.
#[derive(Debug, Clone)]
pub(crate) struct ViewLayout {
    /// `offsets[v]` is the global id of view v's first point; `offsets[w]` the total.
    offsets: Vec<usize>,
}

impl ViewLayout {
    /// Layout for views of the given sizes.
    pub(crate) fn new(sizes: impl IntoIterator<Item = usize>) -> Self {
        let mut offsets = vec![0];
        let mut total = 0;
        for n in sizes {
            total += n;
            offsets.push(total);
        }
        Self { offsets }
    }

    /// Number of views.
    pub(crate) fn views(&self) -> usize {
        self.offsets.len() - 1
    }

    /// Total number of points.
    pub(crate) fn total(&self) -> usize {
        self.offsets[self.views()]
    }

    /// Global id of point `index` of `view`.
    pub(crate) fn global(&self, view: usize, index: usize) -> usize {
        self.offsets[view] + index
    }

    /// View and local index of a global id (`id < total()`).
    pub(crate) fn local(&self, id: usize) -> (usize, usize) {
        // The first offset greater than id, minus one, is the view.
        let view = self.offsets.partition_point(|&o| o <= id) - 1;
        (view, id - self.offsets[view])
    }
}

/// All mutual-nearest-neighbour pairs `[a, b]` (global ids, view(a) < view(b)) within
/// `d_max`, with view v at pose `poses[v]` (view frame → common frame). Ordered by `a`,
/// then by the view of `b`.
pub(crate) fn mutual_edges(
    trees: &[ViewTree],
    poses: &[Pose],
    layout: &ViewLayout,
    d_max: f64,
) -> Vec<[u32; 2]> {
    let w = trees.len();
    // rel[j * w + i] maps view i's frame into view j's frame.
    let rel: Vec<Pose> = (0..w * w)
        .map(|k| poses[k / w].inverse() * poses[k % w])
        .collect();
    let work: Vec<(usize, usize)> = (0..w)
        .flat_map(|i| {
            let n = trees[i].points().len();
            (0..n.div_ceil(CHUNK)).map(move |c| (i, c * CHUNK))
        })
        .collect();
    let search = PairSearch {
        trees,
        rel: &rel,
        d_max,
    };
    let chunks: Vec<Vec<[u32; 2]>> = work
        .par_iter()
        .map(|&(i, start)| {
            let points = trees[i].points();
            let end = (start + CHUNK).min(points.len());
            let mut edges = Vec::new();
            for (a, p) in points[start..end].iter().enumerate() {
                let a = start + a;
                for j in i + 1..w {
                    if let Some(b) = search.partner(i, a, p, j) {
                        edges.push([layout.global(i, a) as u32, layout.global(j, b) as u32]);
                    }
                }
            }
            edges
        })
        .collect();
    chunks.concat()
}

/// The trees and relative poses of one search.
struct PairSearch<'a> {
    trees: &'a [ViewTree],
    /// `rel[j * w + i]` maps view i's frame into view j's frame.
    rel: &'a [Pose],
    d_max: f64,
}

impl PairSearch<'_> {
    /// The point of view j that is the mutual nearest neighbour of point `a` (at `p`) of
    /// view i within `d_max`, if any.
    #[inline]
    fn partner(&self, i: usize, a: usize, p: &Point3<f64>, j: usize) -> Option<usize> {
        let w = self.trees.len();
        let q = self.rel[j * w + i] * p;
        // Outside view j's bounding box by more than d_max: nothing there is close enough.
        if !self.trees[j].near_bounds(&q, self.d_max) {
            return None;
        }
        let (b, d_sq) = self.trees[j].nearest(&q);
        if d_sq >= self.d_max * self.d_max {
            return None;
        }
        let back = self.rel[i * w + j] * self.trees[j].points()[b];
        let (a_back, _) = self.trees[i].nearest(&back);
        (a_back == a).then_some(b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;

    #[test]
    fn layout_round_trips() {
        let l = ViewLayout::new([3, 0, 2]);
        assert_eq!(l.total(), 5);
        assert_eq!(l.views(), 3);
        for id in 0..5 {
            let (v, i) = l.local(id);
            assert_eq!(l.global(v, i), id);
        }
        assert_eq!(l.local(3), (2, 0));
    }

    #[test]
    fn finds_mutual_pairs_only() {
        // View 0: points at x = 0, 1, 2. View 1: x = 0.1, 0.2, 2.05 (poses identity).
        // 0 <-> 0.1 is mutual; 0.2's nearest is 0.1's partner 0, but 0's nearest is 0.1:
        // not mutual. 1's nearest in view 1 is 0.2 (0.8 away > d_max 0.5): rejected.
        let v0: Vec<_> = [0.0, 1.0, 2.0].map(|x| Point3::new(x, 0.0, 0.0)).into();
        let v1: Vec<_> = [0.1, 0.2, 2.05].map(|x| Point3::new(x, 0.0, 0.0)).into();
        let trees = vec![
            ViewTree::build(0, &v0).unwrap(),
            ViewTree::build(1, &v1).unwrap(),
        ];
        let layout = ViewLayout::new([3, 3]);
        let id = [Pose::identity(), Pose::identity()];
        assert_eq!(
            mutual_edges(&trees, &id, &layout, 0.5),
            vec![[0, 3], [2, 5]]
        );
        // Moving view 1 by +1 m in x at its pose: 1.1 <-> 1, 1.2 rejected, 3.05 too far.
        let moved = [Pose::identity(), Pose::translation(1.0, 0.0, 0.0)];
        assert_eq!(mutual_edges(&trees, &moved, &layout, 0.5), vec![[1, 3]]);
        let far = [
            Pose::identity(),
            Pose::new(Vector3::new(9.0, 0.0, 0.0), Vector3::zeros()),
        ];
        assert!(mutual_edges(&trees, &far, &layout, 0.5).is_empty());
    }
}
