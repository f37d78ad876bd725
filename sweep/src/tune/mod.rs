//! `nbv tune`: scene parameters (α_u, α_o, the gain threshold, …) tuned by an optimiser
//! over a set of training episodes, against one objective or a Pareto front of two, the
//! chosen settings checked on seeds the tuning did not see.
//!
//! Each trial runs every training episode with its parameters; its figure is the sweep
//! metric over them, with the standard error between episodes (every trial runs the same
//! episodes, so trials are compared on the same scenes and seeds). Trials are proposed in
//! batches ([`proposer`]) and a batch's episodes run in parallel; a proposal depends only
//! on the seed and the finished trials, so the trials do not depend on `--jobs`, and a
//! killed run, started again, resumes from its stored rows to the same `trials.csv`.
//!
//! ```text
//! DIR/tune.json                    the tune file (a resumed run must be of the same one)
//! DIR/trials/NNNN.json             a trial's point; trials/NNNN/<episode>.row.json its rows
//! DIR/random/trials/…              random search's trials (`random_baseline = true`)
//! DIR/reference/{default,paper}/   the scenes' own settings and `nbv.preset = "paper"`
//! DIR/validation/<setting>/        the chosen settings at `validation_seeds`
//! DIR/trials.csv                   one row per trial ([`report::trials_csv`])
//! DIR/summary.json                 best, pareto, validation, reference, convergence
//! DIR/plots/pareto.svg             the front (two objectives); plots/convergence.svg
//! ```
//!
//! - [`spec`]: the tune file; [`space`]: its parameters as coordinates;
//! - [`proposer`]: Latin hypercube, egobox's Bayesian optimisation, random search;
//! - [`trials`]: trials and rows on disk, what a trial measured; [`pareto`]: the front;
//! - [`report`]: `trials.csv`, `summary.json` and the plots.

pub mod pareto;
pub mod proposer;
pub mod report;
pub mod space;
pub mod spec;
pub mod trials;

use crate::error::{Context, Result, bail};
use crate::grid::{Episode, SweepGrid};
use crate::layout::write_json;
use crate::rows::EpisodeRow;
use proposer::{Observation, Proposer};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use spec::{Method, TuneSpec};
use std::path::{Path, PathBuf};
use trials::{Measured, Trial};

/// A tuning to run.
#[derive(Debug, Clone)]
pub struct TuneRun {
    /// The tune file.
    pub spec_file: PathBuf,
    /// The output directory (a resumed run: the same).
    pub output: PathBuf,
    /// Episodes run at once.
    pub jobs: usize,
}

/// `DIR/tune.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
struct TuneInfo {
    file: PathBuf,
    text: String,
}

/// A trial and what it measured on the training episodes.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Evaluated {
    /// The trial.
    pub trial: Trial,
    /// Its figures.
    pub measured: Measured,
}

/// What a progress callback is told.
#[derive(Debug, Clone)]
pub enum Progress {
    /// A batch of trials of an arm (`tuned`, `random`, `reference`, `validation`) starts:
    /// its label and its episodes to run.
    Batch(String, usize),
    /// An episode finished.
    Episode,
}

/// A finished tuning.
#[derive(Debug, Clone)]
pub struct Tuned {
    /// The tuned arm's trials.
    pub trials: Vec<Evaluated>,
    /// Random search's, when asked.
    pub random: Vec<Evaluated>,
    /// `summary.json`.
    pub summary: report::Summary,
    /// The plots written.
    pub plots: Vec<String>,
}

impl TuneRun {
    /// Runs (or resumes) the tuning, then writes its files.
    pub fn run(&self, progress: &(dyn Fn(Progress) + Sync)) -> Result<Tuned> {
        if self.jobs == 0 {
            bail!("--jobs must be at least 1");
        }
        let spec = TuneSpec::load(&self.spec_file)?;
        let out = &self.output;
        prepare(out, &spec)?;
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(self.jobs)
            .build()
            .context("starting the episode pool")?;
        let run = Runner {
            spec: &spec,
            out,
            pool: &pool,
            progress,
        };
        let trials = run.arm(out, spec.method)?;
        let random = if spec.random_baseline && spec.method != Method::Random {
            run.arm(&out.join("random"), Method::Random)?
        } else {
            Vec::new()
        };
        let reference = run.references()?;
        let chosen = report::chosen(&spec, &trials);
        let validation = run.validation(&chosen, &trials)?;
        let summary = report::Summary::new(&spec, &trials, &random, &chosen, reference, validation);
        nbv_core::atomic_file::write_atomic(
            &out.join("trials.csv"),
            report::trials_csv(&spec, &trials, &random)?.as_bytes(),
        )
        .with_context(|| format!("writing {}", out.join("trials.csv").display()))?;
        write_json(&out.join("summary.json"), &summary)?;
        let plots = report::plots(&out.join("plots"), &spec, &trials, &random, &summary)?;
        // Empty once every episode finished (each removes its own scratch directory).
        let _ = std::fs::remove_dir(out.join(".work"));
        Ok(Tuned {
            trials,
            random,
            summary,
            plots,
        })
    }
}

