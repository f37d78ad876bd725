//! [`explore`]: Algorithm 1 of the paper over any rig.

use super::hand_eye::estimate_hand_eye;
use super::{
    AcquiredView, Exploration, ExploreConfig, ExploreEvent, ExploreMode, ExploreObserver,
    ObjectExploration, ObjectRegion, ObjectRegistration, ObjectStop, PhaseOneReport, PipelineError,
    StepTimes, ViewFailure,
};
use crate::cloud::{PlaneFit, PointCloud};
use crate::kinematics::Joints;
use crate::kinematics::Robot;
use crate::math::Pose;
use crate::nbv::{InformationGain, NextBestView, VisitedViews, view_pose_rolled};
use crate::occupancy::{OccupancyGrid, ReducedMap};
use crate::perception::{align_to_workcell, phase_one};
use crate::planning::{CollisionWorld, MotionPlanner, PlanningError};
use crate::registration::{Method, PosePrior, RegistrationParams, register, register_with_models};
use crate::rig::{
    Arm, DepthCamera, DepthFrame, JointPath, LineScanner, RigError, acquire_sweep, average_frames,
    depth_frame_to_cloud, lines_to_cloud, sensor_pose,
};
use nalgebra::Point3;
use std::time::Instant;

/// Runs the method (or the baseline of `config.mode`) on a rig: the phase-1 sweep and
/// segmentation, the grid and reduced map, next-best-view exploration of each object
/// (Algorithm 1: viewpoints by Algorithm 2, plan and execute with the next viewpoint on
/// failure, acquire, update, information gain, stop rule), then the registration of each
/// object's views by p-ICP-GPA and by sequential ICP with the phase-1 cluster as the
/// reference view.
///
/// The robot's base must be the world frame (`robot` plans in its base frame, the map and
/// the obstacles are in the world frame). A viewpoint whose planning or execution fails is
/// recorded in [`ObjectExploration::failures`] and the next one is tried; collisions the
/// rig reports are counted in [`Exploration::collisions`]. Same rig behaviour and
/// configuration ⇒ same result (timings aside).
pub fn explore<A, L, C>(
    robot: &Robot,
    base: &Pose,
    arm: &mut A,
    scanner: &mut L,
    camera: &mut C,
    config: &ExploreConfig,
    observer: &mut dyn ExploreObserver,
) -> Result<Exploration, PipelineError>
where
    A: Arm + ?Sized,
    L: LineScanner + ?Sized,
    C: DepthCamera + ?Sized,
{
    if (base.translation.vector.norm() > 1e-12) || (base.rotation.angle() > 1e-12) {
        return Err(PipelineError::Config(
            "the robot base must be at the world origin for planning".into(),
        ));
    }
    let phase = run_phase_one(robot, base, arm, scanner, camera, config, observer)?;
    let (phase_report, segmentation) = phase;
    let mut grid = phase_report.grid.clone();
    let mut objects = Vec::new();
    let mut collisions = phase_report.collisions;
    let nbv = NextBestView::new(config.nbv, camera.spec())?;
    // The paths executed since phase 1, to go back along when the arm is boxed in.
    let mut trail = Vec::new();
    for (j, cluster) in segmentation.clusters.iter().enumerate() {
        observer.event(&ExploreEvent::ObjectStarted { object: j });
        let cloud = cluster.cloud(&segmentation.filtered);
        let region =
            ObjectRegion::of_cluster(cluster, segmentation.table.as_ref(), config.object_margin);
        let mut object = ObjectExploration {
            index: j,
            cluster: cloud,
            views: Vec::new(),
            failures: Vec::new(),
            candidates_evaluated: 0,
            retreats: 0,
            stop: ObjectStop::NotExplored,
            registration: None,
            registration_error: None,
            times: StepTimes::default(),
        };
        if config.mode != ExploreMode::MidOnly {
            let hits = explore_object(
                robot,
                base,
                arm,
                camera,
                config,
                &nbv,
                &mut grid,
                &region,
                segmentation.table.as_ref(),
                &mut object,
                &mut trail,
                observer,
            )?;
            collisions += hits;
        }
        let stop = match object.stop {
            ObjectStop::Rule(r) => Some(r),
            _ => None,
        };
        observer.event(&ExploreEvent::ObjectDone {
            object: j,
            reason: stop,
        });
        let dropped = matches!(object.stop, ObjectStop::NotAnObject { .. });
        if !dropped && object.views.iter().any(|v| !v.cloud.is_empty()) {
            let t = Instant::now();
            match register_object(&object, config, phase_report.workcell.as_ref()) {
                Ok(r) => object.registration = Some(r),
                Err(e) => object.registration_error = Some(e.to_string()),
            }
            object.times.registration += t.elapsed().as_secs_f64();
            observer.event(&ExploreEvent::Registered { object: j });
        }
        objects.push(object);
    }
    let hand_eye = estimate_hand_eye(&objects);
    Ok(Exploration {
        mode: config.mode,
        phase_one: phase_report,
        objects,
        grid,
        collisions,
        hand_eye,
    })
}

