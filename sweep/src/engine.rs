//! The sweep engine: episodes of a grid run in parallel into a sweep directory
//! ([`crate::layout`]), resumable (an episode with a row file is skipped) and shardable;
//! then the CSV, the summary, the plots and the gates ([`finish`]); and [`merge`] of
//! several directories of the same grid (e.g. its shards).
//!
//! Every file is written atomically (`nbv_core::atomic_file`: a temporary `.NAME.<random>.tmp`
//! beside it, renamed when complete), so a killed run leaves no half-written file, but it
//! can leave such temporary files, and the outputs of the episodes it was running. A run
//! therefore first removes the temporary files of the sweep directory, `episodes/` and
//! `plots/`, and starts each episode it runs in an empty directory (an episode without a
//! row never finished; what its directory holds is from an interrupted run).

use crate::error::{Context, Result, bail};
use crate::gate::{Gate, GateResult};
use crate::grid::{Episode, SweepGrid};
use crate::layout::{SweepInfo, load_rows, remove_stale_temporaries, row_path, write_json};
use crate::rows::{
    Aggregate, BestSetting, EpisodeRow, RegistrationLine, RobustnessLine, best_setting, csv_text,
    registration_table, robustness_table,
};
use crate::shard::Shard;
use rayon::prelude::*;
use serde::Serialize;
use std::path::{Path, PathBuf};
use std::time::Instant;

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
    /// Per view objective (when `nbv.objective` is swept) and scene group: coverage after
    /// each view, views to 80 % / 90 %, coverage, precision, distance, scoring time.
    pub objectives: Vec<crate::objectives::ObjectiveLine>,
    /// The gates and their outcomes.
    pub gates: Vec<GateResult>,
}

/// What a finished sweep (or merge) wrote.
#[derive(Debug, Clone)]
pub struct Finished {
    /// The summary (`summary.json`).
    pub summary: Summary,
    /// The plot files written under `plots/`.
    pub plots: Vec<String>,
}

impl Finished {
    /// Whether every gate holds.
    pub fn passed(&self) -> bool {
        self.summary.gates.iter().all(|g| g.pass)
    }
}

/// A sweep to run: the grid file, the directory, the shard, the parallelism.
#[derive(Debug, Clone)]
pub struct SweepRun {
    /// The grid file.
    pub grid_file: PathBuf,
    /// The sweep directory (created; finished episodes in it are kept and skipped).
    pub output: PathBuf,
    /// Only this shard's episodes.
    pub shard: Option<Shard>,
    /// Episodes run at once (at least 1).
    pub jobs: usize,
    /// Also write each episode's pictures.
    pub pictures: bool,
    /// Also record each episode for the Rerun viewer (`episode.rrd`, feature `rerun`).
    pub record: bool,
    /// Also write each episode as a ROS 2 bag (`bag/`).
    pub bag: bool,
    /// Which of each episode's files it keeps besides its report.
    pub outputs: crate::episode::Outputs,
}

/// A sweep directory ready to run ([`SweepRun::prepare`]).
#[derive(Debug, Clone)]
pub struct Prepared {
    /// The grid.
    pub grid: SweepGrid,
    /// Episodes of this shard.
    pub in_shard: usize,
    /// Those without a row, to run.
    pub todo: Vec<Episode>,
}

