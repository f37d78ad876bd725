//! One episode: the method on a scene in the twin, measured against the scene's truth
//! ([`crate::report::evaluate`]), its outputs written into a directory — what `nbv
//! explore` runs, and what a sweep runs per episode.
//!
//! ```text
//! OUT/report.json                the report (written atomically, last)
//! OUT/map/grid.nbvgrid           the occupancy grid after phase 1 (final.nbvgrid: at the end)
//! OUT/mid_range.ply              the phase-1 sweep cloud
//! OUT/objects/<name>/model.ply   the registered model; views/view_NN.ply each view
//! OUT/objects/<name>/model_mesh.ply  the fused surface (triangles, normals, world frame)
//! OUT/objects/<name>/rgbd/       its registered camera views in Open3D's layout
//! OUT/objects/<name>/truth.stl   the true object, world frame (the twin's ground truth)
//! OUT/*.png                      the pictures, when asked ([`crate::pictures`])
//! OUT/oracle.json                the ground-truth ceiling, when asked ([`crate::oracle`]),
//! OUT/coverage_by_view.svg       and each object's coverage by view beside it
//! OUT/episode.rrd                the Rerun recording, when asked (feature `rerun`)
//! OUT/bag/                       the episode as a ROS 2 bag, when asked ([`crate::bag_recording`])
//! ```

use crate::error::{Context, Result, bail};
use crate::report::{ExploreReport, evaluate};
use nbv_core::cloud::io::{WriteOptions, write_cloud};
use nbv_core::mesh::io::{write_ply_mesh, write_stl_file};
use nbv_core::pipeline::{Exploration, ExploreConfig, ExploreMode, ExploreObserver, object_views};
use nbv_sim::rig::SimRig;
use std::path::Path;

/// Which of an episode's files it writes besides its report.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum Outputs {
    /// Every file of the layout above: the sweep cloud, the grids, each object's model,
    /// views, fused surface, `rgbd/` and truth.
    #[default]
    All,
    /// The report alone (with the oracle's files, the pictures, the recording and the bag
    /// when asked): an episode's files take about 12 MB, which a sweep of thousands does
    /// not keep.
    ReportOnly,
}

/// What an episode writes besides the report, the models and the map.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Extras {
    /// Which files besides the report ([`Outputs::All`] unless asked).
    pub outputs: Outputs,
    /// The pictures ([`crate::pictures`]).
    pub pictures: bool,
    /// The recording for the Rerun viewer, `episode.rrd` (needs the feature `rerun`).
    pub record: bool,
    /// The episode as a ROS 2 bag, `bag/` ([`crate::bag_recording`]; any build).
    pub bag: bool,
    /// The ground-truth ceiling ([`crate::oracle`]): `oracle.json`, each object measured
    /// against it in the report, and `coverage_by_view.svg`.
    pub oracle: bool,
    /// Where the oracles are shared between episodes ([`crate::oracle::OracleCache`]): a
    /// sweep's `DIR/oracles/`.
    pub oracle_cache: Option<std::path::PathBuf>,
}

/// The error of [`Extras::record`] in a build without the feature `rerun`.
pub const NO_RECORDING: &str =
    "--record: this build has no episode recording; build it with `--features rerun`";

/// One exploration of `scene` in the twin, its events to `observer`, its outputs written
/// into `out`. The bag, when asked, sees each event after `observer` (and before the
/// Rerun recorder); neither changes the episode.
pub fn run_episode(
    scene: &nbv_scenes::Scene,
    mode: ExploreMode,
    out: &Path,
    extras: Extras,
    observer: &mut dyn ExploreObserver,
) -> Result<ExploreReport> {
    check_output(out)?;
    if extras.record && !cfg!(feature = "rerun") {
        return Err(crate::SweepError::Invalid(NO_RECORDING.into()));
    }
    let mut bag = if extras.bag {
        Some(crate::bag_recording::BagRecorder::create(out, scene)?)
    } else {
        None
    };
    let mut tee;
    let observer: &mut dyn ExploreObserver = match bag.as_mut() {
        Some(bag) => {
            tee = bag.observe(observer);
            &mut tee
        }
        None => observer,
    };
    let (report, exploration) = if extras.record {
        record_episode(scene, mode, out, extras, observer)?
    } else {
        let (config, exploration) = explore_in_twin(scene, mode, observer)?;
        let report = finish_in_twin(scene, &config, &exploration, out, extras)?;
        (report, exploration)
    };
    if let Some(bag) = bag {
        bag.finish(&exploration, &report)?;
    }
    Ok(report)
}

