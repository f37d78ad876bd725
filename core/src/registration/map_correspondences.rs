//! [`PairNearest`]: the nearest target point of every used source point of one pair of
//! the MAP registration, kept from one evaluation of the data term to the next in a
//! [`NearestCache`] (super::nearest_cache::NearestCache). Levenberg–Marquardt moves the
//! views by less and less, so most answers are proved unchanged without a k-d tree
//! search, while every answer stays the one a fresh search would give: the objective is
//! still a function of the poses alone.

use nalgebra::Point3;
use rayon::prelude::*;

use super::map_terms::Pair;
use super::map_view::MapView;
use super::nearest_cache::{Nearest, NearestCache};
use crate::math::Pose;

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

    /// Per used source point (by used index), its nearest target point.
    pub(crate) fn entries(&self) -> &[Nearest] {
        self.cache.entries()
    }
}

/// Brings every pair's answers up to date for the poses `poses` (view → world), all pairs'
/// work items in parallel (each entry is independent: the same answers at any thread
/// count). The points a pair's mask leaves out are skipped: the data term does not read
/// them, and they are brought up to date when the mask is lifted.
pub(crate) fn update(
    nearest: &mut [PairNearest],
    views: &[MapView],
    pairs: &[Pair],
    poses: &[Pose],
) {
    let chunks: Vec<_> = nearest
        .iter_mut()
        .zip(pairs)
        .flat_map(|(n, pair)| {
            let to_target = poses[pair.target].inverse() * poses[pair.source];
            n.cache.begin_update(
                &n.points,
                &views[pair.target].tree,
                to_target,
                pair.mask.as_deref(),
            )
        })
        .collect();
    chunks.into_par_iter().for_each(|c| {
        c.run();
    });
}
