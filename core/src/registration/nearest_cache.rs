//! [`NearestCache`]: the nearest point of a target view to every point of a query view,
//! kept from one iteration to the next and searched again only where the answer may have
//! changed. Iterative registration moves the views by less and less, so after the first
//! iterations almost every k-d tree query is skipped, while every answer stays exactly the
//! one a fresh query would give.
//!
//! Each entry remembers, for the query position `q₀` at which it was last searched (kept
//! as a stamp: the query-to-target pose of that iteration), the nearest point `b`, an
//! upper bound `d₁` on its distance and a lower bound `d₂` on the distance of every other
//! point (the second nearest). At the new position `q`, with `δ = |q − q₀|`, every other
//! point is at least `d₂ − δ` away and `b` at most `d₁ + δ`; so
//! - if `d₁ + δ < d₂ − δ`, `b` is still the unique nearest point;
//! - if `d₂ − δ > r` (the search radius), no point but `b` can lie within `r`: if `b`
//!   does, it is the nearest point, and otherwise no point is within `r`;
//! - if `d₁ − δ > r`, with `d₁` the nearest distance (or, for an entry that found no
//!   point within `2r`, a lower bound on every distance), no point lies within `r`.
//!
//! Otherwise the answer is repaired by a walk on the target's [`NeighbourGraph`]
//! (super::neighbour_graph::NeighbourGraph) from the previous nearest point (or the
//! previous query point's) when the target has one and the walk can prove its result, else
//! searched again: first the distance to the target's bounding box, which may rule every
//! point out, then the two nearest points within `2r` in the tree. All tests
//! keep a margin for rounding, so the cache answers exactly as fresh searches do: the
//! nearest point whenever one lies within `r` (and its squared distance at `q`), no point
//! otherwise. Entries are independent, so updating them in parallel chunks gives the same
//! result at any thread count.

use nalgebra::{Matrix3, Point3, Vector3};
use rayon::prelude::*;

use super::view_tree::ViewTree;
use crate::math::Pose;

/// Index meaning "no point".
pub(crate) const NONE: u32 = u32::MAX;

/// Query points per parallel work item.
pub(crate) const CHUNK: usize = 256;

/// Relative margin for rounding in the distance tests (of the coordinates' magnitude).
const ROUNDING: f64 = 1e-12;

/// Relative rounding of the distance bounds stored as f32 (2⁻²³, with room to spare).
const F32_ROUNDING: f64 = 1e-6;

/// One query point's nearest target point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Nearest {
    /// Squared distance to the nearest point at the current position (∞ with [`NONE`], or
    /// when it is known to lie beyond the radius).
    pub(crate) sq: f64,
    /// Index of the nearest target point, or [`NONE`] if no point lies within the radius.
    pub(crate) index: u32,
    /// Stamp of the position of the last search.
    stamp: u32,
    /// Upper bound on the nearest distance at that position; with [`NONE`], a lower bound
    /// on every distance.
    d1: f32,
    /// Lower bound on the distance of every other point at that position.
    d2: f32,
}

impl Nearest {
    /// An entry that has never been searched.
    const UNKNOWN: Self = Self {
        index: NONE,
        sq: f64::INFINITY,
        stamp: u32::MAX,
        d1: 0.0,
        d2: 0.0,
    };

    /// The nearest point and its squared distance, if it lies strictly within `radius`.
    #[inline]
    pub(crate) fn within(&self, radius: f64) -> Option<(usize, f64)> {
        (self.index != NONE && self.sq < radius * radius).then_some((self.index as usize, self.sq))
    }
}

/// Nearest target points of all the points of one query view.
#[derive(Debug, Clone)]
pub(crate) struct NearestCache {
    entries: Vec<Nearest>,
    /// Query-to-target pose of each update, indexed by stamp.
    stamps: Vec<Pose>,
    /// Per stamp, the change of the pose's rotation matrix and translation since then
    /// (refreshed by each update).
    deltas: Vec<(Matrix3<f64>, Vector3<f64>)>,
    /// Search radius `r`.
    radius: f64,
    /// k-d tree searches made by the updates so far (walks not counted).
    searches: usize,
}