/// Creates `out` or checks it holds a tuning of the same file; clears what an
/// interrupted run left in the work directory.
fn prepare(out: &Path, spec: &TuneSpec) -> Result<()> {
    if out.exists() && !out.is_dir() {
        bail!("{}: exists and is not a directory", out.display());
    }
    let info = TuneInfo {
        file: spec.file.clone(),
        text: spec.text.clone(),
    };
    let path = out.join("tune.json");
    if path.exists() {
        let old: TuneInfo = serde_json::from_str(&std::fs::read_to_string(&path)?)
            .with_context(|| format!("{}: not a tune directory", out.display()))?;
        if old.text != info.text {
            bail!(
                "{}: holds a tuning of another tune file ({}); use a new directory",
                out.display(),
                old.file.display()
            );
        }
    }
    let work = out.join(".work");
    if work.exists() {
        std::fs::remove_dir_all(&work)
            .with_context(|| format!("removing the unfinished {}", work.display()))?;
    }
    std::fs::create_dir_all(out.join("trials"))
        .with_context(|| format!("creating {}", out.display()))?;
    write_json(&path, &info)
}

/// Runs a tuning's episodes.
struct Runner<'a> {
    spec: &'a TuneSpec,
    out: &'a Path,
    pool: &'a rayon::ThreadPool,
    progress: &'a (dyn Fn(Progress) + Sync),
}

