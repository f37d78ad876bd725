//! The object loop of Algorithm 1 for one object: candidates around what is seen of it,
//! each tried in order (plan, execute — the next one on failure), the first reached
//! acquired and the grid updated, until the stop rule, the view cap, no reachable
//! viewpoint (after one retreat) or a first view showing no object ends it.

use super::acquire_and_update::{acquire_and_update, table_evidence};
use super::candidates::{ObjectSurface, ViewCandidates, view_candidates, viewing_centre};
use super::episode::Episode;
use super::plan_and_execute::{plan_clearing_start, retrace};
use super::step_timer::timed;
use super::{
    AcquiredView, ExplorationMap, ExploreEvent, ExploreObserver, ObjectExploration, ObjectRegion,
    ObjectStop, PipelineError, ViewFailure,
};
use crate::cloud::PlaneFit;
use crate::math::Pose;
use crate::nbv::{
    Candidate, InformationGain, MissedVoxels, NextBestView, StopReason, SurfaceSides, VisitedViews,
    lazy_best, movement_cost_total,
};
use crate::rig::RigError;

/// Explores `object` (its cluster in `region`, standing on `table`) until a stop; the
/// views go into `object`, the collisions into the episode, each view into `map`.
pub(super) fn explore_object(
    ep: &mut Episode<'_, '_>,
    nbv: &NextBestView,
    map: &mut ExplorationMap,
    region: &ObjectRegion,
    table: Option<&PlaneFit>,
    object: &mut ObjectExploration,
) -> Result<(), PipelineError> {
    let config = ep.config;
    let j = object.index;
    let mut visited = VisitedViews::new(config.visited.0, config.visited.1)?;
    let mut latest_gain: Option<InformationGain> = None;
    let mut failures_since_view = 0;
    let mut attempt: u64 = 0;
    let mut retreated = false;
    let mut first_best: Option<f64> = None;
    // The unknown voxels taken views missed, and the sides of the object's voxels seen.
    let mut missed = MissedVoxels::new(1);
    let mut sides = SurfaceSides::of_cloud(map.grid.geometry(), &object.cluster);
    loop {
        if object.views.len() >= config.max_views_per_object {
            object.stop = ObjectStop::MaxViews;
            return Ok(());
        }
        let shares: Vec<f64> = object.views.iter().map(|v| v.new_surface).collect();
        if let Some(reason) = config.stop.check_new_surface(&shares) {
            object.stop = ObjectStop::Rule(reason);
            return Ok(());
        }
        let ViewCandidates {
            mut planner,
            mut list,
        } = timed(&mut object.times.nbv, || -> Result<_, PipelineError> {
            let centre = viewing_centre(&object.cluster, &object.views, region)
                .ok_or_else(|| PipelineError::Config(format!("object {j} has no point")))?;
            // The arm's joints only when the movement cost reads them (a device round trip).
            let start = if nbv.params.cost_weight > 0.0 {
                Some(ep.rig.arm.joints()?)
            } else {
                None
            };
            view_candidates(
                &ep.rig.robot,
                config,
                nbv,
                map,
                start.as_ref(),
                &centre,
                &visited,
                Some(ObjectSurface {
                    region,
                    sides: &sides,
                    missed: &missed,
                }),
            )
        })?;
        object.candidates_evaluated += list.candidates.len();
        ep.observer.event(&ExploreEvent::Candidates {
            object: j,
            candidates: list.candidates.len(),
            list: &list,
        });
        if let Some(reason) = config
            .stop
            .check(latest_gain.as_ref(), list.candidates.len())
        {
            object.stop = ObjectStop::Rule(reason);
            return Ok(());
        }
        let best = list
            .candidates
            .iter()
            .map(|c| c.score)
            .fold(f64::NEG_INFINITY, f64::max);
        match first_best {
            None => first_best = Some(best),
            Some(first) => {
                if let Some(reason) = config.stop.check_relative(first, best) {
                    object.stop = ObjectStop::Rule(reason);
                    return Ok(());
                }
            }
        }
        let mut taken = false;
        // The movement cost's normaliser Σc, fixed for the round (see `lazy_best`).
        let lambda = nbv.params.cost_weight;
        let total_cost = if lambda > 0.0 {
            movement_cost_total(&list.candidates, &ep.rig.arm.joints()?)
        } else {
            0.0
        };
        loop {
            let start = ep.rig.arm.joints()?;
            // Plans to one candidate: its IK goals, a seed of its own.
            let mut plan = |candidate: &Candidate| {
                attempt += 1;
                let seed = config.seed ^ ((j as u64) << 32) ^ attempt;
                let goals: Vec<_> = candidate
                    .viewpoint
                    .solutions
                    .iter()
                    .map(|s| s.joints)
                    .collect();
                plan_clearing_start(&mut planner, &start, &goals, seed)
            };
            // The best candidate and its path: in ranked order, or with the movement cost
            // the exact best by planned path length.
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
                break;
            };
            let planned = match planned {
                Ok(p) => p,
                Err(e) => {
                    fail(
                        object,
                        &candidate.viewpoint.pose,
                        e.to_string(),
                        false,
                        ep.observer,
                    );
                    failures_since_view += 1;
                    continue;
                }
            };
            let moved = timed(&mut object.times.motion, || {
                ep.rig.arm.execute(&planned.path)
            });
            if let Ok(motion) = &moved {
                ep.observer.event(&ExploreEvent::Moved { motion });
            }
            if let Err(e) = moved {
                let collision = matches!(e, RigError::Collision { .. });
                ep.collisions += usize::from(collision);
                fail(
                    object,
                    &candidate.viewpoint.pose,
                    e.to_string(),
                    collision,
                    ep.observer,
                );
                failures_since_view += 1;
                if !collision {
                    // Anything else than a reported collision is a rig failure.
                    return Err(e.into());
                }
                continue;
            }
            let seen = acquire_and_update(
                ep.rig,
                config,
                map,
                &candidate.visible.all(),
                region,
                table,
                &mut object.times,
            )?;
            let table_seen = timed(&mut object.times.registration, || {
                table_evidence(
                    &seen.frame,
                    &seen.sensor_pose,
                    ep.rig.camera.spec().range[1],
                    &ep.footprints,
                    table,
                    config,
                )
            });
            ep.observer
                .event(&ExploreEvent::GridUpdated { grid: &map.grid });
            visited.push(candidate.viewpoint.pose);
            missed.record_in(&candidate.visible.unknown, &map.grid);
            let before = sides.voxels();
            let origin = nalgebra::Point3::from(seen.sensor_pose.translation.vector);
            let added = sides.record(map.grid.geometry(), &origin, &seen.cloud.points);
            let new_surface = added.voxels as f64 / before.max(1) as f64;
            let first_points = object.views.is_empty().then_some(seen.cloud.len());
            let gain = seen.gain;
            object.views.push(AcquiredView {
                viewpoint: candidate.viewpoint.pose,
                score: candidate.score,
                predicted: (
                    candidate.visible.unknown.len(),
                    candidate.visible.occupied.len(),
                ),
                joints: seen.joints,
                sensor_pose: seen.sensor_pose,
                frame_points: seen.frame_points,
                cloud: seen.cloud,
                free_space: seen.free_space,
                registration_cloud: seen.registration_cloud,
                gain,
                table: table_seen,
                plan: planned.stats,
                failures_before: failures_since_view,
                new_surface,
            });
            failures_since_view = 0;
            if let Some(view) = object.views.last() {
                ep.observer.event(&ExploreEvent::ViewTaken {
                    object: j,
                    views: object.views.len(),
                    gain: config.stop.measure.value(&gain),
                    view,
                    path: &planned.path,
                    frame: &seen.frame,
                    times: &object.times,
                });
            }
            ep.trail.push(planned.path);
            latest_gain = Some(gain);
            taken = true;
            retreated = false;
            if let Some(points) = first_points
                && points < config.phase_one.segmentation.min_cluster_points
            {
                object.stop = ObjectStop::NotAnObject { points };
                return Ok(());
            }
            break;
        }
        if !taken {
            // No viewpoint was reachable from where the arm is (its last view can leave
            // it boxed in by what that view added to the map): once, it goes back the way
            // it came since phase 1 — space it has just moved through — and samples again.
            if !retreated && !ep.trail.is_empty() {
                retreated = true;
                ep.observer.event(&ExploreEvent::Retreated { object: j });
                let back = retrace(&ep.trail, ep.rig.arm.joints()?);
                match timed(&mut object.times.motion, || ep.rig.arm.execute(&back)) {
                    Ok(motion) => {
                        ep.observer.event(&ExploreEvent::Moved { motion: &motion });
                        ep.trail.clear();
                        object.retreats += 1;
                        continue;
                    }
                    Err(RigError::Collision { .. }) => ep.collisions += 1,
                    Err(e) => return Err(e.into()),
                }
            }
            object.stop = ObjectStop::Rule(StopReason::NoViewpoint);
            return Ok(());
        }
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
