//! `nbv scene …`: validate and describe scene files, generate random scenes, and write the
//! library's object meshes.

use anyhow::{Context, Result};
use clap::{Args, Subcommand};
use nbv_core::kinematics::Robot;
use nbv_scenes::generator::{GeneratorConfig, ShapeSet, generate_with};
use std::path::PathBuf;

/// Arguments of `nbv scene`.
#[derive(Debug, Args)]
pub struct SceneArgs {
    #[command(subcommand)]
    command: SceneCommand,
}

#[derive(Debug, Subcommand)]
enum SceneCommand {
    /// Check a scene file (syntax, keys, values, meshes, layout); prints a one-line summary.
    ///
    /// SCENE is a path, or the name of a built-in scene (see `nbv scene list`).
    Validate {
        /// Scene file or built-in scene name.
        scene: String,
    },
    /// Print the objects (mesh size, pose, clearance), the obstacles and the grid.
    Describe {
        /// Scene file or built-in scene name.
        scene: String,
    },
    /// List the built-in scenes.
    List,
    /// Write a random, valid scene (seeded: the same seed gives the same file).
    Generate {
        /// Seed of the random choices (also the scene's episode seed).
        #[arg(long, value_parser = clap::value_parser!(u64).range(0..=i64::MAX as u64))]
        seed: u64,
        /// Number of objects, drawn from the shape set (repeated beyond its size).
        #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u64).range(1..=12))]
        objects: u64,
        /// Objects to draw from: `paper` (jug, bottle-a, bottle-b, mallet, horse, box) or
        /// `all` (also figurine, pitcher, tall-bottle, spatula, bowl).
        #[arg(long, default_value = "paper", value_parser = parse_shapes)]
        shapes: ShapeSet,
        /// Output scene file (written atomically; mesh and URDF paths relative to it).
        #[arg(short, long)]
        output: PathBuf,
        /// Robot URDF the scene refers to [default: assets/urdf/comau_smart_six.urdf of
        /// this source tree].
        #[arg(long)]
        urdf: Option<PathBuf>,
        /// Directory with the library meshes `<object>.stl` [default: assets/meshes of
        /// this source tree].
        #[arg(long)]
        mesh_dir: Option<PathBuf>,
    },
    /// Generate the library's object meshes as binary STL files (`<name>.stl`).
    Meshes {
        /// Output directory (created if missing).
        #[arg(short, long)]
        output: PathBuf,
    },
}

/// `--shapes`: `paper` or `all`.
fn parse_shapes(s: &str) -> Result<ShapeSet, String> {
    s.parse()
}

/// Runs `nbv scene …`.
pub fn run(args: SceneArgs) -> Result<()> {
    match args.command {
        SceneCommand::Validate { scene } => {
            let s = nbv_scenes::overrides::load(&scene)?;
            println!(
                "ok: {} — {} objects, {} obstacles, grid {}x{}x{} ({} voxels)",
                s.name,
                s.objects.len(),
                s.obstacles.len(),
                s.workspace.dims()[0],
                s.workspace.dims()[1],
                s.workspace.dims()[2],
                s.workspace.voxel_count()
            );
        }
        SceneCommand::Describe { scene } => {
            let s = nbv_scenes::overrides::load(&scene)?;
            let robot = Robot::from_urdf_file(&s.robot.urdf)
                .with_context(|| format!("loading the robot of {scene}"))?;
            let reach = robot.reachability(s.robot.base.to_pose(), &s.sensors.short_range.frame);
            let summary = nbv_scenes::describe::describe(&s, Some(&reach))
                .with_context(|| format!("describing {scene}"))?;
            print!("{}", summary.to_text(&s));
            let world = nbv_sim::world::TwinWorld::from_scene(&s)
                .with_context(|| format!("building the twin world of {scene}"))?;
            let contacts = world.contacts();
            if contacts.is_empty() {
                println!(
                    "home configuration {:?} deg: collision-free",
                    s.robot.home_deg
                );
            } else {
                let list: Vec<String> = contacts.iter().map(ToString::to_string).collect();
                println!(
                    "home configuration {:?} deg: IN COLLISION: {}",
                    s.robot.home_deg,
                    list.join("; ")
                );
            }
        }
        SceneCommand::List => {
            for name in nbv_scenes::builtin::names() {
                println!("{name}");
            }
        }
        SceneCommand::Generate {
            seed,
            objects,
            shapes,
            output,
            urdf,
            mesh_dir,
        } => {
            let n = usize::try_from(objects).context("object count")?;
            let mut config = GeneratorConfig {
                shapes,
                ..GeneratorConfig::default()
            };
            let absolute = |p: PathBuf| std::path::absolute(&p).unwrap_or(p);
            if let Some(urdf) = urdf {
                config.urdf = absolute(urdf);
            }
            if let Some(dir) = mesh_dir {
                config.mesh_dir = absolute(dir);
            }
            // Objects are placed only where the short-range sensor has reachable viewpoints.
            let robot = Robot::from_urdf_file(&config.urdf)
                .with_context(|| format!("loading the robot {}", config.urdf.display()))?;
            let reach = robot.reachability(nbv_core::math::Pose::identity(), "dinast");
            let scene = generate_with(seed, n, &config, &reach)
                .with_context(|| format!("generating a scene with seed {seed}"))?;
            // Validate before writing anything: no file unless it is a valid scene.
            scene
                .validate()
                .with_context(|| format!("validating the generated scene (seed {seed})"))?;
            scene
                .save(&output)
                .with_context(|| format!("writing {}", output.display()))?;
            println!(
                "wrote {} ({} objects)",
                output.display(),
                scene.objects.len()
            );
        }
        SceneCommand::Meshes { output } => {
            std::fs::create_dir_all(&output)
                .with_context(|| format!("creating {}", output.display()))?;
            let written = nbv_scenes::meshgen::library::write_library(&output)
                .with_context(|| format!("writing meshes to {}", output.display()))?;
            for p in written {
                println!("wrote {}", p.display());
            }
        }
    }
    Ok(())
}
