//! `nbv scene …`: validate and describe scene files, generate random scenes, and write the
//! library's object meshes.

use anyhow::{Context, Result, bail};
use clap::{Args, Subcommand};
use nbv_core::kinematics::Robot;
use nbv_scenes::Scene;
use nbv_scenes::generator::{GeneratorConfig, generate_with};
use std::path::{Path, PathBuf};

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
        /// Number of objects, drawn from the library (jug, bottle-a, bottle-b, mallet,
        /// horse, box; repeated beyond six).
        #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u64).range(1..=12))]
        objects: u64,
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

/// "Can the arm put `frame` at this world pose?": closed-form IK of the frame through its
/// fixed transform to the flange, for a robot mounted at `base`.
fn sensor_reachability<'a>(
    robot: &'a Robot,
    base: nbv_core::math::Pose,
    frame: &'a str,
) -> impl Fn(&nbv_core::math::Pose) -> bool + 'a {
    let base_inv = base.inverse();
    move |pose| robot.reachable(frame, &(base_inv * pose)).unwrap_or(false)
}

/// Runs `nbv scene …`.
pub fn run(args: SceneArgs) -> Result<()> {
    match args.command {
        SceneCommand::Validate { scene } => {
            let s = load(&scene)?;
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
            let s = load(&scene)?;
            let robot = Robot::from_urdf_file(&s.robot.urdf)
                .with_context(|| format!("loading the robot of {scene}"))?;
            let reach =
                sensor_reachability(&robot, s.robot.base.to_pose(), &s.sensors.short_range.frame);
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
            output,
            urdf,
            mesh_dir,
        } => {
            let n = usize::try_from(objects).context("object count")?;
            let mut config = GeneratorConfig::default();
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
            let reach = sensor_reachability(&robot, nbv_core::math::Pose::identity(), "dinast");
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

/// `base` with each dotted key set to its value (`nbv explore --set`, a sweep's
/// `[params]`), in order, checked by the scene's own validation so a bad key or value names
/// itself; `nbv.preset` first resets every `[nbv]` value to the preset's;
/// `origin` says where the overrides came from, `name` names the result in errors.
pub fn with_overrides(
    base: &Scene,
    overrides: &[(String, toml::Value)],
    origin: &str,
    name: &str,
) -> Result<Scene> {
    if overrides.is_empty() {
        return Ok(base.clone());
    }
    let mut value = toml::Value::try_from(base).context("scene to TOML")?;
    for (key, v) in overrides {
        if key == "nbv.preset" {
            // A preset replaces every `[nbv]` value (keys set after it apply on top).
            let preset: nbv_scenes::schema::NbvPreset = v
                .clone()
                .try_into()
                .with_context(|| format!("{origin}: `{key}` = {v}"))?;
            let values = toml::Value::try_from(nbv_scenes::schema::Nbv::preset(preset))
                .context("[nbv] to TOML")?;
            if let Some(table) = value.as_table_mut() {
                table.insert("nbv".into(), values);
            }
            continue;
        }
        set_dotted(&mut value, key, v.clone()).with_context(|| format!("{origin}: `{key}`"))?;
    }
    let text = toml::to_string(&value).context("scene to TOML")?;
    // The base scene's file paths are already resolved (absolute, or relative to the
    // working directory), so they are read back against the working directory.
    Ok(Scene::from_toml_str(
        &text,
        Path::new("."),
        Path::new(name),
    )?)
}

/// The scene a single run uses: `scene` (path or built-in name) with the `--set` overrides
/// and, if given, the `--seed`.
pub fn load_for_run(
    scene: &str,
    set: &[(String, toml::Value)],
    seed: Option<u64>,
) -> Result<Scene> {
    let mut s = with_overrides(&load(scene)?, set, "--set", &format!("{scene} with --set"))?;
    if let Some(seed) = seed {
        s.seed = seed;
    }
    Ok(s)
}

/// Parses `KEY=VALUE` of `--set`: a dotted scene key and a TOML value (`0.45`, `16`,
/// `"kl"`, `[1, 2]`; a bare word is taken as a string).
pub fn parse_override(text: &str) -> Result<(String, toml::Value), String> {
    let (key, value) = text
        .split_once('=')
        .ok_or_else(|| format!("`{text}`: expected KEY=VALUE (e.g. nbv.radius=0.45)"))?;
    let key = key.trim();
    if key.is_empty() || !key.contains('.') {
        return Err(format!(
            "`{key}` is not a dotted scene key (e.g. nbv.radius)"
        ));
    }
    let value = value.trim();
    let parsed = toml::from_str::<toml::Table>(&format!("v = {value}"))
        .ok()
        .and_then(|mut t| t.remove("v"))
        .unwrap_or_else(|| toml::Value::String(value.to_string()));
    Ok((key.to_string(), parsed))
}

/// A scene from a path, or a built-in one by name when no such file exists.
pub fn load(scene: &str) -> Result<Scene> {
    let path = Path::new(scene);
    if !path.exists() && nbv_scenes::builtin::text(scene).is_some() {
        return nbv_scenes::builtin::load(scene).with_context(|| format!("built-in scene {scene}"));
    }
    if !path.exists() {
        bail!(
            "{scene}: no such file, and no built-in scene of that name (built-in: {})",
            nbv_scenes::builtin::names().join(", ")
        );
    }
    Ok(Scene::load(path)?)
}

/// Sets `a.b.c` in a TOML table; every table on the way must exist (a typo is an error
/// rather than a new, ignored key).
pub(crate) fn set_dotted(root: &mut toml::Value, key: &str, value: toml::Value) -> Result<()> {
    let parts: Vec<&str> = key.split('.').collect();
    let mut at = root;
    for (k, part) in parts.iter().enumerate() {
        let table = at
            .as_table_mut()
            .ok_or_else(|| anyhow::anyhow!("`{}` is not a table", parts[..k].join(".")))?;
        if k + 1 == parts.len() {
            if !table.contains_key(*part) {
                bail!("the scene has no key `{key}`");
            }
            table.insert((*part).to_string(), value);
            return Ok(());
        }
        at = table
            .get_mut(*part)
            .ok_or_else(|| anyhow::anyhow!("the scene has no table `{}`", parts[..=k].join(".")))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dotted_keys_must_exist() {
        let mut v: toml::Value = toml::from_str("[nbv]\nalpha_u = 4.0").unwrap();
        set_dotted(&mut v, "nbv.alpha_u", toml::Value::Float(2.0)).unwrap();
        assert_eq!(v["nbv"]["alpha_u"], toml::Value::Float(2.0));
        let e = set_dotted(&mut v, "nbv.alpha_x", toml::Value::Float(2.0)).unwrap_err();
        assert!(e.to_string().contains("no key `nbv.alpha_x`"));
        let e = set_dotted(&mut v, "nvb.alpha_u", toml::Value::Float(2.0)).unwrap_err();
        assert!(e.to_string().contains("no table `nvb`"));
    }

    #[test]
    fn overrides_keep_the_paths_of_a_scene_file_given_relative() {
        // Tests run in the package root, where scenes/ and assets/ are.
        let base = load("scenes/paper-env1.toml").unwrap();
        let set = [parse_override("nbv.radius=0.45").unwrap()];
        let s = with_overrides(&base, &set, "--set", "env1 with --set").unwrap();
        assert_eq!(s.nbv.radius, 0.45);
        assert_eq!(s.robot.urdf, base.robot.urdf);
        assert!(s.robot.urdf.exists(), "{}", s.robot.urdf.display());
        for (a, b) in s.objects.iter().zip(&base.objects) {
            assert_eq!(a.mesh, b.mesh);
        }
    }

    #[test]
    fn a_preset_replaces_the_nbv_section_and_later_keys_apply_on_top() {
        use nbv_scenes::schema::{Nbv, NbvPreset};
        let base = load("paper-env1").unwrap();
        let set = [
            parse_override("nbv.alpha_u=2").unwrap(),
            parse_override("nbv.preset=paper").unwrap(),
            parse_override("nbv.alpha_o=3").unwrap(),
        ];
        let s = with_overrides(&base, &set, "--set", "env1").unwrap();
        // alpha_u=2 came before the preset: the preset's value wins.
        let expected = Nbv {
            alpha_o: 3.0,
            ..Nbv::preset(NbvPreset::Paper)
        };
        assert_eq!(s.nbv, expected);
        let e = with_overrides(
            &base,
            &[parse_override("nbv.preset=papr").unwrap()],
            "--set",
            "e",
        )
        .unwrap_err();
        assert!(format!("{e:#}").contains("unknown variant `papr`"), "{e:#}");
    }

    #[test]
    fn overrides_parse_as_toml_values_or_words() {
        let p = |t: &str| parse_override(t).unwrap();
        assert_eq!(
            p("nbv.radius=0.45"),
            ("nbv.radius".into(), toml::Value::Float(0.45))
        );
        assert_eq!(p("nbv.rolls = 4").1, toml::Value::Integer(4));
        assert_eq!(
            p("nbv.gain_measure=eq5").1,
            toml::Value::String("eq5".into())
        );
        assert_eq!(
            p("nbv.gain_measure=\"kl\"").1,
            toml::Value::String("kl".into())
        );
        assert!(parse_override("radius=1").unwrap_err().contains("dotted"));
        assert!(
            parse_override("nbv.radius")
                .unwrap_err()
                .contains("KEY=VALUE")
        );
    }
}