impl Runner<'_> {
    /// The trials of one arm (its directory, its method), resumed from what is stored.
    fn arm(&self, dir: &Path, method: Method) -> Result<Vec<Evaluated>> {
        let spec = self.spec;
        let proposer = Proposer {
            space: space::Space::new(&spec.parameters),
            method,
            seed: spec.seed,
            initial: spec.initial,
            objectives: spec.objectives.len(),
        };
        std::fs::create_dir_all(dir.join("trials"))
            .with_context(|| format!("creating {}", dir.display()))?;
        let label = if method == Method::Random {
            "random"
        } else {
            "tuned"
        };
        let mut done: Vec<Evaluated> = Vec::new();
        while done.len() < spec.budget {
            let start = done.len();
            let n = spec.batch.min(spec.budget - start);
            let observed = observations(&done);
            let batch: Vec<Trial> = proposer
                .propose(start, n, &observed)?
                .into_iter()
                .enumerate()
                .map(|(i, (x, source))| Trial {
                    index: start + i,
                    source,
                    params: proposer.space.values(&x),
                    x,
                })
                .collect();
            for t in &batch {
                if trials::load(dir, t.index)?.as_ref() != Some(t) {
                    trials::store(dir, t)?;
                }
            }
            let sets: Vec<(PathBuf, SweepGrid)> = batch
                .iter()
                .map(|t| {
                    let rows = trials::rows_dir(dir, &format!("{:04}", t.index));
                    (rows, trials::with_params(&spec.training, &t.params))
                })
                .collect();
            let rows = self.evaluate(&format!("{label} {start}"), &sets)?;
            for (trial, rows) in batch.into_iter().zip(rows) {
                let measured = Measured::of(&rows, &spec.objectives, &spec.constraints);
                done.push(Evaluated { trial, measured });
            }
        }
        Ok(done)
    }

    /// The scenes' own settings and the paper preset on the training episodes.
    fn references(&self) -> Result<Vec<(String, Measured)>> {
        let spec = self.spec;
        let paper = vec![("nbv.preset".to_string(), toml::Value::from("paper"))];
        let sets = vec![
            (
                self.out.join("reference").join("default"),
                spec.training.clone(),
            ),
            (
                self.out.join("reference").join("paper"),
                trials::with_params(&spec.training, &paper),
            ),
        ];
        let rows = self.evaluate("reference", &sets)?;
        Ok(["default", "paper"]
            .into_iter()
            .zip(rows)
            .map(|(l, r)| {
                (
                    l.to_string(),
                    Measured::of(&r, &spec.objectives, &spec.constraints),
                )
            })
            .collect())
    }

    /// The chosen trials and the scenes' own settings at the validation seeds.
    fn validation(
        &self,
        chosen: &[(String, usize)],
        trials: &[Evaluated],
    ) -> Result<Vec<(String, Option<usize>, Measured)>> {
        let spec = self.spec;
        if spec.validation_seeds.is_empty() {
            return Ok(Vec::new());
        }
        type Setting = (String, Option<usize>, Vec<(String, toml::Value)>);
        let mut settings: Vec<Setting> = chosen
            .iter()
            .map(|(label, i)| (label.clone(), Some(*i), trials[*i].trial.params.clone()))
            .collect();
        settings.push(("default".into(), None, Vec::new()));
        let sets: Vec<(PathBuf, SweepGrid)> = settings
            .iter()
            .map(|(label, _, params)| {
                let grid = trials::with_params(&spec.training, params);
                (
                    self.out.join("validation").join(label),
                    trials::with_seeds(&grid, &spec.validation_seeds),
                )
            })
            .collect();
        let rows = self.evaluate("validation", &sets)?;
        Ok(settings
            .into_iter()
            .zip(rows)
            .map(|((label, trial, _), r)| {
                (
                    label,
                    trial,
                    Measured::of(&r, &spec.objectives, &spec.constraints),
                )
            })
            .collect())
    }

    /// Runs every episode of `sets` (a rows directory and its grid each) that has no row,
    /// `jobs` at once; the rows of each set, in its episodes' order.
    fn evaluate(&self, label: &str, sets: &[(PathBuf, SweepGrid)]) -> Result<Vec<Vec<EpisodeRow>>> {
        let tasks: Vec<(&Path, &SweepGrid, Episode)> = sets
            .iter()
            .flat_map(|(dir, grid)| {
                grid.episodes()
                    .into_iter()
                    .filter(|e| !trials::row_file(dir, e).exists())
                    .map(move |e| (dir.as_path(), grid, e))
            })
            .collect();
        (self.progress)(Progress::Batch(label.to_string(), tasks.len()));
        let results: Vec<Result<()>> = self.pool.install(|| {
            tasks
                .par_iter()
                .map(|(dir, grid, e)| {
                    let r = run_episode(self.out, dir, grid, e);
                    (self.progress)(Progress::Episode);
                    r.with_context(|| format!("episode {} ({})", e.id, e.scene.label()))
                })
                .collect()
        });
        for r in results {
            r?;
        }
        sets.iter()
            .map(|(dir, grid)| {
                trials::rows_of(dir, &grid.episodes())?
                    .with_context(|| format!("{}: rows missing after the run", dir.display()))
            })
            .collect()
    }
}

/// One episode in a scratch directory under `DIR/.work/` (removed after: a tuning keeps
/// the rows alone), its row into `dir`.
fn run_episode(out: &Path, dir: &Path, grid: &SweepGrid, e: &Episode) -> Result<()> {
    let name = dir
        .strip_prefix(out)
        .unwrap_or(dir)
        .to_string_lossy()
        .replace(['/', '\\'], "-");
    let work = out.join(".work").join(format!("{name}-{}", e.id));
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let extras = crate::episode::Extras {
        oracle: grid.oracle,
        oracle_cache: Some(out.join("oracles")),
        outputs: crate::episode::Outputs::ReportOnly,
        ..Default::default()
    };
    crate::engine::run_to_row(grid, e, &work, &trials::row_file(dir, e), extras)?;
    std::fs::remove_dir_all(&work).with_context(|| format!("removing {}", work.display()))
}

/// The finished trials as the optimiser sees them: an infeasible trial (or one whose
/// figure is not a number) takes the worst loss of all trials in each objective, so the
/// surrogate steers away from it without a constraint model.
fn observations(done: &[Evaluated]) -> Vec<Observation> {
    let Some(first) = done.first() else {
        return Vec::new();
    };
    let objectives = first.measured.objectives.len();
    let worst: Vec<f64> = (0..objectives)
        .map(|k| {
            done.iter()
                .map(|e| e.measured.losses[k])
                .filter(|l| l.is_finite())
                .fold(f64::NEG_INFINITY, f64::max)
        })
        .map(|w| if w.is_finite() { w } else { 0.0 })
        .collect();
    done.iter()
        .map(|e| {
            let losses = e.measured.losses.clone();
            let ok = e.measured.usable();
            Observation {
                x: e.trial.x.clone(),
                losses: if ok { losses } else { worst.clone() },
            }
        })
        .collect()
}