impl SweepRun {
    /// Loads the grid, checks the directory is new or holds this grid and shard, writes
    /// `sweep.json`, removes the temporary files of an interrupted run, and lists the
    /// episodes to run.
    pub fn prepare(&self) -> Result<Prepared> {
        let grid = SweepGrid::load(&self.grid_file)?;
        let grid_text = std::fs::read_to_string(&self.grid_file)
            .with_context(|| format!("reading {}", self.grid_file.display()))?;
        if self.jobs == 0 {
            bail!("--jobs must be at least 1");
        }
        if self.record && !cfg!(feature = "rerun") {
            bail!("{}", crate::episode::NO_RECORDING);
        }
        let out = &self.output;
        if out.exists() && !out.is_dir() {
            bail!("{}: exists and is not a directory", out.display());
        }
        let info = SweepInfo {
            grid: self.grid_file.clone(),
            grid_text,
            episodes: grid.len(),
            shard: self.shard,
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
            .filter(|e| Shard::holds(self.shard, e.index))
            .collect();
        let in_shard = mine.len();
        let todo: Vec<Episode> = mine
            .into_iter()
            .filter(|e| !row_path(out, e).exists())
            .collect();
        Ok(Prepared {
            grid,
            in_shard,
            todo,
        })
    }

    /// Runs the episodes to run, `jobs` at once, calling `done` after each; the first
    /// error (by episode order) fails the run, finished episodes are kept.
    pub fn run_episodes(&self, prepared: &Prepared, done: &(dyn Fn() + Sync)) -> Result<()> {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(self.jobs)
            .build()
            .context("starting the episode pool")?;
        let results: Vec<Result<()>> = pool.install(|| {
            prepared
                .todo
                .par_iter()
                .map(|e| {
                    let extras = crate::episode::Extras {
                        pictures: self.pictures,
                        record: self.record,
                        bag: self.bag,
                        oracle: prepared.grid.oracle,
                        oracle_cache: Some(self.output.join("oracles")),
                        outputs: self.outputs,
                    };
                    // A panic in one episode fails that episode, not the sweep.
                    let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                        run_one(&prepared.grid, e, &self.output, extras)
                    }))
                    .unwrap_or_else(|panic| {
                        let message = panic
                            .downcast_ref::<String>()
                            .cloned()
                            .or_else(|| panic.downcast_ref::<&str>().map(|s| s.to_string()))
                            .unwrap_or_else(|| "a panic".into());
                        Err(crate::error::invalid!("panicked: {message}"))
                    });
                    done();
                    let failure = self
                        .output
                        .join("episodes")
                        .join(format!("{}.failed.json", e.id));
                    match &r {
                        Err(err) => record_failure(&failure, e, err),
                        // A success replaces an earlier failure.
                        Ok(()) => {
                            let _ = std::fs::remove_file(&failure);
                        }
                    }
                    r.with_context(|| format!("episode {} ({})", e.id, e.scene.label()))
                })
                .collect()
        });
        // Each failure with its causes, as the command line prints an error.
        let failed: Vec<String> = results
            .into_iter()
            .filter_map(Result::err)
            .map(|e| error_chain(&e))
            .collect();
        if !failed.is_empty() {
            bail!(
                "{} episode(s) failed (recorded in episodes/<id>.failed.json; running the sweep again re-runs them):\n  {}",
                failed.len(),
                failed.join("\n  ")
            );
        }
        Ok(())
    }

    /// The CSV, the summary and the plots of every row of the directory; the gates.
    pub fn finish(&self, prepared: &Prepared, gates: &[Gate]) -> Result<Finished> {
        let rows = load_rows(std::slice::from_ref(&self.output))?;
        finish(&self.output, &prepared.grid, &rows, gates, self.shard)
    }
}

/// An error and its sources, `: `-separated.
fn error_chain(e: &dyn std::error::Error) -> String {
    let mut text = e.to_string();
    let mut source = e.source();
    while let Some(s) = source {
        text += &format!(": {s}");
        source = s.source();
    }
    text
}

/// Records a failed episode in `path`, `episodes/<id>.failed.json` (its id, scene and error): no
/// row, so a resumed sweep runs it again. Best effort: the error is reported anyway.
fn record_failure(path: &Path, e: &Episode, err: &crate::error::SweepError) {
    let record = serde_json::json!({
        "id": e.id,
        "scene": e.scene.label(),
        "error": error_chain(err),
    });
    let _ = write_json(path, &record);
}

/// One episode of a sweep directory: its outputs into `episodes/<id>/`, its row file.
fn run_one(
    grid: &SweepGrid,
    e: &Episode,
    out: &Path,
    extras: crate::episode::Extras,
) -> Result<()> {
    let dir = out.join("episodes").join(&e.id);
    run_to_row(grid, e, &dir, &row_path(out, e), extras)
}

/// One episode: its scene, the episode ([`crate::episode::run_episode`]) into `dir`, then
/// its row into `row` (written last, so a row exists only for a finished episode).
pub fn run_to_row(
    grid: &SweepGrid,
    e: &Episode,
    dir: &Path,
    row: &Path,
    extras: crate::episode::Extras,
) -> Result<()> {
    let scene = e.scene(&grid.file)?;
    // No row: whatever the directory holds is from an interrupted run of this episode
    // (partial outputs, temporary files of writes it never finished).
    if dir.exists() {
        std::fs::remove_dir_all(dir)
            .with_context(|| format!("removing the unfinished {}", dir.display()))?;
    }
    let t = Instant::now();
    let report = crate::episode::run_episode(
        &scene,
        e.mode,
        dir,
        extras,
        &mut nbv_core::pipeline::NoObserver,
    )?;
    let r = EpisodeRow::new(e, &report, t.elapsed().as_secs_f64());
    write_json(row, &r)
}

