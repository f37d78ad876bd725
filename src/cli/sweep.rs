//! `nbv sweep run | merge`: episodes of `nbv explore` over a grid of scenes, modes, scene
//! parameters and seeds, in parallel, resumable, shardable for batch schedulers, with a
//! CSV, a machine-readable summary, plots and `--require` gates for CI.
//!
//! Layout of a sweep directory:
//! ```text
//! DIR/sweep.json               the grid (file, hash, episode count) and the shard
//! DIR/episodes/<id>.row.json   one finished episode (written atomically, last)
//! DIR/episodes/<id>/           its `nbv explore` outputs (report.json, models, map)
//! DIR/results.csv              one row per finished episode, by index
//! DIR/summary.json             aggregates, best settings (by F-score first), registration
//!                              table, gates
//! DIR/plots/*.svg              heatmap of coverage, coverage against views
//! ```
//! A run skips the episodes whose row file exists, so an interrupted sweep resumes without
//! losing or duplicating rows; `merge` unions the rows of shard directories.
//!
//! Every file is written atomically (`nbv_core::atomic_file`: a temporary `.NAME.<random>.tmp`
//! beside it, renamed when complete), so a killed run leaves no half-written file, but it
//! can leave such temporary files, and the outputs of the episodes it was running. A run
//! therefore first removes the temporary files of the sweep directory, `episodes/` and
//! `plots/`, and starts each episode it runs in an empty directory (an episode without a
//! row never finished; what its directory holds is from an interrupted run).

use super::sweep_gate::{Gate, GateResult};
use super::sweep_grid::{Episode, SweepGrid};
use super::sweep_results::{
    Aggregate, BestSetting, EpisodeRow, RegistrationLine, RobustnessLine, best_setting, csv_text,
    registration_table, robustness_table,
};
use anyhow::{Context, Result, bail};
use clap::{Args, Subcommand};
use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

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
  (p-ICP-GPA, total), error_gpa (largest per-episode mean alignment error, m),
  error_gpa_mean, error_icp_mean, missed (objects no cluster matched, total), split
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

/// `I/N`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Shard {
    /// This shard, 0-based.
    pub index: usize,
    /// Shards in all.
    pub count: usize,
}

impl std::str::FromStr for Shard {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        let bad = || format!("`{s}`: expected I/N with 0 <= I < N (e.g. 0/3)");
        let (i, n) = s.split_once('/').ok_or_else(bad)?;
        let (index, count) = (
            i.trim().parse().map_err(|_| bad())?,
            n.trim().parse().map_err(|_| bad())?,
        );
        if count == 0 || index >= count {
            return Err(bad());
        }
        Ok(Self { index, count })
    }
}

/// `DIR/sweep.json`: what a sweep directory holds.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
struct SweepInfo {
    /// The grid file as given.
    grid: PathBuf,
    /// Its text (so a merge can check the shards come from the same grid).
    grid_text: String,
    /// Episodes in the whole grid.
    episodes: usize,
    /// The shard this directory ran (none: all).
    shard: Option<Shard>,
}

/// `DIR/summary.json`.
#[derive(Debug, Clone, Serialize)]
pub struct Summary {
    /// Episodes in the grid.
    pub episodes_expected: usize,
    /// Episodes with a row.
    pub episodes_finished: usize,
    /// Indices of the grid's episodes without a row.
    pub missing: Vec<usize>,
    /// Aggregates (the gateable metrics).
    pub aggregate: Aggregate,
    /// Mode and parameters with the largest mean F-score (the primary ranking).
    pub best_by_f_score: Option<BestSetting>,
    /// Mode and parameters with the largest mean coverage gain per view.
    pub best_by_coverage_per_view: Option<BestSetting>,
    /// Mode and parameters with the smallest mean alignment error of the model's
    /// registration.
    pub best_by_registration_error: Option<BestSetting>,
    /// Per object over every episode: p-ICP-GPA and sequential ICP (Table III).
    pub registration: Vec<RegistrationLine>,
    /// Per error level: missed, split and phantom objects, collisions, F-scores.
    pub robustness: Vec<RobustnessLine>,
    /// The gates and their outcomes.
    pub gates: Vec<GateResult>,
}