/// [`finish_episode`] of an exploration in the twin, with the scene's oracle when
/// `extras` asks for it.
fn finish_in_twin(
    scene: &nbv_scenes::Scene,
    config: &ExploreConfig,
    exploration: &Exploration,
    out: &Path,
    extras: Extras,
) -> Result<ExploreReport> {
    let oracle = oracle_of(scene, exploration, &extras)?;
    finish_episode(
        scene,
        config,
        exploration,
        out,
        extras.pictures,
        oracle.as_ref(),
        extras.outputs,
    )
}

/// The scene's oracle when `extras` asks for it, with the views `exploration` took.
fn oracle_of(
    scene: &nbv_scenes::Scene,
    exploration: &Exploration,
    extras: &Extras,
) -> Result<Option<crate::oracle::OracleReport>> {
    if !extras.oracle {
        return Ok(None);
    }
    let meshes = scene.object_meshes()?;
    let views = exploration
        .objects
        .iter()
        .filter_map(|o| {
            let i = crate::matching::true_object(o, scene, &meshes)?;
            let taken = o.views.iter().map(|v| (v.viewpoint, v.joints)).collect();
            Some((scene.objects[i].name.clone(), taken))
        })
        .collect();
    let options = crate::oracle::OracleOptions {
        views,
        cache: extras
            .oracle_cache
            .as_ref()
            .map(crate::oracle::OracleCache::new),
        ..Default::default()
    };
    crate::oracle::oracle(scene, &options).map(Some)
}

/// The episode of [`run_episode`] with its events recorded into `out/episode.rrd` as
/// well: the report and the exploration.
#[cfg(feature = "rerun")]
fn record_episode(
    scene: &nbv_scenes::Scene,
    mode: ExploreMode,
    out: &Path,
    extras: Extras,
    observer: &mut dyn ExploreObserver,
) -> Result<(ExploreReport, Exploration)> {
    let mut recorder = crate::recording::EpisodeRecorder::create(out, scene)?;
    let (config, exploration) = explore_in_twin(scene, mode, &mut recorder.observe(observer))?;
    let report = finish_in_twin(scene, &config, &exploration, out, extras)?;
    recorder.finish(scene, &exploration, &report)?;
    Ok((report, exploration))
}

#[cfg(not(feature = "rerun"))]
fn record_episode(
    _: &nbv_scenes::Scene,
    _: ExploreMode,
    _: &Path,
    _: Extras,
    _: &mut dyn ExploreObserver,
) -> Result<(ExploreReport, Exploration)> {
    Err(crate::SweepError::Invalid(NO_RECORDING.into()))
}

/// Fails unless `out` is a directory or does not exist yet.
pub fn check_output(out: &Path) -> Result<()> {
    if out.exists() && !out.is_dir() {
        bail!("{}: exists and is not a directory", out.display());
    }
    Ok(())
}

/// The method on `scene` in the twin: the configuration it ran with and what it found.
pub fn explore_in_twin(
    scene: &nbv_scenes::Scene,
    mode: ExploreMode,
    observer: &mut dyn ExploreObserver,
) -> Result<(ExploreConfig, Exploration)> {
    let config = scene.explore_config(mode)?;
    let mut rig = SimRig::from_scene(scene).context("building the twin")?;
    let exploration = rig.explore(&config, observer)?;
    Ok((config, exploration))
}

