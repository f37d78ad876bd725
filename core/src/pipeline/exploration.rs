//! [`explore`]: the method end to end over a [`Rig`] (the paper's Figure 2) — phase 1,
//! then each object explored by Algorithm 1 and its views registered.

use super::ExplorationMap;
use super::calibration_views::calibration_share;
use super::episode_state::Episode;
use super::fuse_surface::fuse_surface;
use super::object_loop::explore_object;
use super::register_views::{refine_along_rays, register_calibrated, register_object};
use super::step_timer::timed;
use super::{
    Exploration, ExploreConfig, ExploreEvent, ExploreMode, ExploreObserver, ObjectExploration,
    ObjectRegion, ObjectStop, PipelineError, StepTimes,
};
use crate::calibration::{HandEyeEstimate, estimate_hand_eye};
use crate::nbv::NextBestView;
use crate::registration::MapPreparation;
use crate::rig::Rig;

/// Runs the method (or the baseline of `config.mode`) on a rig: the phase-1 sweep and
/// segmentation, the grid and reduced map, next-best-view exploration of each object
/// (Algorithm 1: viewpoints by Algorithm 2, plan and execute with the next viewpoint on
/// failure, acquire, update, information gain, stop rule), then the registration of each
/// object's views with the phase-1 cluster as the reference view.
///
/// The robot's base must be the world frame (the robot plans in its base frame, the map
/// and the obstacles are in the world frame). A viewpoint whose planning or execution
/// fails is recorded in [`ObjectExploration::failures`] and the next one is tried;
/// collisions the rig reports are counted in [`Exploration::collisions`]. Same rig
/// behaviour and configuration ⇒ same result (timings aside).
pub fn explore(
    rig: &mut Rig<'_>,
    config: &ExploreConfig,
    observer: &mut dyn ExploreObserver,
) -> Result<Exploration, PipelineError> {
    if (rig.base.translation.vector.norm() > 1e-12) || (rig.base.rotation.angle() > 1e-12) {
        return Err(PipelineError::Config(
            "the robot base must be at the world origin for planning".into(),
        ));
    }
    let mut ep = Episode::new(rig, config, observer);
    let (phase_report, segmentation) = super::phase_one::run(&mut ep)?;
    let mut map = ExplorationMap::after_phase_one(
        phase_report.grid.clone(),
        &phase_report.cloud,
        config.nbv.objective,
    )?;
    let mut objects = Vec::new();
    let mut preparations = Vec::new();
    // The laser's free space, for the registration (the camera survey of short-only mode
    // is no accurate reference).
    let sweep = (config.mode != ExploreMode::ShortOnly).then_some(&phase_report.cloud);
    let nbv = NextBestView::new(config.nbv, ep.rig.camera.spec())?;
    ep.footprints = ObjectRegion::of_segmentation(&segmentation, config.object_margin);
    map.set_free_above(&ep.footprints, config.nbv.free_above_objects);
    for (j, cluster) in segmentation.clusters.iter().enumerate() {
        let region = ep.footprints[j];
        let mut object = ObjectExploration {
            index: j,
            cluster: cluster.cloud(&segmentation.filtered),
            views: Vec::new(),
            calibration_views: Vec::new(),
            failures: Vec::new(),
            candidates_evaluated: 0,
            retreats: 0,
            stop: ObjectStop::NotExplored,
            registration: None,
            registration_error: None,
            surface: None,
            times: StepTimes::default(),
        };
        ep.observer.event(&ExploreEvent::ObjectStarted {
            object: j,
            cluster: &object.cluster,
        });
        if config.mode != ExploreMode::MidOnly {
            let table = segmentation.table.as_ref();
            // The views the calibration still lacks, shared over the objects left.
            let before: usize = objects
                .iter()
                .map(|o: &ObjectExploration| o.registered_views().count())
                .sum();
            let after = segmentation.clusters.len() - j - 1;
            let calibration = |o: &ObjectExploration| {
                let taken = before + o.registered_views().count();
                if config.calibrate_hand_eye {
                    calibration_share(config.calibration_views, taken, after)
                } else {
                    0
                }
            };
            explore_object(
                &mut ep,
                &nbv,
                &mut map,
                &region,
                table,
                &mut object,
                &calibration,
            )?;
        }
        ep.observer.event(&ExploreEvent::ObjectDone {
            object: j,
            stop: object.stop,
        });
        let dropped = matches!(object.stop, ObjectStop::NotAnObject { .. });
        // The views as prepared for the MAP registration, for the calibrated passes.
        let mut prepared = None;
        if !dropped && object.views.iter().any(|v| !v.cloud.is_empty()) {
            let mut seconds = 0.0;
            let registered = timed(&mut seconds, || {
                register_object(&object, config, phase_report.workcell.as_ref(), sweep)
            });
            object.times.registration += seconds;
            match registered {
                Ok((r, p)) => {
                    object.registration = Some(r);
                    prepared = Some(p);
                }
                Err(e) => object.registration_error = Some(e.to_string()),
            }
            ep.observer.event(&ExploreEvent::Registered {
                object: j,
                exploration: &object,
            });
        }
        objects.push(object);
        preparations.push(prepared);
    }
    let hand_eye = if config.calibrate_hand_eye {
        self_calibrate(
            &ep,
            &mut objects,
            &preparations,
            phase_report.workcell.as_ref(),
        )
    } else {
        None
    };
    register_again(&mut objects, &preparations, |object, prepared| {
        refine_along_rays(object, prepared, config)
    });
    if let Some(params) = config.surface {
        for object in &mut objects {
            let mut seconds = 0.0;
            let surface = timed(&mut seconds, || {
                fuse_surface(object, ep.rig.camera.spec(), params, config)
            });
            object.times.meshing += seconds;
            object.surface = surface?;
        }
    }
    Ok(Exploration {
        mode: config.mode,
        phase_one: phase_report,
        objects,
        grid: map.grid,
        collisions: ep.collisions,
        hand_eye,
    })
}