/// Writes the CSV, the summary and the plots of `rows` into `out`; checks the gates.
pub fn finish(
    out: &Path,
    grid: &SweepGrid,
    rows: &[EpisodeRow],
    gates: &[Gate],
    shard: Option<Shard>,
) -> Result<Finished> {
    nbv_core::atomic_file::write_atomic(&out.join("results.csv"), csv_text(rows)?.as_bytes())
        .with_context(|| format!("writing {}", out.join("results.csv").display()))?;
    let aggregate = Aggregate::of(rows);
    let expected: Vec<usize> = (0..grid.len())
        .filter(|k| Shard::holds(shard, *k))
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
        best_by_registration_error: best_setting(rows, |r| r.error_map, false),
        registration: registration_table(rows),
        robustness: robustness_table(rows),
        objectives: crate::objectives::objective_table(rows),
        gates: gate_results,
    };
    write_json(&out.join("summary.json"), &summary)?;
    let plots = crate::plots::write(&out.join("plots"), rows)?;
    Ok(Finished { summary, plots })
}

/// Unions the rows of sweep directories of one grid (e.g. its shards) into `out`, then
/// [`finish`]es it.
pub fn merge(inputs: &[PathBuf], out: &Path, gates: &[Gate]) -> Result<Finished> {
    let mut info: Option<SweepInfo> = None;
    for dir in inputs {
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
                inputs[0].display()
            );
        }
        info.get_or_insert(this);
    }
    let Some(info) = info else {
        bail!("no input directory");
    };
    let grid = SweepGrid::parse(&info.grid_text, &info.grid)?;
    let rows = load_rows(inputs)?;
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
    finish(out, &grid, &rows, gates, None)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rows::tests::row;

    /// Writes a shard directory of `grid_text` holding the rows of episodes `ks`.
    fn shard_dir(root: &Path, grid_text: &str, shard: Shard, ks: &[usize]) -> PathBuf {
        let grid = SweepGrid::parse(grid_text, Path::new("g.toml")).unwrap();
        let episodes = grid.episodes();
        let dir = root.join(format!("shard{}", shard.index));
        std::fs::create_dir_all(dir.join("episodes")).unwrap();
        let info = SweepInfo {
            grid: "g.toml".into(),
            grid_text: grid_text.into(),
            episodes: grid.len(),
            shard: Some(shard),
        };
        write_json(&dir.join("sweep.json"), &info).unwrap();
        for &k in ks {
            let mut r = row(k, "2.0", 0.8, 0.002);
            r.id = episodes[k].id.clone();
            write_json(&row_path(&dir, &episodes[k]), &r).unwrap();
        }
        dir
    }

    #[test]
    fn merge_unions_shards_reports_the_missing_and_checks_gates() {
        let tmp = tempfile::tempdir().unwrap();
        let text = "scenes = [\"a\"]\nseeds = [1, 2, 3]\n";
        // Shard 0/2 finished episode 0 but not 2; shard 1/2 finished episode 1.
        let a = shard_dir(tmp.path(), text, Shard { index: 0, count: 2 }, &[0]);
        let b = shard_dir(tmp.path(), text, Shard { index: 1, count: 2 }, &[1]);
        let out = tmp.path().join("merged");
        let gates: Vec<Gate> = vec![
            "coverage>=0.5".parse().unwrap(),
            "views<=3".parse().unwrap(),
        ];
        let f = merge(&[a.clone(), b.clone()], &out, &gates).unwrap();
        assert_eq!(f.summary.episodes_expected, 3);
        assert_eq!(f.summary.episodes_finished, 2);
        assert_eq!(f.summary.missing, vec![2]);
        assert_eq!(f.summary.aggregate.views, 4);
        assert_eq!(
            f.summary.gates.iter().map(|g| g.pass).collect::<Vec<_>>(),
            [true, false]
        );
        assert!(!f.passed());
        let csv = std::fs::read_to_string(out.join("results.csv")).unwrap();
        assert_eq!(csv.lines().count(), 3);
        assert!(out.join("summary.json").exists());
        assert_eq!(load_rows(std::slice::from_ref(&out)).unwrap().len(), 2);
        // Merging the merge with a shard again adds nothing.
        let again = merge(&[out.clone(), a], &tmp.path().join("again"), &[]).unwrap();
        assert_eq!(again.summary.episodes_finished, 2);
        assert!(again.passed());
        // Shards of another grid are refused.
        let other = shard_dir(
            &tmp.path().join("other"),
            "scenes = [\"b\"]\n",
            Shard { index: 0, count: 1 },
            &[],
        );
        let e = merge(&[b, other], &tmp.path().join("x"), &[]).unwrap_err();
        assert!(e.to_string().contains("a sweep of another grid"), "{e}");
    }
}
