//! The object loop of Algorithm 1 for one object: candidates around what is seen of it,
//! each tried in order (plan, execute — the next one on failure), the first reached
//! acquired and the grid updated, until the stop rule, the view cap, no reachable
//! viewpoint (after one retreat) or a first view showing no object ends it.

use super::acquire_and_update::{REGION_REACH, acquire_and_update, object_view};
use super::calibration_views::take_calibration_views;
use super::candidates::{ObjectSurface, ViewCandidates, view_candidates, viewing_centre};
use super::episode_state::Episode;
use super::plan_and_execute::{plan_clearing_start, retrace};
use super::step_timer::timed;
use super::{
    ExplorationMap, ExploreConfig, ExploreEvent, ExploreObserver, ObjectExploration, ObjectRegion,
    ObjectStop, PipelineError, ViewFailure,
};
use crate::cloud::{PlaneFit, PointCloud};
use crate::math::Pose;
use crate::nbv::{
    Candidate, InformationGain, MissedVoxels, NextBestView, StopReason, SurfaceSides, VisitedViews,
    lazy_best, movement_cost_total, new_surface_share, settle_shift,
};
use crate::planning::PlannedPath;
use crate::rig::RigError;

/// Explores `object` (its cluster in `region`, standing on `table`) until a stop; the
/// views go into `object`, the collisions into the episode, each view into `map`. Then
/// takes the `calibration(object)` views the self-calibration asks of it
/// ([`take_calibration_views`]).
pub(super) fn explore_object(
    ep: &mut Episode<'_, '_>,
    nbv: &NextBestView,
    map: &mut ExplorationMap,
    region: &ObjectRegion,
    table: Option<&PlaneFit>,
    object: &mut ObjectExploration,
    calibration: &dyn Fn(&ObjectExploration) -> usize,
) -> Result<(), PipelineError> {
    let mut state = ObjectLoop::new(ep.config, nbv, map, region, table, object)?;
    object.stop = loop {
        if let Some(stop) = stop_before_sampling(ep.config, object, state.handed_over) {
            break stop;
        }
        let candidates = state.sample(ep, map, object)?;
        if let Some(stop) = state.stop_on_candidates(ep.config, &candidates) {
            if state.hand_over(&stop, object, ep.config.stop.new_surface) {
                continue;
            }
            break stop;
        }
        match state.take_view(ep, map, object, candidates)? {
            Round::Taken => {}
            Round::NotAnObject { points } => break ObjectStop::NotAnObject { points },
            Round::NoneReached => {
                if state.retreat(ep, object)? {
                    continue;
                }
                break ObjectStop::Rule(StopReason::NoViewpoint);
            }
        }
    };
    let count = calibration(object);
    if count > 0 && !matches!(object.stop, ObjectStop::NotAnObject { .. }) {
        let candidates = state.sample(ep, map, object)?;
        take_calibration_views(ep, candidates, &state.region, table, object, count)?;
    }
    Ok(())
}

/// How a round of candidates ended.
enum Round {
    /// The arm reached a candidate and the view was acquired.
    Taken,
    /// The first view was acquired but shows too few points of the object: not an object.
    NotAnObject {
        /// Points of the first view in the object's region.
        points: usize,
    },
    /// No candidate could be reached.
    NoneReached,
}

/// The stops checked before sampling: the view cap, and the rule on the new surface each
/// view added; once the hull `handed_over` the object to eq. (4) after that many views
/// ([`HullScore::First`](crate::nbv::HullScore::First)), one view of eq. (4)'s that adds
/// less than the new-surface share ends it.
fn stop_before_sampling(
    config: &ExploreConfig,
    object: &ObjectExploration,
    handed_over: Option<usize>,
) -> Option<ObjectStop> {
    if object.views.len() >= config.max_views_per_object {
        return Some(ObjectStop::MaxViews);
    }
    let shares: Vec<f64> = object.views.iter().map(|v| v.new_surface).collect();
    if let Some(n) = handed_over
        && let Some(&share) = shares.get(n..).and_then(<[f64]>::last)
        && share < config.stop.new_surface
    {
        return Some(ObjectStop::Rule(StopReason::NoNewSurface {
            share,
            threshold: config.stop.new_surface,
            views: 1,
        }));
    }
    config.stop.check_new_surface(&shares).map(ObjectStop::Rule)
}

