//! Mutual nearest neighbours between every pair of views (Figure 4, lines 3–16): point `p`
//! of view i and point `q` of view j (i < j) are linked when `q` is the nearest point of
//! view j to `p`, lies within `d_max`, and `p` is the nearest point of view i to `q`, all
//! at the current pose estimates.
//!
//! [`MutualSearch`] keeps, for every ordered pair of views (i, j), the nearest point of
//! view j to each point of view i ([`NearestCache`]: exact answers, searched again only
//! where the poses moved enough to change them), so the mutual test is a lookup in both
//! directions. Points are numbered globally (view 0 first); [`ViewLayout`] maps between
//! global ids and (view, index). The graph comes out as a partner table (each point's
//! mutual nearest neighbour in every other view), each row written by the work item of
//! its own point: updates and rows run in parallel over fixed chunks of points, and the
//! table is the same at any thread count.

use rayon::prelude::*;

use crate::math::Pose;
use crate::registration::nearest_cache::{CHUNK, NONE, NearestCache};
use crate::registration::view_tree::ViewTree;

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

/// Mutual nearest neighbours of a fixed set of views at changing poses.
pub(crate) struct MutualSearch {
    /// `caches[i * w + j]`: nearest point of view j to each point of view i (i ≠ j; the
    /// diagonal is empty).
    caches: Vec<NearestCache>,
    d_max: f64,
}

impl MutualSearch {
    /// A search over views with the given trees, linking points within `d_max`.
    pub(crate) fn new(trees: &[ViewTree], d_max: f64) -> Self {
        let w = trees.len();
        let caches = (0..w * w)
            .map(|k| {
                let (i, j) = (k / w, k % w);
                let n = if i == j { 0 } else { trees[i].points().len() };
                NearestCache::new(n, d_max)
            })
            .collect();
        Self { caches, d_max }
    }

    /// The mutual-nearest-neighbour graph within `d_max`, with view v at pose `poses[v]`
    /// (view frame → common frame), as a partner table: `partners[u * w + k]` is the
    /// global id of point u's mutual nearest neighbour in view k, or [`NONE`]. Rows are
    /// filled in parallel, each from its own point's cached answers; a pair (a in view i,
    /// b in view j, i < j) is linked when b is a's nearest point of view j within `d_max`
    /// and a is b's nearest point of view i, and both rows test exactly that, so the table
    /// is symmetric.
    pub(crate) fn partners(
        &mut self,
        trees: &[ViewTree],
        poses: &[Pose],
        layout: &ViewLayout,
    ) -> Vec<u32> {
        let w = trees.len();
        let inverse: Vec<Pose> = poses.iter().map(Pose::inverse).collect();
        let work: Vec<_> = self
            .caches
            .iter_mut()
            .enumerate()
            .filter(|(k, _)| k / w != k % w)
            .flat_map(|(k, cache)| {
                let (i, j) = (k / w, k % w);
                cache.begin_update(trees[i].points(), &trees[j], inverse[j] * poses[i], None)
            })
            .collect();
        work.into_par_iter().for_each(|chunk| {
            chunk.run();
        });
        let d_max = self.d_max;
        let caches = &self.caches;
        let mut partners = vec![NONE; layout.total() * w];
        // Work items: (view, first point, that chunk's rows).
        let mut items = Vec::new();
        let mut rest = partners.as_mut_slice();
        for (i, tree) in trees.iter().enumerate() {
            let (rows, tail) = rest.split_at_mut(tree.points().len() * w);
            rest = tail;
            items.extend(
                rows.chunks_mut(CHUNK * w)
                    .enumerate()
                    .map(|(c, rows)| (i, c * CHUNK, rows)),
            );
        }
        items.into_par_iter().for_each(|(i, start, rows)| {
            for (k, row) in rows.chunks_mut(w).enumerate() {
                let a = start + k;
                for (j, slot) in row.iter_mut().enumerate() {
                    let to_j = caches[i * w + j].entries();
                    let from_j = caches[j * w + i].entries();
                    let partner = match j.cmp(&i) {
                        std::cmp::Ordering::Equal => None,
                        std::cmp::Ordering::Greater => to_j[a]
                            .within(d_max)
                            .map(|(b, _)| b)
                            .filter(|&b| from_j[b].index as usize == a),
                        std::cmp::Ordering::Less => Some(to_j[a].index)
                            .filter(|&b| b != NONE)
                            .map(|b| b as usize)
                            .filter(|&b| from_j[b].within(d_max).is_some_and(|(x, _)| x == a)),
                    };
                    if let Some(b) = partner {
                        *slot = layout.global(j, b) as u32;
                    }
                }
            }
        });
        partners
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Point3, Vector3};

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
        let mut search = MutualSearch::new(&trees, 0.5);
        // Rows: ids 0..3 (view 0), 3..6 (view 1); two slots each (views 0 and 1).
        let n = NONE;
        let start = vec![n, 3, n, n, n, 5, 0, n, n, n, 2, n];
        assert_eq!(search.partners(&trees, &id, &layout), start);
        // Moving view 1 by +1 m in x at its pose: 1.1 <-> 1, 1.2 rejected, 3.05 too far.
        let moved = [Pose::identity(), Pose::translation(1.0, 0.0, 0.0)];
        let linked = vec![n, n, n, 3, n, n, 1, n, n, n, n, n];
        assert_eq!(search.partners(&trees, &moved, &layout), linked);
        let far = [
            Pose::identity(),
            Pose::new(Vector3::new(9.0, 0.0, 0.0), Vector3::zeros()),
        ];
        assert!(
            search
                .partners(&trees, &far, &layout)
                .iter()
                .all(|&p| p == n)
        );
        // Back at the start, with the cache warm: the same answer as a fresh search.
        assert_eq!(search.partners(&trees, &id, &layout), start);
    }
}
