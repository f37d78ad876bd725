//! [`PairNearest`]: the nearest target point of every used source point of one pair of
//! the MAP registration, kept from one evaluation of the data term to the next in a
//! [`NearestCache`] (crate::registration::nearest_cache::NearestCache). Levenberg–Marquardt moves the
//! views by less and less, so most answers are proved unchanged without a k-d tree
//! search, while every answer stays the one a fresh search would give: the objective is
//! still a function of the poses alone.

use nalgebra::Point3;

use super::terms::Pair;
use super::view::MapView;
use crate::math::Pose;
use crate::registration::nearest_cache::{NearestCache, UpdateChunk};

/// One pair's used source points (source frame) and their nearest target points.
#[derive(Clone)]
pub(crate) struct PairNearest {
    points: Vec<Point3<f64>>,
    cache: NearestCache,
}

impl PairNearest {
    /// The cache of `pair`'s used source points, exact within `radius`.
    pub(crate) fn new(views: &[MapView], pair: &Pair, radius: f64) -> Self {
        let points: Vec<Point3<f64>> = views[pair.source]
            .tree
            .points()
            .iter()
            .step_by(pair.stride)
            .copied()
            .collect();
        let cache = NearestCache::new(points.len(), radius);
        Self { points, cache }
    }

    /// Answers within `radius` from now on, if it is at most the cache's own
    /// ([`NearestCache::shrink_to`]); `false` otherwise.
    pub(crate) fn shrink_to(&mut self, radius: f64) -> bool {
        self.cache.shrink_to(radius)
    }
}

/// The work items that bring every pair's answers up to date for the poses `poses` (view
/// → world), each with its pair's index, pairs and chunks in order; run them in any order
/// on any thread (each entry is independent: the same answers at any thread count). The
/// points a pair's mask leaves out are skipped: the data term does not read them, and
/// they are brought up to date when the mask is lifted.
pub(crate) fn begin_update<'a>(
    nearest: &'a mut [PairNearest],
    views: &'a [MapView],
    pairs: &'a [Pair],
    poses: &[Pose],
) -> Vec<(usize, UpdateChunk<'a>)> {
    nearest
        .iter_mut()
        .zip(pairs)
        .enumerate()
        .flat_map(|(p, (n, pair))| {
            let to_target = poses[pair.target].inverse() * poses[pair.source];
            n.cache
                .begin_update(
                    &n.points,
                    &views[pair.target].tree,
                    to_target,
                    pair.mask.as_deref(),
                )
                .into_iter()
                .map(move |chunk| (p, chunk))
        })
        .collect()
}