/// One object's exploration: what it explores with (the view planner, the object's region,
/// the table it stands on) and what the loop carries from one round of candidates to the
/// next.
struct ObjectLoop<'a> {
    /// The view planner (Algorithm 2).
    nbv: &'a NextBestView,
    /// The object's region, grown by what the views see of it past its phase-1 box (with
    /// `object_surface`).
    region: ObjectRegion,
    /// The table it stands on, if phase 1 found one.
    table: Option<&'a PlaneFit>,
    /// The viewpoints taken, which new candidates keep away from.
    visited: VisitedViews,
    /// The unknown voxels the taken views missed.
    missed: MissedVoxels,
    /// The sides of the object's voxels seen.
    sides: SurfaceSides,
    /// The information gain of the latest view (the stop rule's).
    latest_gain: Option<InformationGain>,
    /// The best score of the first round's candidates (the relative stop's reference).
    first_best: Option<f64>,
    /// Viewpoints that failed since the latest view.
    failures_since_view: usize,
    /// Plans attempted so far: each has a seed of its own.
    attempts: u64,
    /// Whether the arm has retreated since the latest view (once, then the object stops).
    retreated: bool,
    /// The views taken when the hull's stop handed the object to eq. (4)
    /// ([`HullScore::First`](crate::nbv::HullScore::First)); `None` while the hull ranks.
    handed_over: Option<usize>,
}

impl<'a> ObjectLoop<'a> {
    /// Before the first round: nothing visited or missed, the sides seen in the cluster.
    fn new(
        config: &ExploreConfig,
        nbv: &'a NextBestView,
        map: &ExplorationMap,
        region: &ObjectRegion,
        table: Option<&'a PlaneFit>,
        object: &ObjectExploration,
    ) -> Result<Self, PipelineError> {
        Ok(Self {
            nbv,
            region: *region,
            table,
            visited: VisitedViews::new(config.visited.0, config.visited.1)?,
            missed: MissedVoxels::new(1),
            sides: SurfaceSides::of_cloud(map.grid.geometry(), &object.cluster),
            latest_gain: None,
            first_best: None,
            failures_since_view: 0,
            attempts: 0,
            retreated: false,
            handed_over: None,
        })
    }

    /// Whether `stop` is the hull's stop and, by the hull score, eq. (4) takes the object
    /// over: once, and only while the object's latest view still added at least the
    /// `new_surface` share (after one that added less the object is done). The relative
    /// stop then starts again from eq. (4)'s first round.
    fn hand_over(
        &mut self,
        stop: &ObjectStop,
        object: &ObjectExploration,
        new_surface: f64,
    ) -> bool {
        let hull_stop = matches!(stop, ObjectStop::Rule(StopReason::NoUnseenHull { .. }));
        let adding = object
            .views
            .last()
            .is_some_and(|v| v.new_surface >= new_surface);
        if !(hull_stop
            && adding
            && self.nbv.params.hull_score.hands_over()
            && self.handed_over.is_none())
        {
            return false;
        }
        self.handed_over = Some(object.views.len());
        self.first_best = None;
        true
    }

