//! `nbv sweep run | merge | submit`: episodes of `nbv explore` over a grid of scenes, modes, scene
//! parameters and seeds, in parallel, resumable, shardable for batch schedulers, with a
//! CSV, a machine-readable summary, plots and `--require` gates for CI. The engine is
//! [`nbv_sweep::engine`] (the directory's layout: [`nbv_sweep::layout`]); this file parses
//! the arguments, shows progress and prints the summary.

use anyhow::Result;
use clap::{Args, Subcommand};
use indicatif::{ProgressBar, ProgressStyle};
use nbv_sweep::engine::{Finished, Summary, SweepRun};
use nbv_sweep::gate::Gate;
use nbv_sweep::rows::BestSetting;
use nbv_sweep::shard::Shard;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Exit status when the sweep ran but a `--require` gate failed (outputs are written).
pub const EXIT_GATE_FAILED: u8 = 4;

/// Arguments of `nbv sweep`.
#[derive(Debug, Args)]
pub struct SweepArgs {
    #[command(subcommand)]
    command: SweepCommand,
}

#[derive(Debug, Subcommand)]
enum SweepCommand {
    /// Runs (or resumes) the episodes of a grid file.
    Run(RunArgs),
    /// Unions the rows of several sweep directories (e.g. shards) into one.
    Merge(MergeArgs),
    /// Submits the grid to Slurm: a job array of its shards and a merge after them.
    Submit(SubmitArgs),
}