/// Evaluates an exploration against the scene's truth (and against its `oracle`, when
/// given: `oracle.json` and `coverage_by_view.svg` written beside the report) and writes
/// the report, the `outputs` (the models, the map, …) and (if asked) the pictures into
/// `out`.
pub fn finish_episode(
    scene: &nbv_scenes::Scene,
    config: &ExploreConfig,
    exploration: &Exploration,
    out: &Path,
    pictures: bool,
    oracle: Option<&crate::oracle::OracleReport>,
    outputs: Outputs,
) -> Result<ExploreReport> {
    let mut report = evaluate(scene, config, exploration)?;
    if let Some(oracle) = oracle {
        report.attach_oracle(oracle);
        check_output(out)?;
        std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
        crate::layout::write_json(&out.join("oracle.json"), oracle)?;
        crate::plots::write_episode_coverage(out, &report)?;
    }
    write_outputs(out, scene, config, exploration, &report, outputs)?;
    if pictures {
        crate::pictures::write(out, scene, exploration, &report);
    }
    Ok(report)
}

/// The `outputs`, then the report (last: its presence marks the episode written).
fn write_outputs(
    out: &Path,
    scene: &nbv_scenes::Scene,
    config: &ExploreConfig,
    exploration: &Exploration,
    report: &ExploreReport,
    outputs: Outputs,
) -> Result<()> {
    check_output(out)?;
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    if outputs == Outputs::All {
        write_files(out, scene, config, exploration, report)?;
    }
    crate::layout::write_json(&out.join("report.json"), report)
}

/// [`Outputs::All`]'s files: the sweep cloud, the grids and each object's.
fn write_files(
    out: &Path,
    scene: &nbv_scenes::Scene,
    config: &ExploreConfig,
    exploration: &Exploration,
    report: &ExploreReport,
) -> Result<()> {
    std::fs::create_dir_all(out.join("map"))
        .with_context(|| format!("creating {}", out.display()))?;
    let opts = WriteOptions::default();
    write_cloud(
        out.join("mid_range.ply"),
        &exploration.phase_one.cloud,
        &opts,
    )?;
    write_grid(&out.join("map/grid.nbvgrid"), &exploration.phase_one.grid)?;
    write_grid(&out.join("map/final.nbvgrid"), &exploration.grid)?;
    let truths = scene.object_meshes()?;
    for (object, entry) in exploration.objects.iter().zip(&report.objects) {
        let dir = out.join("objects").join(&entry.name);
        std::fs::create_dir_all(dir.join("views"))
            .with_context(|| format!("creating {}", dir.display()))?;
        write_cloud(dir.join("model.ply"), &object.model()?, &opts)?;
        if let Some(surface) = &object.surface {
            let path = dir.join("model_mesh.ply");
            write_ply_mesh(&surface.mesh, &surface.normals, &path)
                .with_context(|| format!("writing {}", path.display()))?;
        }
        if let Some(i) = scene.objects.iter().position(|o| o.name == entry.name) {
            let path = dir.join("truth.stl");
            write_stl_file(&truths[i], &path)
                .with_context(|| format!("writing {}", path.display()))?;
        }
        if let Some(views) = object_views(object, &scene.sensors.short_range.spec(), config) {
            let path = dir.join("rgbd");
            views
                .write(&path)
                .with_context(|| format!("writing {}", path.display()))?;
        }
        write_cloud(dir.join("views/view_00.ply"), &object.cluster, &opts)?;
        for (k, v) in object.views.iter().enumerate() {
            write_cloud(
                dir.join(format!("views/view_{:02}.ply", k + 1)),
                &v.cloud,
                &opts,
            )?;
        }
    }
    Ok(())
}

fn write_grid(path: &Path, grid: &nbv_core::occupancy::OccupancyGrid) -> Result<()> {
    grid.save(path)
        .with_context(|| format!("writing {}", path.display()))
}
