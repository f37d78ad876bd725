//! `nbv views`: phase 1 on a scene in the twin, then each object's sorted next-best-view
//! candidates (Algorithm 2) with what the robot can do about them: whether a collision-free
//! IK solution exists, whether the planner reaches it from where phase 1 left the arm, and
//! whether the planned path, executed in the twin, touches anything in truth. The listing
//! is [`nbv_sweep::views`]; this file parses the arguments and prints.

use anyhow::{Result, bail};
use clap::Args;
use nbv_sweep::views::{ObjectViews, ViewsOptions, list_views};

/// Arguments of `nbv views`.
#[derive(Debug, Args)]
#[command(after_help = "\
For every candidate, best first: the sensor pose (x y z in m, roll pitch yaw in degrees),
the predicted unknown and occupied voxels |O_v|, the score of eq. (4), `reachable` (an IK
solution free of self-collision, the known obstacles and the reduced map, at the first of
the scene's `[nbv] rolls` about the optical axis that has one; samples without are counted,
not listed), `planned` (the
RRT-Connect planner found a path from the arm's configuration after phase 1) and, with
--check (default), `collision`: the path executed in the twin touched something in truth
(the arm is put back after each check).")]
pub struct ViewsArgs {
    /// Scene file, or the name of a built-in scene (paper-env1, paper-env2).
    #[arg(long)]
    pub scene: String,
    /// Only this object (its name in the scene); by default every cluster.
    #[arg(long)]
    pub object: Option<String>,
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Do not plan (reachability and scores only).
    #[arg(long)]
    pub no_plan: bool,
    /// Do not execute the planned paths in the twin.
    #[arg(long)]
    pub no_check: bool,
    /// Also cast each reachable candidate as `nbv oracle` does (no noise) and print the
    /// object's true coverage with it beside the score, and how the score ranks the truth.
    #[arg(long)]
    pub oracle: bool,
    /// Overrides the scene's seed.
    #[arg(long)]
    pub seed: Option<u64>,
    /// Sets a scene parameter for this run: a dotted key of the scene file and a TOML
    /// value, e.g. `--set nbv.radius=0.45 --set nbv.gain_threshold=2.5` (repeatable; the
    /// keys a sweep's `[params]` takes).
    #[arg(long = "set", value_name = "KEY=VALUE", value_parser = nbv_scenes::overrides::parse_override)]
    pub set: Vec<(String, toml::Value)>,
}

/// Runs `nbv views`.
pub fn run(args: ViewsArgs) -> Result<()> {
    let scene = nbv_scenes::overrides::load_for_run(&args.scene, &args.set, args.seed)?;
    if let Some(name) = &args.object
        && !scene.objects.iter().any(|o| &o.name == name)
    {
        let names: Vec<_> = scene.objects.iter().map(|o| o.name.as_str()).collect();
        bail!(
            "{}: no object named `{name}` (objects: {})",
            args.scene,
            names.join(", ")
        );
    }
    let options = ViewsOptions {
        object: args.object.clone(),
        plan: !args.no_plan,
        check: !args.no_check,
        oracle: args.oracle,
    };
    let objects = list_views(&scene, &options)?;
    if args.json {
        println!("{}", serde_json::to_string_pretty(&objects)?);
    } else {
        for o in &objects {
            print!("{}", table(o));
        }
    }
    Ok(())
}

fn table(o: &ObjectViews) -> String {
    let mut s = format!(
        "{}: sphere centre ({:.3}, {:.3}, {:.3}); {} samples, {} unreachable, {} candidates, {} rays each\n",
        o.name,
        o.centre[0],
        o.centre[1],
        o.centre[2],
        o.samples,
        o.unreachable,
        o.candidates.len(),
        o.rays_per_view
    );
    if let Some(t) = &o.truth {
        s += &format!(
            "truth: laser {:.1} %, the first candidate {:.1} %, the best {:.1} % (ranked {}), Spearman {:.2}\n",
            100.0 * t.laser,
            100.0 * t.chosen,
            100.0 * t.best,
            t.best_rank,
            t.spearman
        );
    }
    s += "   #   x      y      z      roll   pitch   yaw    unknown occupied  score  reachable planned collision  truth\n";
    let yn = |b: Option<bool>| match b {
        Some(true) => "yes",
        Some(false) => "no",
        None => "-",
    };
    for (k, c) in o.candidates.iter().enumerate() {
        s += &format!(
            "{:>4} {:>6.3} {:>6.3} {:>6.3} {:>6.1} {:>6.1} {:>6.1} {:>7} {:>8} {:>7.0}  {:>9} {:>7} {:>9}  {:>5}\n",
            k + 1,
            c.pose[0],
            c.pose[1],
            c.pose[2],
            c.pose[3],
            c.pose[4],
            c.pose[5],
            c.unknown,
            c.occupied,
            c.score,
            yn(Some(c.reachable)),
            yn(c.planned),
            yn(c.collision),
            c.truth
                .map_or("-".to_owned(), |t| format!("{:.1}", 100.0 * t))
        );
    }
    s
}