/// Phase 1 on a rig: the laser sweep (or, short-only, the camera survey), the cloud, the
/// object segmentation and the grid — what [`explore`] does before the first object.
pub fn run_phase_one<A, L, C>(
    robot: &Robot,
    base: &Pose,
    arm: &mut A,
    scanner: &mut L,
    camera: &mut C,
    config: &ExploreConfig,
    observer: &mut dyn ExploreObserver,
) -> Result<(PhaseOneReport, crate::perception::ObjectSegmentation), PipelineError>
where
    A: Arm + ?Sized,
    L: LineScanner + ?Sized,
    C: DepthCamera + ?Sized,
{
    let mut times = StepTimes::default();
    let mut collisions = 0;
    let mut workcell = None;
    let (lines, survey_frames, cloud) = if config.mode == ExploreMode::ShortOnly {
        let (frames, cloud) = survey(
            robot,
            base,
            arm,
            camera,
            config,
            &mut times,
            &mut collisions,
            observer,
        )?;
        (0, frames, cloud)
    } else {
        observer.event(&ExploreEvent::SweepStarted {
            waypoints: config.sweep.len(),
        });
        let t = Instant::now();
        let sweep = acquire_sweep(arm, scanner, &config.sweep, config.sweep_speed)?;
        times.motion += t.elapsed().as_secs_f64();
        let t = Instant::now();
        let mut cloud = lines_to_cloud(&sweep.lines, &sweep.motion, robot, base, scanner.spec())?;
        times.acquisition += t.elapsed().as_secs_f64();
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
        (sweep.lines.len(), 0, cloud)
    };
    observer.event(&ExploreEvent::SweepDone {
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
    let t = Instant::now();
    let one = phase_one(
        &cloud,
        &config.phase_one.with_pose_error(&residual, &sensor),
    )?;
    // phase_one segments and maps; split the time by re-measuring nothing: both count as
    // segmentation + mapping, attributed to mapping for the grid part below.
    times.segmentation += t.elapsed().as_secs_f64();
    observer.event(&ExploreEvent::Segmented {
        objects: one.segmentation.clusters.len(),
    });
    let report = PhaseOneReport {
        lines,
        survey_frames,
        collisions,
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

/// Algorithm 1's inner loop for one object; returns the collisions the rig reported.
#[allow(clippy::too_many_arguments)]
fn explore_object<A, C>(
    robot: &Robot,
    base: &Pose,
    arm: &mut A,
    camera: &mut C,
    config: &ExploreConfig,
    nbv: &NextBestView,
    grid: &mut OccupancyGrid,
    region: &ObjectRegion,
    table: Option<&PlaneFit>,
    object: &mut ObjectExploration,
    trail: &mut Vec<JointPath>,
    observer: &mut dyn ExploreObserver,
) -> Result<usize, PipelineError>
where
    A: Arm + ?Sized,
    C: DepthCamera + ?Sized,
{
    let j = object.index;
    let mut visited = VisitedViews::new(config.visited.0, config.visited.1)?;
    let mut latest_gain: Option<InformationGain> = None;
    let mut collisions = 0;
    let mut failures_since_view = 0;
    let mut attempt: u64 = 0;
    let mut retreated = false;
    loop {
        if object.views.len() >= config.max_views_per_object {
            object.stop = ObjectStop::MaxViews;
            return Ok(collisions);
        }
        // Algorithm 2 around the centroid of everything seen of the object so far, at
        // the object's middle height when it rests on a table (ObjectRegion).
        let t = Instant::now();
        let reduced = ReducedMap::from_grid(grid);
        object.times.mapping += t.elapsed().as_secs_f64();
        let t = Instant::now();
        let centroid = object_points(object)
            .centroid()
            .map(|c| region.viewing_centre(&c))
            .ok_or_else(|| PipelineError::Config(format!("object {j} has no point")))?;
        // Goals must be free of self-collision, the known obstacles and the map (MoveIt's
        // collision-aware IK): a viewpoint none of whose IK solutions is free is
        // unreachable, and the next roll about the optical axis is tried.
        let world = CollisionWorld::new(robot, &config.obstacles)?.with_reduced_map(&reduced);
        let mut planner = MotionPlanner::new(world, config.planner)?;
        let usable = |s: &crate::kinematics::IkSolution| !planner.world().in_collision(&s.joints);
        let mut list =
            nbv.candidates_around_where(robot, &reduced, &centroid, &visited, &usable)?;
        object.times.nbv += t.elapsed().as_secs_f64();
        object.candidates_evaluated += list.candidates.len();
        observer.event(&ExploreEvent::Candidates {
            object: j,
            candidates: list.candidates.len(),
        });
        if let Some(reason) = config
            .stop
            .check(latest_gain.as_ref(), list.candidates.len())
        {
            object.stop = ObjectStop::Rule(reason);
            return Ok(collisions);
        }
        let mut taken = false;
        while let Some(candidate) = list.pop_first() {
            attempt += 1;
            let seed = config.seed ^ ((j as u64) << 32) ^ attempt;
            let start = arm.joints()?;
            let goals: Vec<_> = candidate
                .viewpoint
                .solutions
                .iter()
                .map(|s| s.joints)
                .collect();
            let t = Instant::now();
            let planned = plan_clearing_start(&mut planner, &start, &goals, seed);
            object.times.planning += t.elapsed().as_secs_f64();
            let planned = match planned {
                Ok(p) => p,
                Err(e) => {
                    fail(
                        object,
                        &candidate.viewpoint.pose,
                        e.to_string(),
                        false,
                        observer,
                    );
                    failures_since_view += 1;
                    continue;
                }
            };
            let t = Instant::now();
            let moved = arm.execute(&planned.path);
            object.times.motion += t.elapsed().as_secs_f64();
            if let Err(e) = moved {
                let collision = matches!(e, RigError::Collision { .. });
                collisions += usize::from(collision);
                fail(
                    object,
                    &candidate.viewpoint.pose,
                    e.to_string(),
                    collision,
                    observer,
                );
                failures_since_view += 1;
                if !collision {
                    // Anything else than a reported collision is a rig failure.
                    return Err(e.into());
                }
                continue;
            }
            trail.push(planned.path);
            // Acquire, update, gain.
            let t = Instant::now();
            let frame = capture_burst(camera, config.frames_per_view)?;
            let joints = arm.joints()?;
            let pose = sensor_pose(robot, base, &joints, &camera.spec().frame)?;
            let full = depth_frame_to_cloud(&frame, camera.spec(), &pose)?;
            object.times.acquisition += t.elapsed().as_secs_f64();
            let t = Instant::now();
            let before = grid.clone();
            grid.insert_cloud(&full, camera.spec().range[1])?;
            let gain = InformationGain::between(&before, grid, &candidate.visible.all())?;
            object.times.mapping += t.elapsed().as_secs_f64();
            visited.push(candidate.viewpoint.pose);
            let mut cloud = region.crop(&full);
            if let (Some(filter), Some(plane)) = (&config.table_filter, table) {
                cloud = filter.remove(plane, &cloud);
            }
            // The known obstacles are no object: their surfaces, wherever this view's pose
            // error may have put them, leave the view.
            let known = config
                .phase_one
                .with_pose_error(
                    &config.uncertainty.camera_pose,
                    &Point3::from(pose.translation.vector),
                )
                .exclude;
            cloud = cloud.retain_indices(|i| !known.iter().any(|b| b.contains(&cloud.points[i])));
            let first_points = object.views.is_empty().then_some(cloud.len());
            object.views.push(AcquiredView {
                viewpoint: candidate.viewpoint.pose,
                score: candidate.score,
                predicted: (
                    candidate.visible.unknown.len(),
                    candidate.visible.occupied.len(),
                ),
                joints,
                sensor_pose: pose,
                frame_points: full.len(),
                cloud,
                gain,
                plan: planned.stats,
                failures_before: failures_since_view,
            });
            failures_since_view = 0;
            observer.event(&ExploreEvent::ViewTaken {
                object: j,
                views: object.views.len(),
                gain: config.stop.measure.value(&gain),
            });
            latest_gain = Some(gain);
            taken = true;
            retreated = false;
            if let Some(points) = first_points
                && points < config.phase_one.segmentation.min_cluster_points
            {
                object.stop = ObjectStop::NotAnObject { points };
                return Ok(collisions);
            }
            break;
        }
        if !taken {
            // No viewpoint was reachable from where the arm is (its last view can leave
            // it boxed in by what that view added to the map): once, it goes back the way
            // it came since phase 1 — space it has just moved through — and samples again.
            if !retreated && !trail.is_empty() {
                retreated = true;
                let back = retrace(trail, arm.joints()?);
                let t = Instant::now();
                let moved = arm.execute(&back);
                object.times.motion += t.elapsed().as_secs_f64();
                match moved {
                    Ok(_) => {
                        trail.clear();
                        object.retreats += 1;
                        continue;
                    }
                    Err(RigError::Collision { .. }) => collisions += 1,
                    Err(e) => return Err(e.into()),
                }
            }
            object.stop = ObjectStop::Rule(crate::nbv::StopReason::NoViewpoint);
            return Ok(collisions);
        }
    }
}

/// The short-only survey: the camera at each survey pose (first reachable roll with a
/// collision-free IK solution; poses that cannot be planned to are skipped), every frame
/// into one cloud with sensor origins. Returns the frames taken and the cloud.
#[allow(clippy::too_many_arguments)]
fn survey<A, C>(
    robot: &Robot,
    base: &Pose,
    arm: &mut A,
    camera: &mut C,
    config: &ExploreConfig,
    times: &mut StepTimes,
    collisions: &mut usize,
    observer: &mut dyn ExploreObserver,
) -> Result<(usize, PointCloud), PipelineError>
where
    A: Arm + ?Sized,
    C: DepthCamera + ?Sized,
{
    observer.event(&ExploreEvent::SweepStarted {
        waypoints: config.survey.len(),
    });
    let frame = camera.spec().frame.clone();
    let world = CollisionWorld::new(robot, &config.obstacles)?;
    let planner = MotionPlanner::new(world, config.planner)?;
    let rolls = config.nbv.roll_candidates.max(1);
    let mut cloud = PointCloud::default();
    let mut frames = 0;
    for (k, target) in config.survey.iter().enumerate() {
        let goals: Vec<_> = (0..rolls)
            .flat_map(|r| {
                let pose =
                    view_pose_rolled(target, std::f64::consts::TAU * r as f64 / rolls as f64);
                robot.ik(&frame, &pose).unwrap_or_default()
            })
            .map(|s| s.joints)
            .filter(|q| !planner.world().in_collision(q))
            .collect();
        if goals.is_empty() {
            continue;
        }
        let t = Instant::now();
        let start = arm.joints()?;
        let planned = planner.plan(&start, &goals, config.seed ^ (k as u64 + 1));
        times.planning += t.elapsed().as_secs_f64();
        let Ok(planned) = planned else { continue };
        let t = Instant::now();
        match arm.execute(&planned.path) {
            Ok(_) => {}
            Err(RigError::Collision { .. }) => {
                times.motion += t.elapsed().as_secs_f64();
                *collisions += 1;
                continue;
            }
            Err(e) => return Err(e.into()),
        }
        times.motion += t.elapsed().as_secs_f64();
        let t = Instant::now();
        let image = capture_burst(camera, config.frames_per_view)?;
        let joints = arm.joints()?;
        let pose = sensor_pose(robot, base, &joints, &camera.spec().frame)?;
        cloud.extend(&depth_frame_to_cloud(&image, camera.spec(), &pose)?);
        times.acquisition += t.elapsed().as_secs_f64();
        frames += 1;
    }
    Ok((frames, cloud))
}

/// The executed paths of `trail` backwards, from `now` (the arm's configuration) to where
/// the first of them started.
fn retrace(trail: &[JointPath], now: Joints) -> JointPath {
    let mut waypoints = vec![now];
    for path in trail.iter().rev() {
        waypoints.extend(path.waypoints.iter().rev().copied());
    }
    JointPath {
        waypoints,
        speed_fraction: trail.last().map_or(1.0, |p| p.speed_fraction),
    }
}

/// Plans; when the start touches only map voxels (unknown space around the arm that no
/// ray cleared), those voxels are dropped from the planner's world and it plans again.
fn plan_clearing_start(
    planner: &mut MotionPlanner,
    start: &Joints,
    goals: &[Joints],
    seed: u64,
) -> Result<crate::planning::PlannedPath, PlanningError> {
    match planner.plan(start, goals, seed) {
        Err(PlanningError::StartInCollision(c)) if c.is_voxel() => {
            let voxels = planner.world().colliding_voxels(start);
            planner.world_mut().ignore_voxels(&voxels);
            planner.plan(start, goals, seed)
        }
        other => other,
    }
}

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
    });
    object.failures.push(ViewFailure {
        viewpoint: *viewpoint,
        reason,
        collision,
    });
}

/// `n` frames (at least one) at the camera's current pose, averaged.
fn capture_burst<C: DepthCamera + ?Sized>(
    camera: &mut C,
    n: usize,
) -> Result<DepthFrame, RigError> {
    let frames = (0..n.max(1))
        .map(|_| camera.capture())
        .collect::<Result<Vec<_>, _>>()?;
    average_frames(&frames)
}

/// The cluster and every view's object points.
fn object_points(object: &ObjectExploration) -> PointCloud {
    let mut all = PointCloud::from_points(object.cluster.points.clone());
    for v in &object.views {
        all.extend(&PointCloud::from_points(v.cloud.points.clone()));
    }
    all
}

/// Evenly keeps at most `n` points of `cloud` (all columns); 0 keeps all.
fn subsample(cloud: &PointCloud, n: usize) -> PointCloud {
    if n == 0 || cloud.len() <= n {
        return cloud.clone();
    }
    let indices: Vec<usize> = (0..n).map(|k| k * cloud.len() / n).collect();
    cloud.select(&indices)
}

/// Registers the cluster (reference) and the views with the MAP registration (the
/// model's), the paper's p-ICP-GPA and sequential ICP, from the same input.
fn register_object(
    object: &ObjectExploration,
    config: &ExploreConfig,
    workcell: Option<&crate::perception::WorkcellAlignment>,
) -> Result<ObjectRegistration, crate::registration::RegistrationError> {
    let points = config.registration_points;
    let mut views = vec![subsample(&object.cluster, points)];
    views.extend(
        object
            .views
            .iter()
            .filter(|v| !v.cloud.is_empty())
            .map(|v| {
                let mut cloud = subsample(&v.cloud, points);
                // Every point of a frame was seen from the reported sensor position.
                let o = nalgebra::Point3::from(v.sensor_pose.translation.vector);
                cloud.origins = Some(vec![o; cloud.len()]);
                cloud
            }),
    );
    let initial = vec![Pose::identity(); views.len()];
    // A sweep aligned to the workcell is off by its posterior uncertainty only.
    let mut uncertainty = config.uncertainty;
    if let Some(a) = workcell.filter(|a| a.accepted) {
        uncertainty.laser_pose = crate::registration::PosePrior {
            rotation_sigma: a.sigma.0,
            translation_sigma: a.sigma.1,
        };
    }
    let models = uncertainty.view_models(&views, config.frames_per_view);
    let params = |method| RegistrationParams {
        method,
        reference: 0,
        ..config.registration.clone()
    };
    let map = register_with_models(&views, &initial, &models, &params(Method::Map))?;
    let gpa = register(&views, &initial, &params(Method::Gpa))?;
    let icp = register(
        &views,
        &initial,
        &params(Method::SequentialIcp {
            point_to_plane: false,
        }),
    )?;
    let accepted = |r: &crate::registration::Registration| {
        r.converged && within_correction(&views, &r.poses, config.max_correction)
    };
    let map_accepted = match &map.report {
        crate::registration::MethodReport::Map(m) => m.accepted,
        _ => false,
    };
    Ok(ObjectRegistration {
        models,
        map_accepted,
        gpa_accepted: accepted(&gpa),
        icp_accepted: accepted(&icp),
        views,
        map,
        gpa,
        icp,
    })
}

/// Whether every pose (a correction of a view given in the world frame) turns by at most
/// `max.0` rad and moves the view's centroid by at most `max.1` m.
fn within_correction(views: &[PointCloud], poses: &[Pose], max: (f64, f64)) -> bool {
    views.iter().zip(poses).all(|(v, p)| {
        let moved = v.centroid().is_none_or(|c| (p * c - c).norm() <= max.1);
        p.rotation.angle() <= max.0 && moved
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn q(a: f64) -> Joints {
        Joints::from([a, 0.0, -1.5, 0.0, 1.5, 0.0])
    }

    #[test]
    fn retrace_goes_back_through_every_executed_waypoint_to_the_first_start() {
        let trail = vec![
            JointPath {
                waypoints: vec![q(0.0), q(0.1), q(0.2)],
                speed_fraction: 0.3,
            },
            JointPath {
                waypoints: vec![q(0.2), q(0.5)],
                speed_fraction: 0.3,
            },
        ];
        // The arm stopped a hair off the last waypoint.
        let back = retrace(&trail, q(0.501));
        let firsts: Vec<f64> = back.waypoints.iter().map(|w| w[0]).collect();
        assert_eq!(firsts, vec![0.501, 0.5, 0.2, 0.2, 0.1, 0.0]);
        assert_eq!(back.speed_fraction, 0.3);
    }
}
