//! Trials on disk and their figures: `trials/NNNN.json` (a trial's point, written before it
//! runs), `trials/NNNN/<episode>.row.json` (its finished episodes), and what a trial
//! measured — each objective's mean over the training episodes with its standard error,
//! the per-episode values, the constraints' verdicts.

use crate::error::{Context, Result};
use crate::grid::{Episode, SweepGrid};
use crate::layout::write_json;
use crate::rows::{Aggregate, EpisodeRow};
use crate::tune::proposer::Source;
use crate::tune::spec::{Constraint, Objective};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// A trial: its point and the scene values it runs with.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Trial {
    /// Its index in its arm (0-based).
    pub index: usize,
    /// Where its point came from.
    pub source: Source,
    /// Its point ([`crate::tune::space::Space`] coordinates).
    pub x: Vec<f64>,
    /// Its scene values, `(dotted key, value)`.
    pub params: Vec<(String, toml::Value)>,
}

/// `DIR/trials/NNNN.json`.
pub fn trial_path(arm: &Path, index: usize) -> PathBuf {
    arm.join("trials").join(format!("{index:04}.json"))
}

/// Where the rows of the episodes of `name` (a trial `NNNN`, `default`, …) are kept.
pub fn rows_dir(arm: &Path, name: &str) -> PathBuf {
    arm.join("trials").join(name)
}

/// Writes a trial's file.
pub fn store(arm: &Path, trial: &Trial) -> Result<()> {
    let dir = arm.join("trials");
    std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
    write_json(&trial_path(arm, trial.index), trial)
}

/// Reads trial `index` of the arm, if it was stored.
pub fn load(arm: &Path, index: usize) -> Result<Option<Trial>> {
    let path = trial_path(arm, index);
    if !path.exists() {
        return Ok(None);
    }
    let text =
        std::fs::read_to_string(&path).with_context(|| format!("reading {}", path.display()))?;
    serde_json::from_str(&text)
        .map(Some)
        .with_context(|| format!("{}: not a trial file", path.display()))
}

/// `grid` with `params` fixed for every episode (added to the grid's own fixed values).
pub fn with_params(grid: &SweepGrid, params: &[(String, toml::Value)]) -> SweepGrid {
    let mut g = grid.clone();
    g.params
        .extend(params.iter().map(|(k, v)| (k.clone(), vec![v.clone()])));
    g.params.sort_by(|a, b| a.0.cmp(&b.0));
    g
}

/// `grid` at other episode seeds.
pub fn with_seeds(grid: &SweepGrid, seeds: &[u64]) -> SweepGrid {
    let mut g = grid.clone();
    g.seeds = seeds.iter().map(|&s| Some(s)).collect();
    g
}

/// The row file of episode `e` in `dir`.
pub fn row_file(dir: &Path, e: &Episode) -> PathBuf {
    dir.join(format!("{}.row.json", e.id))
}

/// The rows of `episodes` in `dir`, if every one finished.
pub fn rows_of(dir: &Path, episodes: &[Episode]) -> Result<Option<Vec<EpisodeRow>>> {
    let mut rows = Vec::with_capacity(episodes.len());
    for e in episodes {
        let path = row_file(dir, e);
        if !path.exists() {
            return Ok(None);
        }
        let text = std::fs::read_to_string(&path)
            .with_context(|| format!("reading {}", path.display()))?;
        rows.push(
            serde_json::from_str(&text)
                .with_context(|| format!("{}: not an episode row", path.display()))?,
        );
    }
    Ok(Some(rows))
}

/// What a setting measured over a set of episodes.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Measured {
    /// Each objective's value (the sweep aggregate over the episodes).
    pub objectives: Vec<f64>,
    /// Each objective as a loss (smaller is better: a maximised objective negated).
    pub losses: Vec<f64>,
    /// Each objective's standard error over the episodes (the seed-to-seed noise).
    pub standard_errors: Vec<f64>,
    /// Each objective's value per episode, in the episodes' order.
    pub per_episode: Vec<Vec<f64>>,
    /// Each constraint's metric.
    pub constraint_values: Vec<f64>,
    /// Whether every constraint holds.
    pub feasible: bool,
}

impl Measured {
    /// Whether the trial counts as a result: feasible, every objective a number.
    pub fn usable(&self) -> bool {
        self.feasible && self.losses.iter().all(|l| l.is_finite())
    }

    /// The figures of `rows`.
    pub fn of(rows: &[EpisodeRow], objectives: &[Objective], constraints: &[Constraint]) -> Self {
        let all = Aggregate::of(rows);
        let metric = |a: &Aggregate, name: &str| a.metric(name).unwrap_or(f64::NAN);
        let singles: Vec<Aggregate> = rows
            .iter()
            .map(|r| Aggregate::of(std::slice::from_ref(r)))
            .collect();
        let per_episode: Vec<Vec<f64>> = objectives
            .iter()
            .map(|o| singles.iter().map(|a| metric(a, &o.metric)).collect())
            .collect();
        let standard_errors = per_episode.iter().map(|v| standard_error(v)).collect();
        let constraint_values: Vec<f64> = constraints
            .iter()
            .map(|c| metric(&all, &c.metric))
            .collect();
        let feasible = constraints
            .iter()
            .zip(&constraint_values)
            .all(|(c, &v)| c.holds(v));
        let values: Vec<f64> = objectives.iter().map(|o| metric(&all, &o.metric)).collect();
        Self {
            losses: objectives
                .iter()
                .zip(&values)
                .map(|(o, &v)| o.loss(v))
                .collect(),
            objectives: values,
            standard_errors,
            per_episode,
            constraint_values,
            feasible,
        }
    }
}

/// The standard error of the mean of `v` (0 for fewer than two values).
pub fn standard_error(v: &[f64]) -> f64 {
    let n = v.len() as f64;
    if v.len() < 2 {
        return 0.0;
    }
    let mean = v.iter().sum::<f64>() / n;
    let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (var / n).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn standard_error_of_known_values() {
        assert_eq!(standard_error(&[1.0]), 0.0);
        // sd of (1, 2, 3) is 1; se = 1 / sqrt(3).
        assert!((standard_error(&[1.0, 2.0, 3.0]) - 3f64.sqrt().recip()).abs() < 1e-12);
    }

    #[test]
    fn a_trial_round_trips_through_its_file() {
        let dir = tempfile::tempdir().unwrap();
        let t = Trial {
            index: 3,
            source: Source::Bayesian,
            x: vec![0.25, 2.0],
            params: vec![
                ("nbv.alpha_u".into(), toml::Value::Float(1.284)),
                ("nbv.objective".into(), toml::Value::String("paper".into())),
            ],
        };
        store(dir.path(), &t).unwrap();
        assert_eq!(load(dir.path(), 3).unwrap(), Some(t));
        assert_eq!(load(dir.path(), 4).unwrap(), None);
    }
}