/// Runs `nbv sweep`.
pub fn run(args: SweepArgs) -> Result<ExitCode> {
    match args.command {
        SweepCommand::Run(a) => run_grid(a),
        SweepCommand::Merge(a) => merge(a),
    }
}

fn run_grid(args: RunArgs) -> Result<ExitCode> {
    let grid = SweepGrid::load(&args.grid)?;
    let grid_text = std::fs::read_to_string(&args.grid)
        .with_context(|| format!("reading {}", args.grid.display()))?;
    if args.jobs == 0 {
        bail!("--jobs must be at least 1");
    }
    let out = &args.output;
    if out.exists() && !out.is_dir() {
        bail!("{}: exists and is not a directory", out.display());
    }
    let info = SweepInfo {
        grid: args.grid.clone(),
        grid_text,
        episodes: grid.len(),
        shard: args.shard,
    };
    let info_path = out.join("sweep.json");
    if info_path.exists() {
        let old: SweepInfo = serde_json::from_str(&std::fs::read_to_string(&info_path)?)
            .with_context(|| format!("{}: not a sweep directory", out.display()))?;
        if old.grid_text != info.grid_text || old.shard != info.shard {
            bail!(
                "{}: holds a sweep of another grid or shard ({}); use a new directory",
                out.display(),
                old.grid.display()
            );
        }
    }
    std::fs::create_dir_all(out.join("episodes"))
        .with_context(|| format!("creating {}", out.display()))?;
    remove_stale_temporaries(out)?;
    write_json(&info_path, &info)?;

    let mine: Vec<Episode> = grid
        .episodes()
        .into_iter()
        .filter(|e| args.shard.is_none_or(|s| e.index % s.count == s.index))
        .collect();
    let todo: Vec<&Episode> = mine.iter().filter(|e| !row_path(out, e).exists()).collect();
    eprintln!(
        "{}: {} episode(s) in the grid, {} in this shard, {} already done, {} to run",
        args.grid.display(),
        grid.len(),
        mine.len(),
        mine.len() - todo.len(),
        todo.len()
    );
    let bar = if args.quiet {
        ProgressBar::hidden()
    } else {
        ProgressBar::new(todo.len() as u64)
    };
    bar.set_style(
        ProgressStyle::with_template("[{elapsed_precise}] {bar:30} {pos}/{len} episodes {msg}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(args.jobs)
        .build()
        .context("starting the episode pool")?;
    let results: Vec<Result<()>> = pool.install(|| {
        todo.par_iter()
            .map(|e| {
                let r = run_one(&grid, e, out, args.pictures);
                bar.inc(1);
                r.with_context(|| format!("episode {} ({})", e.id, e.scene.label()))
            })
            .collect()
    });
    bar.finish_and_clear();
    // The first error (by episode order) fails the run; finished episodes are kept.
    for r in results {
        r?;
    }
    let rows = load_rows(std::slice::from_ref(out))?;
    finish(out, &grid, &rows, &args.require, args.shard)
}

/// One episode: its scene, `nbv explore`'s episode, then the row file (written last, so
/// a row exists only for a finished episode).
fn run_one(grid: &SweepGrid, e: &Episode, out: &Path, pictures: bool) -> Result<()> {
    let scene = e.scene(&grid.file)?;
    let dir = out.join("episodes").join(&e.id);
    // No row: whatever the directory holds is from an interrupted run of this episode
    // (partial outputs, temporary files of writes it never finished).
    if dir.exists() {
        std::fs::remove_dir_all(&dir)
            .with_context(|| format!("removing the unfinished {}", dir.display()))?;
    }
    let t = Instant::now();
    let report = super::explore::run_episode(&scene, e.mode, &dir, pictures, true)?;
    let row = EpisodeRow::new(e, &report, t.elapsed().as_secs_f64());
    write_json(&row_path(out, e), &row)
}

/// Whether `name` is the temporary file of an atomic write (`.NAME.<random>.tmp`, see
/// `nbv_core::atomic_file`).
fn is_temporary(name: &str) -> bool {
    name.len() > ".x..tmp".len() && name.starts_with('.') && name.ends_with(".tmp")
}

/// Removes the temporary files an interrupted run left in the sweep directory `out`, its
/// `episodes/` and its `plots/` (the episodes' own directories are emptied when they run
/// again); how many.
fn remove_stale_temporaries(out: &Path) -> Result<usize> {
    let mut removed = 0;
    for dir in [out.to_path_buf(), out.join("episodes"), out.join("plots")] {
        let Ok(entries) = std::fs::read_dir(&dir) else {
            continue;
        };
        for entry in entries {
            let entry = entry.with_context(|| format!("reading {}", dir.display()))?;
            let stale = entry.file_type().is_ok_and(|t| t.is_file())
                && is_temporary(&entry.file_name().to_string_lossy());
            if stale {
                std::fs::remove_file(entry.path())
                    .with_context(|| format!("removing {}", entry.path().display()))?;
                removed += 1;
            }
        }
    }
    if removed > 0 {
        tracing::info!(
            "{}: removed {removed} temporary file(s) of an interrupted run",
            out.display()
        );
    }
    Ok(removed)
}

fn row_path(out: &Path, e: &Episode) -> PathBuf {
    out.join("episodes").join(format!("{}.row.json", e.id))
}

fn write_json<T: Serialize>(path: &Path, value: &T) -> Result<()> {
    let text = serde_json::to_string_pretty(value)?;
    nbv_scenes::paths::write_atomic(path, text.as_bytes())
        .with_context(|| format!("writing {}", path.display()))
}

/// Every row file of the directories, by index; the same id twice must be the same row.
fn load_rows(dirs: &[PathBuf]) -> Result<Vec<EpisodeRow>> {
    let mut rows: Vec<EpisodeRow> = Vec::new();
    for dir in dirs {
        let episodes = dir.join("episodes");
        let entries = std::fs::read_dir(&episodes)
            .with_context(|| format!("reading {}", episodes.display()))?;
        let mut paths: Vec<PathBuf> = entries
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.to_string_lossy().ends_with(".row.json"))
            .collect();
        paths.sort();
        for p in paths {
            let row = EpisodeRow::load(&p)?;
            if let Some(old) = rows.iter().find(|r| r.id == row.id) {
                let same = EpisodeRow {
                    time_s: old.time_s,
                    ..row.clone()
                } == *old;
                if !same {
                    bail!(
                        "{}: episode {} differs from the same episode in another input",
                        p.display(),
                        row.id
                    );
                }
                continue;
            }
            rows.push(row);
        }
    }
    rows.sort_by_key(|r| r.index);
    Ok(rows)
}

/// Writes the CSV, the summary and the plots; checks the gates.
fn finish(
    out: &Path,
    grid: &SweepGrid,
    rows: &[EpisodeRow],
    gates: &[Gate],
    shard: Option<Shard>,
) -> Result<ExitCode> {
    nbv_scenes::paths::write_atomic(&out.join("results.csv"), csv_text(rows)?.as_bytes())
        .with_context(|| format!("writing {}", out.join("results.csv").display()))?;
    let aggregate = Aggregate::of(rows);
    let expected: Vec<usize> = (0..grid.len())
        .filter(|k| shard.is_none_or(|s| k % s.count == s.index))
        .collect();
    let missing: Vec<usize> = expected
        .iter()
        .copied()
        .filter(|k| !rows.iter().any(|r| r.index == *k))
        .collect();
    let gate_results: Vec<GateResult> = gates.iter().map(|g| g.check(&aggregate)).collect();
    let summary = Summary {
        episodes_expected: expected.len(),
        episodes_finished: rows.len(),
        missing,
        aggregate,
        best_by_f_score: best_setting(rows, |r| r.f_score, true),
        best_by_coverage_per_view: best_setting(rows, |r| r.coverage_gain_per_view, true),
        best_by_registration_error: best_setting(rows, |r| r.error_gpa, false),
        registration: registration_table(rows),
        robustness: robustness_table(rows),
        gates: gate_results.clone(),
    };
    write_json(&out.join("summary.json"), &summary)?;
    let plots = super::sweep_plots::write(&out.join("plots"), rows)?;
    print!("{}", summary_text(&summary, out, &plots));
    if gate_results.iter().all(|g| g.pass) {
        Ok(ExitCode::SUCCESS)
    } else {
        Ok(ExitCode::from(EXIT_GATE_FAILED))
    }
}

fn summary_text(s: &Summary, out: &Path, plots: &[String]) -> String {
    let a = &s.aggregate;
    let mut t = format!(
        "{} of {} episode(s): F-score min {:.1} mean {:.1} (as acquired {:.1}), coverage min {:.1}% mean {:.1}%, {} view(s), {} collision(s), \
         registration error (the model's) mean {:.1} mm (max {:.1}), ICP {:.1} mm, {} failed registration(s); \
         {:.0} episodes/hour\n",
        s.episodes_finished,
        s.episodes_expected,
        100.0 * a.f_score,
        100.0 * a.f_score_mean,
        100.0 * a.f_score_unregistered_mean,
        100.0 * a.coverage,
        100.0 * a.coverage_mean,
        a.views,
        a.collisions,
        1e3 * a.error_gpa_mean,
        1e3 * a.error_gpa,
        1e3 * a.error_icp_mean,
        a.failed_registrations,
        a.episodes_per_hour
    );
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
            t += &format!(
                "  x{:<4} {:<12} {:>2}   {}  {}  {}  {}  {}/{}/{}  {:>5}  {:>6}  {:>5.1} / {:>5.1}\n",
                l.level,
                l.object,
                l.experiments,
                q(l.acquired_quantiles),
                q(l.map_quantiles),
                q(l.pgpa_quantiles),
                q(l.icp_quantiles),
                l.gpa_failures,
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

fn merge(args: MergeArgs) -> Result<ExitCode> {
    let mut info: Option<SweepInfo> = None;
    for dir in &args.inputs {
        let path = dir.join("sweep.json");
        let text = std::fs::read_to_string(&path)
            .with_context(|| format!("{}: not a sweep directory (no sweep.json)", dir.display()))?;
        let this: SweepInfo = serde_json::from_str(&text)
            .with_context(|| format!("{}: not a sweep description", path.display()))?;
        if let Some(first) = &info
            && first.grid_text != this.grid_text
        {
            bail!(
                "{}: a sweep of another grid than {}",
                dir.display(),
                args.inputs[0].display()
            );
        }
        info.get_or_insert(this);
    }
    let Some(info) = info else {
        bail!("no input directory");
    };
    let grid = SweepGrid::parse(&info.grid_text, &info.grid)?;
    let rows = load_rows(&args.inputs)?;
    let out = &args.output;
    std::fs::create_dir_all(out.join("episodes"))
        .with_context(|| format!("creating {}", out.display()))?;
    remove_stale_temporaries(out)?;
    write_json(
        &out.join("sweep.json"),
        &SweepInfo {
            shard: None,
            ..info.clone()
        },
    )?;
    for r in &rows {
        write_json(&out.join("episodes").join(format!("{}.row.json", r.id)), r)?;
    }
    finish(out, &grid, &rows, &args.require, None)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_parse() {
        assert_eq!(
            "1/3".parse::<Shard>().unwrap(),
            Shard { index: 1, count: 3 }
        );
        assert!("3/3".parse::<Shard>().is_err());
        assert!("0/0".parse::<Shard>().is_err());
        assert!("x".parse::<Shard>().unwrap_err().contains("I/N"));
    }

    #[test]
    fn stale_temporaries_are_removed_and_nothing_else() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path();
        std::fs::create_dir_all(out.join("episodes/0000-x")).unwrap();
        let stale = [
            ".results.csv.a1B2c3.tmp",
            "episodes/.0000-x.row.json.Zz9yY8.tmp",
        ];
        let kept = [
            "results.csv",
            "episodes/0000-x.row.json",
            ".hidden",
            "notes.tmp",
            // Inside an episode directory: that directory is emptied when the episode
            // runs again, and left alone when it finished.
            "episodes/0000-x/.report.json.q1w2e3.tmp",
        ];
        for f in stale.iter().chain(&kept) {
            std::fs::write(out.join(f), "x").unwrap();
        }
        // A real temporary file of the atomic writer, kept by a writer that never finished.
        let real = tempfile::Builder::new()
            .prefix(".summary.json.")
            .suffix(".tmp")
            .tempfile_in(out)
            .unwrap()
            .keep()
            .unwrap()
            .1;
        assert_eq!(remove_stale_temporaries(out).unwrap(), 3);
        assert!(!real.exists());
        for f in stale {
            assert!(!out.join(f).exists(), "{f}");
        }
        for f in kept {
            assert!(out.join(f).exists(), "{f}");
        }
        assert_eq!(remove_stale_temporaries(&out.join("missing")).unwrap(), 0);
    }
}
