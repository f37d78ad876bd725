//! `nbv explore --backend hw`: the pipeline on the real drivers (nbv-hw), against the
//! devices a rig file names or, with `--emulate`, against wire-level emulators backed by
//! the scene's twin. The only place that knows both backends.

use anyhow::{Context, Result};
use nbv_core::pipeline::{Exploration, ExploreConfig, ExploreObserver, explore as run_pipeline};
use nbv_hw::emulated_rig::{BackingRig, EmulatedRig};
use nbv_hw::hw_rig::HwRig;
use nbv_hw::rig_file::RigFile;
use nbv_scenes::Scene;
use nbv_sim::rig::SimRig;
use std::path::Path;

/// Explores `scene` through the real drivers of the rig file `rig`.
pub fn explore(
    scene: &Scene,
    config: &ExploreConfig,
    rig: &Path,
    emulate: bool,
    observer: &mut dyn ExploreObserver,
) -> Result<Exploration> {
    let rig_file = RigFile::load(rig)?;
    let laser = scene.sensors.mid_range.spec();
    let camera = scene.sensors.short_range.spec();
    let robot = rig_file.robot(&scene.robot.urdf, &laser.frame, &camera.frame)?;
    let base = scene.robot.base.to_pose();

    let mut emulators = if emulate {
        let twin_scene = scene.clone();
        let factory = Box::new(move || {
            let rig = SimRig::from_scene(&twin_scene).map_err(|e| e.to_string())?;
            let (controller_model, _) = rig.robot_and_base();
            Ok(BackingRig {
                arm: Box::new(rig.arm),
                scanner: Box::new(rig.scanner),
                camera: Box::new(rig.camera),
                controller_model: Some(controller_model),
            })
        });
        Some(EmulatedRig::start(&rig_file, factory)?)
    } else {
        None
    };
    let (devices, transport) = match emulators.as_mut() {
        Some(e) => (e.rig_file().clone(), e.camera_transport()),
        None => (rig_file, None),
    };
    let mut hw = HwRig::connect(&devices, laser, camera, transport)
        .with_context(|| format!("connecting to the rig of {}", rig.display()))?;
    let exploration = run_pipeline(&mut hw.rig(robot, base), config, observer)?;
    drop(hw);
    if let Some(e) = emulators {
        let stats = e.finish()?;
        tracing::info!(?stats, "emulated rig");
    }
    Ok(exploration)
}