    /// The round's candidates around what is seen of the object (timed as the NBV step),
    /// counted and reported.
    fn sample(
        &self,
        ep: &mut Episode<'_, '_>,
        map: &ExplorationMap,
        object: &mut ObjectExploration,
    ) -> Result<ViewCandidates, PipelineError> {
        let j = object.index;
        let candidates = timed(&mut object.times.nbv, || -> Result<_, PipelineError> {
            let centre = viewing_centre(&object.cluster, &object.views, &self.region)
                .ok_or_else(|| PipelineError::Config(format!("object {j} has no point")))?;
            // A view that added less than the new-surface share: eq. (4) ranks this
            // object's views poorly from here (`HullScore::AfterStall`).
            let stalled = object
                .views
                .iter()
                .any(|v| v.new_surface < ep.config.stop.new_surface);
            let hull = self.nbv.params.hull_score.applies(stalled) && self.handed_over.is_none();
            // What the hull score reads: everything seen of the object.
            let points: Vec<_> = if hull {
                object
                    .cluster
                    .points
                    .iter()
                    .chain(object.views.iter().flat_map(|v| &v.cloud.points))
                    .copied()
                    .collect()
            } else {
                Vec::new()
            };
            // The arm's joints only when the movement cost reads them (a device round trip).
            let start = if self.nbv.params.cost_weight > 0.0 {
                Some(ep.rig.arm.joints()?)
            } else {
                None
            };
            view_candidates(
                &ep.rig.robot,
                ep.config,
                self.nbv,
                map,
                start.as_ref(),
                &centre,
                &self.visited,
                Some(ObjectSurface {
                    region: &self.region,
                    sides: &self.sides,
                    missed: &self.missed,
                    points: &points,
                    views: &object.views,
                    stalled,
                    hull,
                }),
            )
        })?;
        let list = &candidates.list;
        object.candidates_evaluated += list.candidates.len();
        ep.observer.event(&ExploreEvent::Candidates {
            object: j,
            candidates: list.candidates.len(),
            list,
        });
        Ok(candidates)
    }

    /// The stops checked on a round's candidates: the rule on the latest gain and the
    /// number of candidates, the unseen hull the best would see (with the hull score),
    /// then the best score against the first round's.
    fn stop_on_candidates(
        &mut self,
        config: &ExploreConfig,
        candidates: &ViewCandidates,
    ) -> Option<ObjectStop> {
        let list = &candidates.list;
        if let Some(reason) = config
            .stop
            .check(self.latest_gain.as_ref(), list.candidates.len())
        {
            return Some(ObjectStop::Rule(reason));
        }
        let best = list
            .candidates
            .iter()
            .map(|c| c.score)
            .fold(f64::NEG_INFINITY, f64::max);
        if let Some(hull) = candidates.hull_area
            && self.latest_gain.is_some()
            && let Some(reason) = config.stop.check_unseen_hull(best, hull)
        {
            return Some(ObjectStop::Rule(reason));
        }
        match self.first_best {
            None => {
                self.first_best = Some(best);
                None
            }
            Some(first) => config
                .stop
                .check_relative(first, best)
                .map(ObjectStop::Rule),
        }
    }

    /// Tries the round's candidates — in ranked order, or with the movement cost the exact
    /// best by planned path length — until the arm reaches one, and acquires there.
    fn take_view(
        &mut self,
        ep: &mut Episode<'_, '_>,
        map: &mut ExplorationMap,
        object: &mut ObjectExploration,
        candidates: ViewCandidates,
    ) -> Result<Round, PipelineError> {
        let ViewCandidates {
            mut planner,
            mut list,
            ..
        } = candidates;
        // The way the arm came in is free: it moved through it.
        if let Some(way_in) = ep.trail.last() {
            planner.clear_way(&way_in.waypoints);
        }
        // The movement cost's normaliser Σc, fixed for the round (see `lazy_best`).
        let lambda = self.nbv.params.cost_weight;
        let total_cost = if lambda > 0.0 {
            movement_cost_total(&list.candidates, &ep.rig.arm.joints()?)
        } else {
            0.0
        };
        loop {
            let start = ep.rig.arm.joints()?;
            let seed_base = ep.config.seed ^ ((object.index as u64) << 32);
            let attempts = &mut self.attempts;
            // Plans to one candidate: its IK goals, a seed of its own.
            let mut plan = |candidate: &Candidate| {
                *attempts += 1;
                let seed = seed_base ^ *attempts;
                plan_clearing_start(&mut planner, &start, &candidate.viewpoint.goals(), seed)
            };
            let next = timed(&mut object.times.planning, || {
                if lambda > 0.0 {
                    lazy_best(
                        &mut list.candidates,
                        &start,
                        lambda,
                        total_cost,
                        plan,
                        |p| p.stats.length_after_shortcut,
                    )
                } else {
                    list.pop_first().map(|c| {
                        let planned = plan(&c);
                        (c, planned)
                    })
                }
            });
            let Some((candidate, planned)) = next else {
                return Ok(Round::NoneReached);
            };
            let planned = match planned {
                Ok(p) => p,
                Err(e) => {
                    self.record_failure(ep, object, &candidate, e.to_string(), false);
                    continue;
                }
            };
            if self.reach(ep, object, &candidate, &planned)? {
                return self.acquire(ep, map, object, &candidate, planned);
            }
        }
    }

