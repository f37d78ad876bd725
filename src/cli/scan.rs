//! `nbv scan …`: one acquisition on the twin of a scene — the phase-1 LMS400 sweep
//! (`scan mid`) or one Dinast frame from a given view (`scan short`) — written as a point
//! cloud (PLY or PCD, by extension) and, for the camera, a 16-bit PNG depth image.
//!
//! Points are in the world frame as the pipeline sees them: posed with the joints the arm
//! reports and the nominal robot model, so they carry the scene's `[errors]`. Each point
//! has its sensor origin (`ox oy oz` / `vp_x vp_y vp_z`), its ground-truth label (`label`:
//! 0 table, 1 robot, 1000 + i obstacle i, 2000 + i object i) and its noise-free true
//! point (`tx ty tz`). Nothing is written unless the whole acquisition succeeded. The
//! acquisitions and their clouds are the twin's ([`nbv_sim::rig::SimRig`]); this file
//! parses the arguments, writes the files and prints.

use anyhow::{Context, Result, bail};
use clap::{Args, Subcommand};
use nbv_core::cloud::io::{
    CloudFormat, DEFAULT_DEPTH_SCALE, Encoding, FloatType, WriteOptions, write_cloud,
    write_depth_png,
};
use nbv_core::math::{Pose, pose_from_xyz_rpy};
use nbv_core::rig::{DepthCamera, LabelCounts, acquire_sweep};
use nbv_scenes::overrides::load;
use nbv_sim::rig::SimRig;
use std::path::{Path, PathBuf};

/// Arguments of `nbv scan`.
#[derive(Debug, Args)]
pub struct ScanArgs {
    #[command(subcommand)]
    command: ScanCommand,
}

/// Options shared by both scans.
#[derive(Debug, Args)]
struct Common {
    /// Scene file, or the name of a built-in scene (see `nbv scene list`).
    #[arg(long)]
    scene: String,
    /// Output cloud, `.ply` or `.pcd` (written atomically).
    #[arg(short, long)]
    output: PathBuf,
    /// Seed of the sensor noise and pose errors [default: the scene's seed]. The same
    /// scene and seed give byte-identical files.
    #[arg(long, value_parser = clap::value_parser!(u64).range(0..=i64::MAX as u64))]
    seed: Option<u64>,
    /// Write ASCII instead of little-endian binary.
    #[arg(long)]
    ascii: bool,
    /// Write coordinates as 64-bit doubles instead of 32-bit floats.
    #[arg(long)]
    double: bool,
}

#[derive(Debug, Subcommand)]
enum ScanCommand {
    /// The phase-1 mid-range observation: the arm moves from home to the first waypoint of
    /// the scene's `[sweep]`, then follows the waypoints while the LMS400 streams lines
    /// (190 per second, each cast from the sensor pose at its time); writes one cloud.
    ///
    /// Example: `nbv scan mid --scene paper-env1 -o cloud.ply`
    Mid {
        #[command(flatten)]
        common: Common,
    },
    /// One short-range frame: the arm is placed (inverse kinematics, no path planning;
    /// refused if it would touch anything there) so the Dinast camera is at VIEW, and the
    /// camera captures one 320×240 frame.
    ///
    /// Example, looking straight down from 0.75 m above the floor: `nbv scan short --scene paper-env1
    /// --view "0.75 0 0.75 180 0 0" -o frame.ply --depth depth.png`
    Short {
        #[command(flatten)]
        common: Common,
        /// Commanded camera pose in the world frame, "x y z roll pitch yaw" (metres,
        /// degrees; URDF roll-pitch-yaw about fixed x, y, z). Optical frame: z along the
        /// view, x to the image's right, y down the image.
        #[arg(long, allow_hyphen_values = true)]
        view: String,
        /// Also write the organised depth image as a 16-bit PNG (1 mm per unit, z along the
        /// optical axis, 0 = no return).
        #[arg(long)]
        depth: Option<PathBuf>,
    },
}

/// Runs `nbv scan …`.
pub fn run(args: ScanArgs) -> Result<()> {
    match args.command {
        ScanCommand::Mid { common } => scan_mid(&common),
        ScanCommand::Short {
            common,
            view,
            depth,
        } => scan_short(&common, &view, depth.as_deref()),
    }
}

impl Common {
    fn write_options(&self) -> WriteOptions {
        WriteOptions {
            encoding: if self.ascii {
                Encoding::Ascii
            } else {
                Encoding::Binary
            },
            float: if self.double {
                FloatType::F64
            } else {
                FloatType::F32
            },
        }
    }

    /// The scene with the seed override, and a rig in its twin.
    fn rig(&self) -> Result<(nbv_scenes::Scene, SimRig)> {
        let mut scene = load(&self.scene)?;
        if let Some(seed) = self.seed {
            scene.seed = seed;
        }
        let rig = SimRig::from_scene(&scene)
            .with_context(|| format!("{}: building the twin", self.scene))?;
        Ok((scene, rig))
    }
}