impl NearestCache {
    /// A cache for `n` query points, exact within `radius`.
    pub(crate) fn new(n: usize, radius: f64) -> Self {
        Self {
            entries: vec![Nearest::UNKNOWN; n],
            stamps: Vec::new(),
            deltas: Vec::new(),
            radius,
            searches: 0,
        }
    }

    /// Makes the cache answer within `radius` from now on, if that is at most its own:
    /// every entry's bounds hold whatever the radius, and the nearest point within a
    /// larger radius is the nearest within a smaller one when it lies there, so the
    /// answers stay exact. A larger radius is refused (`false`): the cache never looked
    /// that far.
    pub(crate) fn shrink_to(&mut self, radius: f64) -> bool {
        if radius > self.radius {
            return false;
        }
        self.radius = radius;
        true
    }

    /// The entries, in query-point order.
    pub(crate) fn entries(&self) -> &[Nearest] {
        &self.entries
    }

    /// k-d tree searches made so far.
    #[cfg(test)]
    pub(crate) fn searches(&self) -> usize {
        self.searches
    }

    /// Records the pose of a new update (query frame → target frame) and splits the
    /// entries into work items, to be run in any order on any thread. With `only`, the
    /// entries not flagged in it are skipped: they keep their last answer, which the next
    /// update that includes them brings up to date from the stamp it was found at.
    pub(crate) fn begin_update<'a>(
        &'a mut self,
        points: &'a [Point3<f64>],
        target: &'a ViewTree,
        pose: Pose,
        only: Option<&'a [bool]>,
    ) -> Vec<UpdateChunk<'a>> {
        if self.stamps.len() >= (u32::MAX - 1) as usize {
            // Out of stamps (never in practice): forget everything, search afresh.
            self.stamps.clear();
            self.entries.fill(Nearest::UNKNOWN);
        }
        self.stamps.push(pose);
        let stamp = (self.stamps.len() - 1) as u32;
        // q = R p + t now, and q − q₀ = (R − R₀) p + (t − t₀) for the pose of each stamp.
        let (rotation, translation) = matrix(&pose);
        self.deltas.clear();
        self.deltas.extend(self.stamps.iter().map(|old| {
            let (r0, t0) = matrix(old);
            (rotation - r0, translation - t0)
        }));
        let context = UpdateContext {
            points,
            target,
            rotation,
            translation,
            deltas: &self.deltas,
            stamp,
            radius: self.radius,
        };
        self.entries
            .chunks_mut(CHUNK)
            .enumerate()
            .map(|(c, entries)| UpdateChunk {
                only: only.map(|m| &m[c * CHUNK..c * CHUNK + entries.len()]),
                entries,
                start: c * CHUNK,
                context,
            })
            .collect()
    }

    /// Updates every entry for query points `points` (own frame) mapped into the target's
    /// frame by `pose` (in parallel over chunks).
    pub(crate) fn update(&mut self, points: &[Point3<f64>], target: &ViewTree, pose: Pose) {
        let searches: usize = self
            .begin_update(points, target, pose, None)
            .into_par_iter()
            .map(UpdateChunk::run)
            .sum();
        self.searches += searches;
    }
}

/// Rotation matrix and translation of a pose.
pub(crate) fn matrix(pose: &Pose) -> (Matrix3<f64>, Vector3<f64>) {
    (
        pose.rotation.to_rotation_matrix().into_inner(),
        pose.translation.vector,
    )
}

/// What every work item of one update shares.
#[derive(Clone, Copy)]
struct UpdateContext<'a> {
    points: &'a [Point3<f64>],
    target: &'a ViewTree,
    /// The current pose as a matrix and a translation.
    rotation: Matrix3<f64>,
    translation: Vector3<f64>,
    /// Pose changes since each stamp.
    deltas: &'a [(Matrix3<f64>, Vector3<f64>)],
    stamp: u32,
    radius: f64,
}

/// A chunk of entries to update; run it on any thread.
pub(crate) struct UpdateChunk<'a> {
    entries: &'a mut [Nearest],
    /// Which of the entries to update (all if `None`).
    only: Option<&'a [bool]>,
    start: usize,
    context: UpdateContext<'a>,
}

/// A chunk's entries once brought up to date.
pub(crate) struct Updated<'a> {
    /// The entries, up to date.
    pub(crate) entries: &'a [Nearest],
    /// Index of the first of them in the cache.
    pub(crate) start: usize,
    /// k-d tree searches made.
    pub(crate) searches: usize,
}

