//! `nbv oracle`: the ground-truth ceiling of each object's exploration on a scene — the
//! coverage every reachable camera pose achieves together, and the greedy set cover's
//! coverage after 1, 2, … views. The computation is [`nbv_sweep::oracle`]; this file
//! parses the arguments, writes `oracle.json` and prints.

use anyhow::{Context, Result};
use clap::Args;
use nbv_sweep::oracle::{OracleObject, OracleOptions, oracle};
use std::path::PathBuf;

/// Arguments of `nbv oracle`.
#[derive(Debug, Args)]
#[command(after_help = "\
Per object: the ceiling (share of the true surface above the table, within 1 cm, that the
laser sweep and every reachable camera pose see together — the report's coverage), the
laser's share, the ceiling of Algorithm 2's own candidates, the greedy views to 95 % of the
ceiling, the poses evaluated and reachable, and where the unseen rest lies (against the
table, hidden by the object itself, facing an obstacle, out of the arm's reach).
Writes DIR/oracle.json.")]
pub struct OracleArgs {
    /// Scene file, or the name of a built-in scene (paper-env1, paper-env2).
    #[arg(long)]
    pub scene: String,
    /// Output directory (created).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Only this object (its name in the scene).
    #[arg(long)]
    pub object: Option<String>,
    /// Overrides the scene's seed.
    #[arg(long)]
    pub seed: Option<u64>,
    /// Sets a scene parameter for this run (dotted key = TOML value; repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE", value_parser = nbv_scenes::overrides::parse_override)]
    pub set: Vec<(String, toml::Value)>,
    /// Print nothing but errors.
    #[arg(short, long)]
    pub quiet: bool,
}

/// Runs `nbv oracle`.
pub fn run(args: OracleArgs) -> Result<()> {
    let scene = nbv_scenes::overrides::load_for_run(&args.scene, &args.set, args.seed)?;
    let options = OracleOptions {
        object: args.object.clone(),
        ..OracleOptions::default()
    };
    let report = oracle(&scene, &options)?;
    std::fs::create_dir_all(&args.output)
        .with_context(|| format!("creating {}", args.output.display()))?;
    let path = args.output.join("oracle.json");
    let json = serde_json::to_vec_pretty(&report)?;
    nbv_core::atomic_file::write_atomic(&path, &json)
        .with_context(|| format!("writing {}", path.display()))?;
    if !args.quiet {
        println!(
            "{} (seed {}): the ceiling of each object, {:.0} s",
            report.scene, report.seed, report.seconds
        );
        for o in &report.objects {
            println!("{}", line(o));
        }
        println!("wrote {}", path.display());
    }
    Ok(())
}

fn line(o: &OracleObject) -> String {
    let pct = |v: f64| 100.0 * v;
    let curve: Vec<String> = o
        .greedy
        .iter()
        .take(8)
        .map(|c| format!("{:.1}", pct(*c)))
        .collect();
    format!(
        "  {:<12} ceiling {:>5.1} %  laser {:>5.1}  Algorithm 2's {:>5.1}  greedy {}{}  ({} views to 95 % of it)\n  {:<12} poses {} evaluated, {} reachable; unseen: table {:.1}, itself {:.1}, obstacle {:.1}, out of reach {:.1} %",
        o.name,
        pct(o.ceiling),
        pct(o.laser),
        pct(o.algorithm2_ceiling),
        curve.join(" "),
        if o.greedy.len() > 8 { " …" } else { "" },
        o.views_to_95,
        "",
        o.poses.evaluated,
        o.poses.reachable,
        pct(o.unseen.table),
        pct(o.unseen.self_occluded),
        pct(o.unseen.obstacle),
        pct(o.unseen.out_of_reach),
    )
}
