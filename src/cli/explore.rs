//! `nbv explore`: the method end to end on a scene in the twin, with a report, the models,
//! the map and pictures in an output directory.

use super::progress::ProgressObserver;
use anyhow::Result;
#[cfg(feature = "hw")]
use anyhow::{Context, bail};
use clap::{Args, ValueEnum};
use nbv_core::pipeline::ExploreMode;
use nbv_sweep::report::ExploreReport;
use std::path::PathBuf;

/// Arguments of `nbv explore`.
#[derive(Debug, Args)]
#[command(after_help = "\
Writes into OUT:
  report.json                  per object: views, viewpoints tried and failed, gain per view,
                               surface coverage, registration error (p-ICP-GPA and sequential
                               ICP) against ground truth, times per step; totals, collisions,
                               configuration and seed
  map/grid.nbvgrid             the occupancy grid after phase 1 and at the end (final.nbvgrid)
  map/clusters.ply             the phase-1 object clusters (label = cluster)
  mid_range.ply                the phase-1 sweep cloud (with sensor origins)
  objects/<name>/model.ply     the registered model (view property = view index)
  objects/<name>/views/*.ply   each view as acquired (view_00 is the phase-1 cluster)
  *.png                        scene, map front/back, view sequences, models before/after
                               registration (skipped with a warning when no GPU adapter exists)
  episode.rrd                  with --record: the episode for the Rerun viewer (robot, sweep,
                               grid, each view's candidates, path, camera and cloud, models,
                               gains, coverage, step times, decisions)
  bag/                         with --bag: a rosbag2 directory (bag_0.mcap, metadata.yaml) for
                               RViz, Foxglove and `ros2 bag play`: /tf, /tf_static,
                               /joint_states, /robot_description, the sweep cloud, each view's
                               points, depth image and camera info, the grid and the candidates
                               as markers, the models, the events (docs/bags.md)
Same scene and seed give the same report apart from the times.")]
pub struct ExploreArgs {
    /// Scene file, or the name of a built-in scene (paper-env1, paper-env2).
    #[arg(long)]
    pub scene: String,
    /// Output directory (created; existing files in it are replaced).
    #[arg(short, long)]
    pub output: PathBuf,
    /// The method, or a baseline.
    #[arg(long, value_enum, default_value_t = Mode::Hybrid)]
    pub mode: Mode,
    /// Overrides the scene's seed.
    #[arg(long)]
    pub seed: Option<u64>,
    /// Sets a scene parameter for this run: a dotted key of the scene file and a TOML
    /// value, e.g. `--set nbv.radius=0.45 --set nbv.gain_threshold=2.5` (repeatable; the
    /// keys a sweep's `[params]` takes).
    #[arg(long = "set", value_name = "KEY=VALUE", value_parser = nbv_scenes::overrides::parse_override)]
    pub set: Vec<(String, toml::Value)>,
    /// Skip the pictures.
    #[arg(long)]
    pub no_pictures: bool,
    /// Record the episode for the Rerun viewer: OUT/episode.rrd (a build with `--features
    /// rerun`; open it with `rerun OUT/episode.rrd`).
    #[arg(long)]
    pub record: bool,
    /// Write the episode as a ROS 2 bag: OUT/bag/, a rosbag2 directory (MCAP) for RViz,
    /// Foxglove and `ros2 bag play` (any build; works with --record).
    #[arg(long)]
    pub bag: bool,
    /// No progress bars.
    #[arg(long, short)]
    pub quiet: bool,
    /// Also compute each object's ground-truth ceiling (`nbv oracle`; about a minute on a
    /// paper scene) and measure the exploration against it: `oracle.json`, the report's
    /// `oracle` per object, `coverage_by_view.svg` (the twin only).
    #[arg(long)]
    pub oracle: bool,
    /// Which rig runs the pipeline: the twin, or the real drivers (built with `--features
    /// hw`) talking to the devices a rig file names.
    #[arg(long, value_enum, default_value_t = Backend::Sim)]
    pub backend: Backend,
    /// Rig file for `--backend hw`: device addresses and hand-eye calibration
    /// (examples/rigs/lab.toml, examples/rigs/emulated.toml).
    #[arg(long, required_if_eq("backend", "hw"))]
    pub rig: Option<PathBuf>,
    /// With `--backend hw`: serve the rig file's devices from wire-level emulators backed
    /// by the scene's twin (port 0 in an address picks a free port), so the real drivers run
    /// the whole pipeline without hardware.
    #[arg(long, requires = "rig")]
    pub emulate: bool,
}

/// `--backend`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Backend {
    /// The digital twin (nbv-sim).
    Sim,
    /// The real drivers (nbv-hw): SICK LMS400, Comau C4G, Dinast IPA-1110.
    Hw,
}

/// `--mode`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Mode {
    /// Laser sweep, then next-best views with the depth camera (the paper's method).
    Hybrid,
    /// The laser sweep only.
    MidOnly,
    /// The depth camera only: a survey of the table from above, then next-best views.
    ShortOnly,
}

impl From<Mode> for ExploreMode {
    fn from(m: Mode) -> Self {
        match m {
            Mode::Hybrid => ExploreMode::Hybrid,
            Mode::MidOnly => ExploreMode::MidOnly,
            Mode::ShortOnly => ExploreMode::ShortOnly,
        }
    }
}

/// Runs `nbv explore`.
pub fn run(args: ExploreArgs) -> Result<()> {
    let scene = nbv_scenes::overrides::load_for_run(&args.scene, &args.set, args.seed)?;
    if args.oracle && matches!(args.backend, Backend::Hw) {
        anyhow::bail!("--oracle needs the twin's truth: it runs with --backend sim only");
    }
    let report = match args.backend {
        Backend::Sim => {
            let mut observer = ProgressObserver::new(args.quiet);
            let extras = nbv_sweep::episode::Extras {
                pictures: !args.no_pictures,
                record: args.record,
                bag: args.bag,
                oracle: args.oracle,
                oracle_cache: None,
                outputs: nbv_sweep::episode::Outputs::All,
            };
            let report = nbv_sweep::episode::run_episode(
                &scene,
                args.mode.into(),
                &args.output,
                extras,
                &mut observer,
            );
            observer.finish();
            report?
        }
        Backend::Hw if args.record || args.bag => {
            anyhow::bail!("--record, --bag: episodes are recorded in the twin only (--backend sim)")
        }
        Backend::Hw => run_hw(&scene, &args)?,
    };
    println!("{}", super::explore_summary::summary(&report));
    Ok(())
}

#[cfg(feature = "hw")]
fn run_hw(scene: &nbv_scenes::Scene, args: &ExploreArgs) -> Result<ExploreReport> {
    let rig = args
        .rig
        .as_deref()
        .context("--backend hw needs --rig FILE")?;
    if args.output.exists() && !args.output.is_dir() {
        bail!("{}: exists and is not a directory", args.output.display());
    }
    let config = scene.explore_config(args.mode.into())?;
    let mut observer = ProgressObserver::new(args.quiet);
    let exploration = super::hw_backend::explore(scene, &config, rig, args.emulate, &mut observer)?;
    observer.finish();
    Ok(nbv_sweep::episode::finish_episode(
        scene,
        &config,
        &exploration,
        &args.output,
        !args.no_pictures,
        None,
        nbv_sweep::episode::Outputs::All,
    )?)
}

#[cfg(not(feature = "hw"))]
fn run_hw(_: &nbv_scenes::Scene, _: &ExploreArgs) -> Result<ExploreReport> {
    anyhow::bail!(
        "--backend hw: this nbv was built without the real drivers; build it with `--features hw`"
    )
}