    /// Executes the planned path to `candidate`: whether the arm got there (a reported
    /// collision is a failed viewpoint, any other rig failure an error).
    fn reach(
        &mut self,
        ep: &mut Episode<'_, '_>,
        object: &mut ObjectExploration,
        candidate: &Candidate,
        planned: &PlannedPath,
    ) -> Result<bool, PipelineError> {
        let moved = timed(&mut object.times.motion, || {
            ep.rig.arm.execute(&planned.path)
        });
        match moved {
            Ok(motion) => {
                ep.observer.event(&ExploreEvent::Moved { motion: &motion });
                Ok(true)
            }
            Err(e) => {
                let collision = matches!(e, RigError::Collision { .. });
                ep.collisions += usize::from(collision);
                self.record_failure(ep, object, candidate, e.to_string(), collision);
                if !collision {
                    // Anything else than a reported collision is a rig failure.
                    return Err(e.into());
                }
                Ok(false)
            }
        }
    }

    /// Acquires the view at `candidate` (the arm is there): the grid updated, the view and
    /// what it saw of the object recorded; a first view with too few points ends the
    /// object as not an object.
    fn acquire(
        &mut self,
        ep: &mut Episode<'_, '_>,
        map: &mut ExplorationMap,
        object: &mut ObjectExploration,
        candidate: &Candidate,
        planned: PlannedPath,
    ) -> Result<Round, PipelineError> {
        let config = ep.config;
        let seen = acquire_and_update(
            ep.rig,
            config,
            map,
            &candidate.visible.all(),
            &mut object.times,
        )?;
        if self.nbv.params.object_surface {
            self.grow_region(ep, object.index, &seen.frame)?;
        }
        let view = object_view(
            ep,
            &seen,
            &self.region,
            self.table,
            self.nbv.params.object_surface,
            &mut object.times,
        );
        let table = view.table.as_ref().or(self.table);
        let (cloud, registration_cloud) = (&view.cloud, &view.registration_cloud);
        ep.observer
            .event(&ExploreEvent::GridUpdated { grid: &map.grid });
        self.visited.push(candidate.viewpoint.pose);
        self.missed.record_in(&candidate.visible.unknown, &map.grid);
        let origin = nalgebra::Point3::from(seen.sensor_pose.translation.vector);
        self.sides
            .record(map.grid.geometry(), &origin, &cloud.points);
        let model: Vec<nalgebra::Point3<f64>> = object
            .cluster
            .points
            .iter()
            .chain(object.views.iter().flat_map(|v| v.cloud.points.iter()))
            .copied()
            .collect();
        // The view's points as the registration smooths them: the averaged frame's range
        // noise (6 mm at 0.45 m) puts one point in eight past 1 cm off a surface already
        // seen. An object lower than the smoothing's gate (a spatula) is pulled towards
        // its table, and the rule sees less of it; the earlier views are read as acquired
        // (`nbv/new_surface.rs` says what that misses).
        let smoothed = registration_cloud.as_ref().unwrap_or(cloud);
        // With the object's surface, the view is counted where it lies on the earlier
        // ones (its pose error moves it by a centimetre or two), above its own table
        // moved with it.
        let shift = if self.nbv.params.object_surface {
            settle_shift(&smoothed.points, &model)
        } else {
            nalgebra::Vector3::zeros()
        };
        let counted: Vec<_> = smoothed.points.iter().map(|p| p + shift).collect();
        let counted_table = table.map(|t| t.translated(&shift));
        let new_surface = new_surface_share(&model, &counted, counted_table.as_ref());
        let first_points = object.views.is_empty().then_some(cloud.len());
        let gain = seen.gain;
        let mut recorded = view.recorded(candidate, &seen, planned.stats);
        recorded.failures_before = self.failures_since_view;
        recorded.new_surface = new_surface;
        object.views.push(recorded);
        self.failures_since_view = 0;
        if let Some(view) = object.views.last() {
            ep.observer.event(&ExploreEvent::ViewTaken {
                object: object.index,
                views: object.views.len(),
                gain: config.stop.measure.value(&gain),
                view,
                path: &planned.path,
                frame: &seen.frame,
                times: &object.times,
            });
        }
        ep.trail.push(planned.path);
        self.latest_gain = Some(gain);
        self.retreated = false;
        match first_points {
            Some(points) if points < config.phase_one.segmentation.min_cluster_points => {
                Ok(Round::NotAnObject { points })
            }
            _ => Ok(Round::Taken),
        }
    }