impl<'a> UpdateChunk<'a> {
    /// Brings the chunk's entries up to date; returns the number of k-d tree searches.
    pub(crate) fn run(self) -> usize {
        self.run_and_read().searches
    }

    /// Brings the chunk's entries up to date and hands them back, to be read at once on
    /// the same thread.
    pub(crate) fn run_and_read(self) -> Updated<'a> {
        let UpdateContext {
            points,
            target,
            rotation,
            translation,
            deltas,
            stamp,
            radius,
        } = self.context;
        let scale = target.scale();
        let mut searches = 0;
        // The previous point's nearest point: a start for walks of fresh entries, since
        // neighbouring query points (scan order) have neighbouring answers.
        let mut hint = None;
        for (k, entry) in self.entries.iter_mut().enumerate() {
            if self.only.is_some_and(|m| !m[k]) {
                continue;
            }
            let p = &points[self.start + k].coords;
            let q = Point3::from(rotation * p + translation);
            let margin = ROUNDING * (1.0 + scale + q.coords.amax());
            let mut start = hint;
            if entry.stamp != u32::MAX {
                let (dr, dt) = &deltas[entry.stamp as usize];
                let delta = (dr * p + dt).norm() + margin;
                let (d1, d2) = (f64::from(entry.d1), f64::from(entry.d2));
                if entry.index == NONE {
                    if d1 - delta > radius + margin {
                        continue;
                    }
                } else if d1 * (1.0 - F32_ROUNDING) - delta > radius + margin {
                    // Even the nearest point is beyond the radius.
                    entry.sq = f64::INFINITY;
                    continue;
                } else if d1 + delta < d2 - delta || d2 - delta > radius + margin {
                    entry.sq = (q - target.points()[entry.index as usize]).norm_squared();
                    hint = Some(entry.index as usize);
                    continue;
                } else {
                    start = Some(entry.index as usize);
                }
            }
            let walk = target
                .graph()
                .zip(start)
                .and_then(|(g, s)| g.walk(target.points(), &q, s));
            *entry = match walk {
                Some(w) => Nearest {
                    index: w.index as u32,
                    sq: w.sq,
                    stamp,
                    d1: round_up(w.sq.sqrt() + margin),
                    d2: round_down((w.others - margin).max(0.0)),
                },
                None => {
                    searches += 1;
                    search(target, &q, radius, stamp)
                }
            };
            if entry.index != NONE {
                hint = Some(entry.index as usize);
            }
        }
        Updated {
            entries: self.entries,
            start: self.start,
            searches,
        }
    }
}

/// A fresh entry for query position `q`.
fn search(target: &ViewTree, q: &Point3<f64>, radius: f64, stamp: u32) -> Nearest {
    let reach = 2.0 * radius;
    let empty = |bound: f64| Nearest {
        index: NONE,
        sq: f64::INFINITY,
        stamp,
        d1: round_down(bound),
        d2: 0.0,
    };
    let box_distance = target.distance_to_bounds(q);
    if box_distance > reach {
        return empty(box_distance);
    }
    match target.nearest_two_within(q, reach) {
        (None, _) => empty(reach),
        (Some(b), second) => {
            let sq = (q - target.points()[b]).norm_squared();
            Nearest {
                index: b as u32,
                sq,
                stamp,
                d1: round_up(sq.sqrt()),
                d2: round_down(second.unwrap_or(reach)),
            }
        }
    }
}

/// The smallest f32 at least `x` (x ≥ 0).
fn round_up(x: f64) -> f32 {
    let y = x as f32;
    if f64::from(y) < x { y.next_up() } else { y }
}