/// `nbv sweep run`.
#[derive(Debug, Args)]
#[command(after_long_help = "\
GRID FILE (TOML)
  scenes = [\"paper-env1\", \"my-scene.toml\"]      # files or built-in names
  generated = { seeds = [1, 2], objects = 1 }     # scenes by `nbv scene generate`
                                                  # (objects = [1, 4]: each seed, each count)
  seeds = [1, 2]                                  # episode seeds (default: the scene's)
  modes = [\"hybrid\", \"mid-only\"]                 # default: hybrid
  [params]                                        # dotted scene keys and values to try
  \"nbv.alpha_u\" = [2.0, 4.0]
  \"nbv.gain_threshold\" = [5.0, 10.0]
  Episodes: scenes (listed, then generated) x modes x parameter combinations (keys in
  alphabetical order, the last fastest) x seeds. Episode k belongs to shard k mod n.

GATES (--require, repeatable)
  METRIC OP VALUE with OP in >=, <=, ==, >, <. Metrics over all finished episodes:
  f_score (smallest per-episode mean F-score of the models: the harmonic mean of
  precision and completeness at 1 cm; misaligned views lower precision), f_score_mean,
  f_score_unregistered_mean (the views as acquired), coverage (smallest per-episode mean
  coverage), coverage_mean, collisions (total), views (total), failed_registrations
  (p-ICP-GPA, total), error_map (largest per-episode mean alignment error, m),
  error_map_mean, error_icp_mean, missed (objects no cluster matched, total), split
  (objects explored as several clusters, total), phantoms (clusters explored that are no
  object and no unknown obstacle, total). A failed
  gate prints the measured value and exits with status 4; the outputs are written all the
  same. E.g. --require \"f_score>=0.8\" --require \"collisions==0\".

EXIT STATUS
  0 all episodes finished and every gate holds; 1 error; 2 usage; 4 a gate failed.")]
pub struct RunArgs {
    /// The grid file.
    grid: PathBuf,
    /// Output directory (created; finished episodes in it are kept and skipped).
    #[arg(short, long)]
    output: PathBuf,
    /// Run only shard I of N (0-based): episodes whose index mod N is I.
    #[arg(long, value_name = "I/N")]
    shard: Option<Shard>,
    /// Episodes run at once.
    #[arg(long, default_value_t = 1)]
    jobs: usize,
    /// A gate on the aggregate (see GATES).
    #[arg(long = "require", value_name = "METRIC OP VALUE")]
    require: Vec<Gate>,
    /// Also write each episode's pictures.
    #[arg(long)]
    pictures: bool,
    /// Also record each episode for the Rerun viewer: `episodes/<id>/episode.rrd` (a build
    /// with `--features rerun`).
    #[arg(long)]
    record: bool,
    /// Also write each episode as a ROS 2 bag: `episodes/<id>/bag/`, a rosbag2 directory
    /// (MCAP) for RViz, Foxglove and `ros2 bag play` (docs/bags.md).
    #[arg(long)]
    bag: bool,
    /// Each episode keeps only its `report.json` (and `oracle.json`): no clouds, grids,
    /// models, meshes or `rgbd/`, which take about 12 MB an episode.
    #[arg(long)]
    report_only: bool,
    /// No progress bar.
    #[arg(long, short)]
    quiet: bool,
}

/// `nbv sweep merge`.
#[derive(Debug, Args)]
pub struct MergeArgs {
    /// Sweep directories of the same grid (e.g. its shards).
    #[arg(required = true)]
    inputs: Vec<PathBuf>,
    /// Output directory.
    #[arg(short, long)]
    output: PathBuf,
    /// A gate on the aggregate (see `nbv sweep run --help`).
    #[arg(long = "require", value_name = "METRIC OP VALUE")]
    require: Vec<Gate>,
}

/// `nbv sweep submit`.
#[derive(Debug, Args)]
#[command(after_long_help = "\
WHAT IT SUBMITS
  OUT/slurm/array.sbatch: a job array of N tasks; task I runs
    nbv sweep run GRID -o OUT/shards/shard_I --shard I/N --jobs J -q
  OUT/slurm/merge.sbatch, submitted with --dependency=afterok:<array> and
  --kill-on-invalid-dep=yes: nbv sweep merge OUT/shards/shard_* -o OUT --require ...
  Job ids go to OUT/slurm/jobs.json, the jobs' output to OUT/slurm/*.out.

FAULTS
  Run the same command again after cancelled, failed or killed tasks: the previous jobs
  still queued are cancelled, each task skips the episodes its shard already finished,
  and the merge runs again.

MORE NODES
  OUT and the grid on a filesystem every node sees, and the nbv binary at the same path
  on each (the scripts name it by its absolute path); --sbatch-arg for the partition,
  time limit and account.

EXIT STATUS
  0 submitted (with --wait: merged, every gate holds); 1 error or a failed job; 4 a gate
  failed (with --wait).")]
pub struct SubmitArgs {
    /// The grid file.
    grid: PathBuf,
    /// Output directory: the merged sweep, its shards and the Slurm scripts.
    #[arg(short, long)]
    output: PathBuf,
    /// Array tasks (shards).
    #[arg(long)]
    shards: usize,
    /// Episodes each task runs at once (its --cpus-per-task).
    #[arg(long, default_value_t = 1)]
    jobs: usize,
    /// A gate the merge checks (see `nbv sweep run --help`).
    #[arg(long = "require", value_name = "METRIC OP VALUE")]
    require: Vec<String>,
    /// An extra #SBATCH option for both jobs, e.g. --sbatch-arg=--time=2:00:00.
    #[arg(long = "sbatch-arg", value_name = "ARG", allow_hyphen_values = true)]
    sbatch_args: Vec<String>,
    /// Wait for the merge and exit with its status.
    #[arg(long)]
    wait: bool,
    /// Write the scripts only; submit nothing.
    #[arg(long)]
    dry_run: bool,
}

/// Runs `nbv sweep`.
pub fn run(args: SweepArgs) -> Result<ExitCode> {
    match args.command {
        SweepCommand::Run(a) => run_grid(a),
        SweepCommand::Merge(a) => {
            let finished = nbv_sweep::engine::merge(&a.inputs, &a.output, &a.require)?;
            Ok(report(&finished, &a.output))
        }
        SweepCommand::Submit(a) => submit(a),
    }
}

fn submit(args: SubmitArgs) -> Result<ExitCode> {
    use anyhow::{Context, bail};
    use nbv_sweep::slurm::{Submission, wait_for};
    if args.shards == 0 || args.jobs == 0 {
        bail!("--shards and --jobs must be at least 1");
    }
    for g in &args.require {
        if let Err(e) = g.parse::<Gate>() {
            bail!("--require {g}: {e}");
        }
    }
    // The grid must parse before anything is submitted.
    nbv_sweep::grid::SweepGrid::load(&args.grid)?;
    std::fs::create_dir_all(&args.output)
        .with_context(|| format!("creating {}", args.output.display()))?;
    let absolute = |p: &Path| {
        std::path::absolute(p).with_context(|| format!("the absolute path of {}", p.display()))
    };
    let submission = Submission {
        nbv: std::env::current_exe().context("the path of this nbv binary")?,
        grid: absolute(&args.grid)?,
        out: absolute(&args.output)?,
        shards: args.shards,
        jobs: args.jobs,
        require: args.require.clone(),
        sbatch_args: args.sbatch_args.clone(),
    };
    if args.dry_run {
        let (array, merge) = submission.write_scripts()?;
        println!(
            "wrote {} and {}; to submit them:\n  array=$(sbatch --parsable {})\n  sbatch --dependency=afterok:$array --kill-on-invalid-dep=yes {}",
            array.display(),
            merge.display(),
            array.display(),
            merge.display()
        );
        return Ok(ExitCode::SUCCESS);
    }
    let jobs = submission.submit()?;
    println!(
        "submitted: array job {} ({} task(s)), merge job {} after it; watch with `squeue -j {},{}`",
        jobs.array, args.shards, jobs.merge, jobs.array, jobs.merge
    );
    if !args.wait {
        return Ok(ExitCode::SUCCESS);
    }
    let end = wait_for(&jobs.merge, std::time::Duration::from_secs(2))?;
    let log = submission
        .slurm_dir()
        .join(format!("merge-{}.out", jobs.merge));
    if let Ok(text) = std::fs::read_to_string(&log) {
        print!("{text}");
    }
    match (end.state.as_str(), end.exit_code) {
        ("COMPLETED", _) => Ok(ExitCode::SUCCESS),
        (_, 4) => Ok(ExitCode::from(EXIT_GATE_FAILED)),
        (state, code) => bail!(
            "the merge job {} ended {state} (exit code {code}): a task of array job {} failed or was cancelled; its output is in {}; run the same command again to complete the sweep",
            jobs.merge,
            jobs.array,
            submission.slurm_dir().display()
        ),
    }
}

fn run_grid(args: RunArgs) -> Result<ExitCode> {
    let sweep = SweepRun {
        grid_file: args.grid.clone(),
        output: args.output.clone(),
        shard: args.shard,
        jobs: args.jobs,
        pictures: args.pictures,
        record: args.record,
        bag: args.bag,
        outputs: if args.report_only {
            nbv_sweep::episode::Outputs::ReportOnly
        } else {
            nbv_sweep::episode::Outputs::All
        },
    };
    let prepared = sweep.prepare()?;
    let todo = prepared.todo.len();
    eprintln!(
        "{}: {} episode(s) in the grid, {} in this shard, {} already done, {} to run",
        args.grid.display(),
        prepared.grid.len(),
        prepared.in_shard,
        prepared.in_shard - todo,
        todo
    );
    let bar = if args.quiet {
        ProgressBar::hidden()
    } else {
        ProgressBar::new(todo as u64)
    };
    bar.set_style(
        ProgressStyle::with_template("[{elapsed_precise}] {bar:30} {pos}/{len} episodes {msg}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let ran = sweep.run_episodes(&prepared, &|| bar.inc(1));
    bar.finish_and_clear();
    ran?;
    let finished = sweep.finish(&prepared, &args.require)?;
    Ok(report(&finished, &args.output))
}

/// Prints the summary; the exit status of the gates.
fn report(finished: &Finished, out: &Path) -> ExitCode {
    print!("{}", summary_text(&finished.summary, out, &finished.plots));
    if finished.passed() {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(EXIT_GATE_FAILED)
    }
}

fn summary_text(s: &Summary, out: &Path, plots: &[String]) -> String {
    let a = &s.aggregate;
    let mut t = format!(
        "{} of {} episode(s): F-score min {:.1} mean {:.1} (as acquired {:.1}), coverage min {:.1}% mean {:.1}%, {} view(s), {} collision(s), \
         registration error (the model's) mean {:.1} mm (max {:.1}), ICP {}, {} failed registration(s); \
         {:.0} episodes/hour (one job)\n",
        s.episodes_finished,
        s.episodes_expected,
        100.0 * a.f_score,
        100.0 * a.f_score_mean,
        100.0 * a.f_score_unregistered_mean,
        100.0 * a.coverage,
        100.0 * a.coverage_mean,
        a.views,
        a.collisions,
        1e3 * a.error_map_mean,
        1e3 * a.error_map,
        // Sweeps without the baselines have no ICP figure.
        if s.registration.iter().any(|l| l.icp.is_some()) {
            format!("{:.1} mm", 1e3 * a.error_icp_mean)
        } else {
            "-".to_string()
        },
        a.failed_registrations,
        a.episodes_per_hour
    );
    t += &format!(
        "exploration: {:.1} view(s) per object, {} added under 0.5 point of coverage, at most {} after an object's coverage last rose by 0.5 point",
        a.views_per_object, a.wasted_views, a.views_after_rise
    );
    if a.coverage_of_ceiling_mean > 0.0 {
        t += &format!(
            "; against the oracle's ceiling: coverage / ceiling min {:.1}% mean {:.1}%, {} object(s) below 95% of it, at most {:.1}x the oracle's views to 95%",
            100.0 * a.coverage_of_ceiling,
            100.0 * a.coverage_of_ceiling_mean,
            a.below_95,
            a.views_to_95_ratio
        );
    }
    t += "\n";
    let setting = |b: &Option<BestSetting>| {
        b.as_ref().map_or("-".to_string(), |b| {
            let kv: Vec<String> = b.setting.iter().map(|(k, v)| format!("{k}={v}")).collect();
            format!(
                "{} ({:.4}, {} episode(s))",
                kv.join(" "),
                b.value,
                b.episodes
            )
        })
    };
    t += &format!(
        "best by F-score: {}\nbest by coverage gain per view: {}\n\
         best by registration error (the model's): {}\n",
        setting(&s.best_by_f_score),
        setting(&s.best_by_coverage_per_view),
        setting(&s.best_by_registration_error)
    );
    if !s.registration.is_empty() {
        t += "registration (alignment error, mm: median / 95th percentile; the model's is the \
              MAP registration; failures; worse than as acquired by > 0.5 mm; unconverged; \
              median F-score as acquired / of the model):\n";
        t += "  level object        n   acquired      map           p-ICP-GPA     ICP          \
              fail map/pGPA/ICP  worse  unconv  F acq / map\n";
        for l in &s.registration {
            let q = |v: (f64, f64)| format!("{:>5.1} / {:>5.1}", 1e3 * v.0, 1e3 * v.1);
            // The baselines are absent when the sweep ran without them.
            let q_or_dash = |v: Option<(f64, f64)>| v.map_or(format!("{:>13}", "-"), q);
            t += &format!(
                "  x{:<4} {:<12} {:>2}   {}  {}  {}  {}  {}/{}/{}  {:>5}  {:>6}  {:>5.1} / {:>5.1}\n",
                l.level,
                l.object,
                l.experiments,
                q(l.acquired_quantiles),
                q(l.map_quantiles),
                q_or_dash(l.pgpa_quantiles),
                q_or_dash(l.icp_quantiles),
                l.map_failures,
                l.pgpa_failures,
                l.icp_failures,
                l.worse_than_acquired,
                l.unconverged,
                100.0 * l.f_score_medians.0,
                100.0 * l.f_score_medians.1
            );
        }
    }
    if !s.robustness.is_empty() {
        t += "per error level (objects of the scenes; missed, split into several clusters, \
              phantom clusters explored, clusters dropped as not objects; collisions; \
              F-score per object, median / 5th percentile, as acquired and of the model):\n";
        for l in &s.robustness {
            t += &format!(
                "  x{:<4} {:>3} episode(s) {:>4} objects  missed {:>2}  split {:>2}  phantoms {:>2}  dropped {:>2}  collisions {:>2}  F acquired {:>5.1} / {:>5.1}  model {:>5.1} / {:>5.1}\n",
                l.level,
                l.episodes,
                l.objects,
                l.missed,
                l.split,
                l.phantoms,
                l.dropped,
                l.collisions,
                100.0 * l.f_score_acquired.0,
                100.0 * l.f_score_acquired.1,
                100.0 * l.f_score_model.0,
                100.0 * l.f_score_model.1
            );
        }
    }
    for g in &s.gates {
        t += &format!(
            "gate {}: {} (measured {})\n",
            g.gate,
            if g.pass { "pass" } else { "FAILED" },
            g.measured
        );
    }
    if !s.missing.is_empty() {
        t += &format!("missing episodes: {:?}\n", s.missing);
    }
    t += &format!(
        "wrote {}/results.csv, summary.json{}\n",
        out.display(),
        plots
            .iter()
            .map(|p| format!(", plots/{p}"))
            .collect::<String>()
    );
    t
}