    /// Grows the object's region over what the view's `frame` saw of the object past it
    /// ([`ObjectRegion::grow`]: linked at phase 1's clustering tolerance, at most
    /// [`REGION_REACH`] per view, never into another object's region or a known
    /// obstacle), and the episode's footprint of the object with it.
    fn grow_region(
        &mut self,
        ep: &mut Episode<'_, '_>,
        index: usize,
        frame: &PointCloud,
    ) -> Result<(), PipelineError> {
        let config = ep.config;
        let others: Vec<ObjectRegion> = ep
            .footprints
            .iter()
            .enumerate()
            .filter(|&(k, _)| k != index)
            .map(|(_, r)| *r)
            .collect();
        let known = &config.phase_one.exclude;
        let grew = self.region.grow(
            frame,
            config.phase_one.segmentation.cluster_tolerance,
            REGION_REACH,
            config.object_margin,
            config.table_filter.as_ref(),
            |p| others.iter().any(|r| r.contains(p)) || known.iter().any(|b| b.contains(p)),
        )?;
        if grew && let Some(footprint) = ep.footprints.get_mut(index) {
            *footprint = self.region;
        }
        Ok(())
    }

    /// After a round in which no viewpoint was reachable from where the arm is (its last
    /// view can leave it boxed in by what that view added to the map): once, the arm goes
    /// back the way it came since phase 1 — space it has just moved through — so that the
    /// next round samples from there. Whether it did (a collision on the way back counts
    /// and ends the object; any other rig failure is an error).
    fn retreat(
        &mut self,
        ep: &mut Episode<'_, '_>,
        object: &mut ObjectExploration,
    ) -> Result<bool, PipelineError> {
        if self.retreated || ep.trail.is_empty() {
            return Ok(false);
        }
        self.retreated = true;
        ep.observer.event(&ExploreEvent::Retreated {
            object: object.index,
        });
        let back = retrace(&ep.trail, ep.rig.arm.joints()?);
        match timed(&mut object.times.motion, || ep.rig.arm.execute(&back)) {
            Ok(motion) => {
                ep.observer.event(&ExploreEvent::Moved { motion: &motion });
                ep.trail.clear();
                object.retreats += 1;
                Ok(true)
            }
            Err(RigError::Collision { .. }) => {
                ep.collisions += 1;
                Ok(false)
            }
            Err(e) => Err(e.into()),
        }
    }

    /// Records a viewpoint that could not be reached, one more failure since the latest
    /// view.
    fn record_failure(
        &mut self,
        ep: &mut Episode<'_, '_>,
        object: &mut ObjectExploration,
        candidate: &Candidate,
        reason: String,
        collision: bool,
    ) {
        fail(
            object,
            &candidate.viewpoint.pose,
            reason,
            collision,
            ep.observer,
        );
        self.failures_since_view += 1;
    }
}

/// Records a viewpoint that could not be reached.
fn fail(
    object: &mut ObjectExploration,
    viewpoint: &Pose,
    reason: String,
    collision: bool,
    observer: &mut dyn ExploreObserver,
) {
    observer.event(&ExploreEvent::ViewFailed {
        object: object.index,
        reason: reason.clone(),
        viewpoint,
    });
    object.failures.push(ViewFailure {
        viewpoint: *viewpoint,
        reason,
        collision,
    });
}