/// The largest f32 at most `x` (x ≥ 0).
fn round_down(x: f64) -> f32 {
    let y = x as f32;
    if f64::from(y) > x { y.next_down() } else { y }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;
    use proptest::prelude::*;

    /// Exact nearest point by brute force, if within `radius`.
    fn brute(points: &[Point3<f64>], q: &Point3<f64>, radius: f64) -> Option<usize> {
        let (b, sq) = points
            .iter()
            .enumerate()
            .map(|(i, p)| (i, (q - p).norm_squared()))
            .min_by(|x, y| x.1.total_cmp(&y.1))?;
        (sq < radius * radius).then_some(b)
    }

    fn cloud(seed: &[f64]) -> Vec<Point3<f64>> {
        // A wavy sheet with jitter from the seed values.
        (0..300)
            .map(|i| {
                let (x, y) = ((i % 20) as f64 * 0.004, (i / 20) as f64 * 0.004);
                let j = seed[i % seed.len()];
                Point3::new(
                    x + 0.001 * j,
                    y - 0.0007 * j,
                    0.01 * (50.0 * x).sin() + 0.0003 * j,
                )
            })
            .collect()
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(48))]
        /// Along any sequence of poses the cache answers as brute force does, with or
        /// without the target's neighbour graph, also after updates that skipped some of
        /// its entries (which keep their answers meanwhile).
        #[test]
        fn matches_brute_force_along_a_path(
            seed in prop::collection::vec(-1.0f64..1.0, 7..13),
            steps in prop::collection::vec(
                (prop::array::uniform3(-1.0f64..1.0), prop::array::uniform3(-1.0f64..1.0)),
                1..12,
            ),
            scale in prop::sample::select(vec![1e-6, 1e-4, 1e-3, 1e-2]),
            graph: bool,
            only in prop::collection::vec(any::<bool>(), 300),
            masked in prop::collection::vec(any::<bool>(), 12),
            shrink_at in 0usize..16,
        ) {
            let target_points = cloud(&seed);
            let query: Vec<_> = target_points.iter().map(|p| p + Vector3::new(0.0011, 0.0, 0.0)).collect();
            let target = if graph {
                ViewTree::build_with_graph(0, &target_points).unwrap()
            } else {
                ViewTree::build(0, &target_points).unwrap()
            };
            let mut radius = 0.003;
            let mut cache = NearestCache::new(query.len(), radius);
            let mut pose = Pose::identity();
            for (step, (t, r)) in steps.into_iter().enumerate() {
                // From some step on (or never), the cache answers within half its radius.
                if step == shrink_at {
                    radius = 0.0015;
                    prop_assert!(cache.shrink_to(radius));
                    prop_assert!(!cache.shrink_to(0.003));
                }
                pose = Pose::new(Vector3::from(t) * scale, Vector3::from(r) * scale * 5.0) * pose;
                // Some updates bring only the entries flagged in `only` up to date: the
                // others must keep their answers, and be exact again once updated.
                let before = cache.entries().to_vec();
                let mask = masked[step].then_some(&only[..]);
                if let Some(mask) = mask {
                    for chunk in cache.begin_update(&query, &target, pose, Some(mask)) {
                        chunk.run();
                    }
                } else {
                    cache.update(&query, &target, pose);
                }
                for (a, p) in query.iter().enumerate() {
                    if mask.is_some_and(|m| !m[a]) {
                        prop_assert_eq!(cache.entries()[a], before[a], "skipped point {}", a);
                        continue;
                    }
                    let q = pose * p;
                    let got = cache.entries()[a].within(radius).map(|(b, _)| b);
                    prop_assert_eq!(got, brute(&target_points, &q, radius), "point {}", a);
                    if let Some((b, sq)) = cache.entries()[a].within(radius) {
                        let exact = (q - target_points[b]).norm_squared();
                        // The cache and the check reach the squared distance by different roundings.
                        prop_assert!((sq - exact).abs() <= 1e-9 * exact, "{} vs {}", sq, exact);
                    }
                }
            }
        }
    }

    #[test]
    fn small_steps_skip_searches() {
        let target_points = cloud(&[0.3, -0.2, 0.7, 0.1, -0.9]);
        let target = ViewTree::build(0, &target_points).unwrap();
        let mut cache = NearestCache::new(target_points.len(), 0.003);
        cache.update(&target_points, &target, Pose::identity());
        assert_eq!(cache.searches(), target_points.len());
        cache.update(&target_points, &target, Pose::translation(1e-6, 0.0, 0.0));
        assert!(
            cache.searches() < target_points.len() + 5,
            "{}",
            cache.searches()
        );
        // Far away: the bounding box rules every point out without a tree search.
        let mut far = NearestCache::new(target_points.len(), 0.003);
        far.update(&target_points, &target, Pose::translation(1.0, 0.0, 0.0));
        assert!(far.entries().iter().all(|e| e.within(0.003).is_none()));
    }
}
