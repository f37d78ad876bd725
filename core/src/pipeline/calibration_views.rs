//! The self-calibration's own views: when the exploration took fewer views than the
//! calibration reads (`[registration] calibration_views`), each object, once explored,
//! is seen from more of its candidate viewpoints, for the calibration alone. Each view
//! carries a standstill error of its own and only the camera's mount is common to all, so
//! the estimate's spread falls with the views (docs/hand-eye.md); these views add that
//! evidence after the object's coverage is reached instead of before.

use super::acquire_and_update::{acquire, object_view};
use super::candidates::ViewCandidates;
use super::episode_state::Episode;
use super::plan_and_execute::plan_clearing_start;
use super::step_timer::timed;
use super::{ExploreEvent, ObjectExploration, ObjectRegion, PipelineError};
use crate::cloud::PlaneFit;
use crate::rig::RigError;

/// The calibration views to ask of one object so that the episode reaches `wanted`
/// camera views: the views still missing (`taken` so far, this object's included) shared
/// evenly over it and the `objects_after` objects still to explore, rounded up.
///
/// ```
/// use nbv_core::pipeline::calibration_share;
/// assert_eq!(calibration_share(18, 7, 2), 4); // 11 missing over 3 objects
/// assert_eq!(calibration_share(18, 20, 0), 0);
/// assert_eq!(calibration_share(0, 3, 1), 0);
/// ```
pub fn calibration_share(wanted: usize, taken: usize, objects_after: usize) -> usize {
    wanted.saturating_sub(taken).div_ceil(objects_after + 1)
}

/// Takes up to `count` views of `object` from `candidates` (a round sampled after its
/// exploration stopped: viewpoints away from those it took), in their ranked order, into
/// [`ObjectExploration::calibration_views`], each cut to the object's `region`. The map
/// stays the exploration's; a candidate the arm does not reach is skipped (after `count`
/// of them the object takes no more: each failed plan spends the planner's whole budget),
/// and a reported collision counts in the episode.
pub(super) fn take_calibration_views(
    ep: &mut Episode<'_, '_>,
    candidates: ViewCandidates,
    region: &ObjectRegion,
    table: Option<&PlaneFit>,
    object: &mut ObjectExploration,
    count: usize,
) -> Result<(), PipelineError> {
    let config = ep.config;
    let ViewCandidates {
        mut planner,
        mut list,
        ..
    } = candidates;
    let seed_base = config.seed ^ ((object.index as u64) << 32) ^ (1 << 31);
    let mut tries = 0u64;
    let mut failed = 0;
    while object.calibration_views.len() < count && failed < count {
        let Some(candidate) = list.pop_first() else {
            break;
        };
        tries += 1;
        let goals = candidate.viewpoint.goals();
        let start = ep.rig.arm.joints()?;
        let planned = timed(&mut object.times.planning, || {
            plan_clearing_start(&mut planner, &start, &goals, seed_base ^ tries)
        });
        let Ok(planned) = planned else {
            failed += 1;
            continue;
        };
        match timed(&mut object.times.motion, || {
            ep.rig.arm.execute(&planned.path)
        }) {
            Ok(motion) => ep.observer.event(&ExploreEvent::Moved { motion: &motion }),
            Err(RigError::Collision { .. }) => {
                ep.collisions += 1;
                failed += 1;
                continue;
            }
            Err(e) => return Err(e.into()),
        }
        let (seen, _) = acquire(ep.rig, config, &mut object.times)?;
        let view = object_view(
            ep,
            &seen,
            region,
            table,
            config.nbv.object_surface,
            &mut object.times,
        );
        ep.trail.push(planned.path);
        object
            .calibration_views
            .push(view.recorded(&candidate, &seen, planned.stats));
    }
    Ok(())
}