/// `register` run again on every object with prepared views, its time added to the
/// object's registration time and an error kept in the object's report.
fn register_again(
    objects: &mut [ObjectExploration],
    preparations: &[Option<MapPreparation>],
    mut register: impl FnMut(
        &mut ObjectExploration,
        &MapPreparation,
    ) -> Result<bool, crate::registration::RegistrationError>,
) {
    for (object, prepared) in objects.iter_mut().zip(preparations) {
        let Some(prepared) = prepared else {
            continue;
        };
        let mut seconds = 0.0;
        let outcome = timed(&mut seconds, || register(object, prepared));
        object.times.registration += seconds;
        if let Err(e) = outcome {
            object.registration_error = Some(e.to_string());
        }
    }
}

/// Calibrated registration passes at most (a safety net).
const CALIBRATION_PASSES: usize = 3;
/// The estimate has settled when `E` moves by less than this fraction of its own σ
/// between passes.
const CALIBRATION_SETTLED: f64 = 0.25;

/// The rig's self-calibration: the hand-eye correction and joint offsets from every
/// object's registration ([`estimate_hand_eye`]), then each object registered again with
/// its priors centred on the calibrated poses, until the estimate settles.
fn self_calibrate(
    ep: &Episode<'_, '_>,
    objects: &mut [ObjectExploration],
    preparations: &[Option<MapPreparation>],
    workcell: Option<&crate::perception::WorkcellAlignment>,
) -> Option<HandEyeEstimate> {
    let config = ep.config;
    let robot = &ep.rig.robot;
    let frame = ep.rig.camera.spec().frame.clone();
    let estimate = |objects: &[ObjectExploration]| {
        estimate_hand_eye(objects, robot, &frame, &config.uncertainty)
    };
    let mut current = estimate(objects)?;
    for pass in 1..=CALIBRATION_PASSES {
        register_again(objects, preparations, |object, prepared| {
            register_calibrated(object, prepared, config, workcell, &current, robot, &frame)
        });
        current.passes = pass;
        let Some(mut next) = estimate(objects) else {
            break;
        };
        next.passes = pass;
        let (dr, dt) = next.change_from(&current);
        current = next;
        let settled = |d: f64, sigma: f64| d < CALIBRATION_SETTLED * sigma;
        if settled(dr, current.sigma[0]) && settled(dt, current.sigma[1]) {
            break;
        }
    }
    Some(current)
}
