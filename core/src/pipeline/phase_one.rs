//! Phase 1 (Figure 2, lines 2–6): the laser sweep — or, short-only, a camera survey of the
//! table — into one cloud, the sweep's pose corrected by the known workcell, then the
//! object clusters, the grid and its reduced map.

use super::acquire_and_update::capture_burst;
use super::episode_state::Episode;
use super::plan_and_execute::goals_at;
use super::step_timer::timed;
use super::{
    ExploreConfig, ExploreEvent, ExploreMode, ExploreObserver, PhaseOneReport, PipelineError,
    StepTimes,
};
use crate::cloud::PointCloud;
use crate::perception::{ObjectSegmentation, align_to_workcell, phase_one};
use crate::planning::{CollisionWorld, MotionPlanner};
use crate::registration::PosePrior;
use crate::rig::{Rig, RigError, acquire_sweep, depth_frame_to_cloud, lines_to_cloud, sensor_pose};
use nalgebra::Point3;

/// Phase 1 on a rig: the laser sweep (or, short-only, the camera survey), the cloud, the
/// object segmentation and the grid — what [`explore`](super::explore) does before the
/// first object.
pub fn run_phase_one(
    rig: &mut Rig<'_>,
    config: &ExploreConfig,
    observer: &mut dyn ExploreObserver,
) -> Result<(PhaseOneReport, ObjectSegmentation), PipelineError> {
    run(&mut Episode::new(rig, config, observer))
}

/// Phase 1 within an episode (its collisions counted in the episode).
pub(super) fn run(
    ep: &mut Episode<'_, '_>,
) -> Result<(PhaseOneReport, ObjectSegmentation), PipelineError> {
    let config = ep.config;
    let mut times = StepTimes::default();
    let collisions_before = ep.collisions;
    let mut workcell = None;
    let (lines, survey_frames, cloud) = if config.mode == ExploreMode::ShortOnly {
        let (frames, cloud) = survey(ep, &mut times)?;
        (0, frames, cloud)
    } else {
        ep.observer.event(&ExploreEvent::SweepStarted {
            waypoints: config.sweep.len(),
        });
        let rig = &mut *ep.rig;
        let sweep = timed(&mut times.motion, || {
            acquire_sweep(rig.arm, rig.scanner, &config.sweep, config.sweep_speed)
        })?;
        let mut cloud = timed(&mut times.acquisition, || {
            lines_to_cloud(
                &sweep.lines,
                &sweep.motion,
                &rig.robot,
                &rig.base,
                rig.scanner.spec(),
            )
        })?;
        if config.align_to_workcell {
            let a = align_to_workcell(
                &cloud,
                &config.obstacles,
                config.uncertainty.laser_noise.sigma(1.0),
                &config.uncertainty.laser_pose,
            );
            cloud.transform(&a.correction);
            workcell = Some(a);
        }
        ep.observer.event(&ExploreEvent::Moved {
            motion: &sweep.motion,
        });
        ep.observer.event(&ExploreEvent::SweepCloud {
            lines: &sweep.lines,
            cloud: &cloud,
        });
        (sweep.lines.len(), 0, cloud)
    };
    ep.observer.event(&ExploreEvent::SweepDone {
        lines,
        points: cloud.len(),
    });
    // The known obstacles' boxes, grown by what is left of the pose error: the sweep's
    // after the workcell alignment, else the rig's declared prior (the camera's, for the
    // short-only survey).
    let residual = match &workcell {
        Some(a) if a.accepted => PosePrior {
            rotation_sigma: a.sigma.0,
            translation_sigma: a.sigma.1,
        },
        _ if config.mode == ExploreMode::ShortOnly => config.uncertainty.camera_pose,
        _ => config.uncertainty.laser_pose,
    };
    let sensor = cloud.origin_centroid().unwrap_or_else(Point3::origin);
    // Segmentation and the grid are timed together, as segmentation.
    let one = timed(&mut times.segmentation, || {
        phase_one(
            &cloud,
            &config.phase_one.with_pose_error(&residual, &sensor),
        )
    })?;
    ep.observer.event(&ExploreEvent::Segmented {
        objects: one.segmentation.clusters.len(),
    });
    ep.observer.event(&ExploreEvent::GridUpdated {
        grid: &one.map.grid,
    });
    let report = PhaseOneReport {
        lines,
        survey_frames,
        collisions: ep.collisions - collisions_before,
        cloud,
        segmentation: one.segmentation.counts,
        slivers: one.segmentation.slivers.iter().map(|(_, s)| *s).collect(),
        scan: one.map.scan,
        reduced: *one.map.reduced.stats(),
        grid: one.map.grid,
        workcell,
        times,
    };
    Ok((report, one.segmentation))
}

/// The short-only survey: the camera at each survey pose (first reachable roll with a
/// collision-free IK solution; poses that cannot be planned to are skipped), every frame
/// into one cloud with sensor origins. Returns the frames taken and the cloud.
fn survey(
    ep: &mut Episode<'_, '_>,
    times: &mut StepTimes,
) -> Result<(usize, PointCloud), PipelineError> {
    let config = ep.config;
    ep.observer.event(&ExploreEvent::SweepStarted {
        waypoints: config.survey.len(),
    });
    let rig = &mut *ep.rig;
    let world = CollisionWorld::new(&rig.robot, &config.obstacles)?;
    let planner = MotionPlanner::new(world, config.planner)?;
    let mut cloud = PointCloud::default();
    let mut frames = 0;
    for (k, target) in config.survey.iter().enumerate() {
        let goals = goals_at(
            &rig.robot,
            &rig.camera.spec().frame,
            target,
            config.nbv.roll_candidates,
            &|q| !planner.world().in_collision(q),
        );
        if goals.is_empty() {
            continue;
        }
        let start = rig.arm.joints()?;
        let planned = timed(&mut times.planning, || {
            planner.plan(&start, &goals, config.seed ^ (k as u64 + 1))
        });
        let Ok(planned) = planned else { continue };
        match timed(&mut times.motion, || rig.arm.execute(&planned.path)) {
            Ok(motion) => ep.observer.event(&ExploreEvent::Moved { motion: &motion }),
            Err(RigError::Collision { .. }) => {
                ep.collisions += 1;
                continue;
            }
            Err(e) => return Err(e.into()),
        }
        let view = timed(&mut times.acquisition, || -> Result<_, PipelineError> {
            let (image, _) = capture_burst(rig.camera, config)?;
            let joints = rig.arm.joints()?;
            let pose = sensor_pose(&rig.robot, &rig.base, &joints, &rig.camera.spec().frame)?;
            Ok(depth_frame_to_cloud(&image, rig.camera.spec(), &pose)?)
        })?;
        cloud.extend(&view);
        frames += 1;
    }
    Ok((frames, cloud))
}