/// Checks an output path before any work: known extension, existing directory.
fn check_output(path: &Path, what: &str, cloud: bool) -> Result<()> {
    if cloud {
        CloudFormat::from_path(path).with_context(|| format!("{what} {}", path.display()))?;
    } else if !path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("png"))
    {
        bail!(
            "{what} {}: the depth image must be a .png file",
            path.display()
        );
    }
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    if !dir.is_dir() {
        bail!(
            "{what} {}: directory {} does not exist",
            path.display(),
            dir.display()
        );
    }
    Ok(())
}

/// The phase-1 sweep on the twin, written as one cloud.
fn scan_mid(c: &Common) -> Result<()> {
    check_output(&c.output, "output", true)?;
    let (scene, mut rig) = c.rig()?;
    let waypoints = scene.sweep.joint_waypoints();
    let sweep = acquire_sweep(
        &mut rig.arm,
        &mut rig.scanner,
        &waypoints,
        scene.sweep.joint_speed_fraction,
    )
    .with_context(|| {
        format!(
            "{}: the sweep failed (check [sweep] waypoints_deg and joint_speed_fraction)",
            c.scene
        )
    })?;
    let cloud = rig.sweep_cloud(&sweep)?;
    if cloud.is_empty() {
        bail!(
            "{}: the sweep returned no point (check [sweep] and [sensors.mid_range])",
            c.scene
        );
    }
    write_cloud(&c.output, &cloud, &c.write_options())?;
    let duration = match (sweep.lines.first(), sweep.lines.last()) {
        (Some(a), Some(b)) => b.time - a.time,
        _ => 0.0,
    };
    let LabelCounts {
        table,
        objects,
        obstacles,
        robot,
    } = LabelCounts::of(&cloud);
    println!(
        "{}: {} lines over {duration:.2} s, {} points ({table} table, {objects} objects, \
         {obstacles} obstacles, {robot} robot) -> {}",
        scene.name,
        sweep.lines.len(),
        cloud.len(),
        c.output.display()
    );
    Ok(())
}

/// Parses "x y z roll pitch yaw" (metres, degrees; spaces and/or commas).
fn parse_view(view: &str) -> Result<Pose> {
    let values: Vec<f64> = view
        .split(|ch: char| ch.is_whitespace() || ch == ',')
        .filter(|s| !s.is_empty())
        .map(|s| {
            s.parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .with_context(|| format!("--view \"{view}\": `{s}` is not a finite number"))
        })
        .collect::<Result<_>>()?;
    let [x, y, z, roll, pitch, yaw] = values[..] else {
        bail!(
            "--view \"{view}\": expected 6 numbers \"x y z roll pitch yaw\" (m, degrees), got {}",
            values.len()
        );
    };
    Ok(pose_from_xyz_rpy(
        [x, y, z],
        [roll.to_radians(), pitch.to_radians(), yaw.to_radians()],
    ))
}

/// One depth frame from `view`, written as a cloud (and, if asked, as a depth image).
fn scan_short(c: &Common, view: &str, depth: Option<&Path>) -> Result<()> {
    check_output(&c.output, "output", true)?;
    if let Some(d) = depth {
        check_output(d, "--depth", false)?;
        if d == c.output {
            bail!("--depth and --output are the same file {}", d.display());
        }
    }
    let target = parse_view(view)?;
    let (scene, mut rig) = c.rig()?;
    let q = rig
        .camera_joints(&target)
        .with_context(|| format!("--view \"{view}\": the arm cannot put the camera there"))?;
    rig.arm
        .teleport(q)
        .with_context(|| format!("--view \"{view}\": the arm cannot stand there"))?;
    let frame = rig.camera.capture()?;
    let cloud = rig.frame_cloud(&frame, &q)?;
    if let Some(d) = depth {
        // Both files or none: the depth image first, removed if the cloud fails.
        write_depth_png(
            d,
            frame.width as u32,
            frame.height as u32,
            &frame.depth,
            DEFAULT_DEPTH_SCALE,
        )?;
        if let Err(e) = write_cloud(&c.output, &cloud, &c.write_options()) {
            let _ = std::fs::remove_file(d);
            return Err(e.into());
        }
    } else {
        write_cloud(&c.output, &cloud, &c.write_options())?;
    }
    let LabelCounts {
        table,
        objects,
        obstacles,
        robot,
    } = LabelCounts::of(&cloud);
    let (near, far) = cloud.range_extent();
    println!(
        "{}: {}x{} frame, {} valid pixels ({table} table, {objects} objects, {obstacles} \
         obstacles, {robot} robot), ranges {near:.3}–{far:.3} m -> {}{}",
        scene.name,
        frame.width,
        frame.height,
        cloud.len(),
        c.output.display(),
        depth
            .map(|d| format!(", {}", d.display()))
            .unwrap_or_default()
    );
    Ok(())
}
