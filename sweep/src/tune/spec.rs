//! [`TuneSpec`]: a tune file parsed and checked — the training episodes (named as a sweep
//! grid names them), the validation seeds, the budget and batch, the parameters with
//! their ranges, the objectives and the constraints. Every error names the file and the
//! key.
//!
//! ```toml
//! scenes = ["paper-env1", "paper-env2"]          # the training episodes, as in a grid
//! generated = { seeds = [1, 2, 3], objects = 3, shapes = "all" }
//! seeds = [1, 2]
//! validation_seeds = [101, 102]                   # the same scenes at unseen seeds
//! budget = 24                                     # trials
//! batch = 2                                       # trials proposed (and run) together
//! seed = 1
//! method = "bayesian"                             # or "random"
//! random_baseline = true                          # also run random search, same budget
//!
//! [parameters]
//! "nbv.alpha_u" = { min = 0.5, max = 8.0, log = true }
//! "nbv.max_views_per_object" = { min = 6, max = 16 }   # integers: an integer range
//! "nbv.objective" = ["paper", "rear-side-entropy"]      # choices
//!
//! [objectives]
//! maximize = "f_score_mean"                       # any sweep metric; one or two in all
//! minimize = "views_per_object"
//!
//! [constraints]
//! collisions = 0                                  # at most; or { min = … } / { max = … }
//! ```

use crate::error::{Result, bail, invalid};
use crate::grid::SweepGrid;
use crate::rows::Aggregate;
use std::path::{Path, PathBuf};

/// The values a tuned parameter may take.
#[derive(Debug, Clone, PartialEq)]
pub enum Range {
    /// A real interval, searched uniformly or (`log`) in the logarithm.
    Float {
        /// Lower bound.
        min: f64,
        /// Upper bound.
        max: f64,
        /// Searched in the logarithm (both bounds positive).
        log: bool,
    },
    /// The integers `min..=max`.
    Int {
        /// Lower bound.
        min: i64,
        /// Upper bound.
        max: i64,
    },
    /// One of these values.
    Choice(Vec<toml::Value>),
}

/// A tuned parameter: a dotted scene key and its range.
#[derive(Debug, Clone, PartialEq)]
pub struct Parameter {
    /// The dotted scene key (`nbv.alpha_u`).
    pub key: String,
    /// Its values.
    pub range: Range,
}

/// Whether an objective is to be made large or small.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Direction {
    /// Larger is better.
    Maximize,
    /// Smaller is better.
    Minimize,
}

/// An objective: a sweep metric ([`Aggregate::METRICS`]) and its direction.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Objective {
    /// The metric.
    pub metric: String,
    /// Its direction.
    pub direction: Direction,
}

impl Objective {
    /// `value` as a loss (smaller is better).
    pub fn loss(&self, value: f64) -> f64 {
        match self.direction {
            Direction::Maximize => -value,
            Direction::Minimize => value,
        }
    }
}

/// A constraint on a sweep metric: a trial that breaks it is infeasible.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Constraint {
    /// The metric.
    pub metric: String,
    /// Its smallest allowed value.
    pub min: Option<f64>,
    /// Its largest allowed value.
    pub max: Option<f64>,
}

impl Constraint {
    /// Whether `value` satisfies it.
    pub fn holds(&self, value: f64) -> bool {
        self.min.is_none_or(|m| value >= m) && self.max.is_none_or(|m| value <= m)
    }
}

/// How trials are proposed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Method {
    /// Bayesian optimisation (egobox: expected improvement for one objective, expected
    /// hypervolume improvement for two), after a Latin-hypercube start.
    Bayesian,
    /// Independent uniform draws (log-uniform for `log` ranges).
    Random,
}

/// A checked tune file.
#[derive(Debug, Clone)]
pub struct TuneSpec {
    /// The file it came from.
    pub file: PathBuf,
    /// Its text (a resumed run must be of the same file).
    pub text: String,
    /// The training episodes (fixed `params`, one value each, apply to every trial).
    pub training: SweepGrid,
    /// The episode seeds the chosen settings are checked on.
    pub validation_seeds: Vec<u64>,
    /// Trials.
    pub budget: usize,
    /// Trials proposed and evaluated together.
    pub batch: usize,
    /// Trials of the Latin-hypercube start (Bayesian optimisation).
    pub initial: usize,
    /// The optimiser's seed.
    pub seed: u64,
    /// How trials are proposed.
    pub method: Method,
    /// Also run random search with the same budget, for comparison.
    pub random_baseline: bool,
    /// The tuned parameters, by key (the order of `trials.csv`).
    pub parameters: Vec<Parameter>,
    /// One or two objectives.
    pub objectives: Vec<Objective>,
    /// Constraints on the trials.
    pub constraints: Vec<Constraint>,
}

/// The keys of a tune file that are not a grid's.
const TUNE_KEYS: [&str; 10] = [
    "validation_seeds",
    "budget",
    "batch",
    "initial",
    "seed",
    "method",
    "random_baseline",
    "parameters",
    "objectives",
    "constraints",
];

impl TuneSpec {
    /// Reads and checks a tune file.
    pub fn load(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| invalid!("reading {}: {e}", path.display()))?;
        Self::parse(&text, path)
    }

    /// Parses and checks tune text (`file` names it in errors).
    pub fn parse(text: &str, file: &Path) -> Result<Self> {
        let f = file.display();
        let mut table: toml::Table = toml::from_str(text)
            .map_err(|e| invalid!("{f}: {}", e.to_string().trim_end().replace('\n', "\n  ")))?;
        let mut tune = toml::Table::new();
        for key in TUNE_KEYS {
            if let Some(v) = table.remove(key) {
                tune.insert(key.to_string(), v);
            }
        }
        if let Some(params) = table.get("params").and_then(toml::Value::as_table)
            && let Some((key, _)) = params
                .iter()
                .find(|(_, v)| v.as_array().is_none_or(|a| a.len() != 1))
        {
            bail!(
                "{f}: `params.\"{key}\"`: a tune file's `params` fix one value for every \
                 trial (`[\"{key}\"] = [value]`); ranges to tune go in `[parameters]`"
            );
        }
        let grid_text = toml::to_string(&table).map_err(|e| invalid!("{f}: {e}"))?;
        let training = SweepGrid::parse(&grid_text, file)?;
        let int = |key: &str, default: i64| -> Result<i64> {
            match tune.get(key) {
                None => Ok(default),
                Some(v) => v
                    .as_integer()
                    .ok_or_else(|| invalid!("{f}: `{key}` must be an integer, not {v}")),
            }
        };
        let positive = |key: &str, default: i64| -> Result<usize> {
            let v = int(key, default)?;
            usize::try_from(v)
                .ok()
                .filter(|&n| n >= 1)
                .ok_or_else(|| invalid!("{f}: `{key}` must be at least 1, not {v}"))
        };
        let budget = positive("budget", 20)?;
        let batch = positive("batch", 1)?;
        let parameters = parse_parameters(tune.get("parameters"), &f.to_string())?;
        if let Some(p) = parameters
            .iter()
            .find(|p| training.params.iter().any(|(k, _)| *k == p.key))
        {
            bail!(
                "{f}: `{}` is both fixed in `[params]` and tuned in `[parameters]`",
                p.key
            );
        }
        let initial = match tune.get("initial") {
            None => (2 * parameters.len() + 1).min(budget),
            Some(_) => positive("initial", 1)?,
        };
        if initial > budget {
            bail!("{f}: `initial` ({initial}) is larger than `budget` ({budget})");
        }
        let seed = u64::try_from(int("seed", 0)?)
            .map_err(|_| invalid!("{f}: `seed` must not be negative"))?;
        let method = match tune.get("method").map(|v| v.as_str()) {
            None | Some(Some("bayesian")) => Method::Bayesian,
            Some(Some("random")) => Method::Random,
            Some(_) => bail!("{f}: `method` must be \"bayesian\" or \"random\""),
        };
        let random_baseline = match tune.get("random_baseline") {
            None => false,
            Some(v) => v
                .as_bool()
                .ok_or_else(|| invalid!("{f}: `random_baseline` must be true or false"))?,
        };
        let validation_seeds = match tune.get("validation_seeds") {
            None => Vec::new(),
            Some(v) => v
                .as_array()
                .and_then(|a| {
                    a.iter()
                        .map(|s| s.as_integer().and_then(|s| u64::try_from(s).ok()))
                        .collect::<Option<Vec<u64>>>()
                })
                .ok_or_else(|| {
                    invalid!("{f}: `validation_seeds` must be a list of seeds (integers ≥ 0)")
                })?,
        };
        let objectives = parse_objectives(tune.get("objectives"), &f.to_string())?;
        let constraints = parse_constraints(tune.get("constraints"), &f.to_string())?;
        Ok(Self {
            file: file.to_path_buf(),
            text: text.to_string(),
            training,
            validation_seeds,
            budget,
            batch,
            initial,
            seed,
            method,
            random_baseline,
            parameters,
            objectives,
            constraints,
        })
    }
}

/// `[parameters]`: each key a range table or a list of choices.
fn parse_parameters(value: Option<&toml::Value>, f: &str) -> Result<Vec<Parameter>> {
    let Some(table) = value.and_then(toml::Value::as_table) else {
        bail!("{f}: no `[parameters]` table (the dotted scene keys to tune and their ranges)");
    };
    if table.is_empty() {
        bail!("{f}: `[parameters]` is empty");
    }
    let mut out = Vec::new();
    for (key, v) in table {
        let at = format!("{f}: `parameters.\"{key}\"`");
        if key.split('.').any(str::is_empty) || !key.contains('.') {
            bail!("{at}: not a dotted scene key (e.g. nbv.alpha_u)");
        }
        let range = match v {
            toml::Value::Array(choices) if choices.len() >= 2 => Range::Choice(choices.clone()),
            toml::Value::Array(_) => bail!("{at}: a list of choices needs at least two values"),
            toml::Value::Table(t) => parse_range(t, &at)?,
            _ => bail!("{at}: give {{ min = …, max = … [, log = true] }} or a list of choices"),
        };
        out.push(Parameter {
            key: key.clone(),
            range,
        });
    }
    Ok(out)
}

/// `{ min, max [, log] }`: integers when both bounds are.
fn parse_range(t: &toml::Table, at: &str) -> Result<Range> {
    if let Some(k) = t
        .keys()
        .find(|k| !["min", "max", "log"].contains(&k.as_str()))
    {
        bail!("{at}: unknown key `{k}` (min, max, log)");
    }
    let (Some(min), Some(max)) = (t.get("min"), t.get("max")) else {
        bail!("{at}: needs `min` and `max`");
    };
    let log = match t.get("log") {
        None => false,
        Some(v) => v
            .as_bool()
            .ok_or_else(|| invalid!("{at}: `log` must be true or false"))?,
    };
    if let (Some(min), Some(max)) = (min.as_integer(), max.as_integer())
        && !log
    {
        if min >= max {
            bail!("{at}: `min` ({min}) must be below `max` ({max})");
        }
        return Ok(Range::Int { min, max });
    }
    let number = |v: &toml::Value, name: &str| {
        v.as_float()
            .or_else(|| v.as_integer().map(|i| i as f64))
            .filter(|x| x.is_finite())
            .ok_or_else(|| invalid!("{at}: `{name}` must be a number, not {v}"))
    };
    let (min, max) = (number(min, "min")?, number(max, "max")?);
    if min >= max {
        bail!("{at}: `min` ({min}) must be below `max` ({max})");
    }
    if log && min <= 0.0 {
        bail!("{at}: a `log` range needs `min` > 0, not {min}");
    }
    Ok(Range::Float { min, max, log })
}

/// `[objectives]`: `maximize` and `minimize`, each a metric or a list; one or two in all.
fn parse_objectives(value: Option<&toml::Value>, f: &str) -> Result<Vec<Objective>> {
    let Some(table) = value.and_then(toml::Value::as_table) else {
        bail!("{f}: no `[objectives]` table (maximize = \"f_score_mean\", minimize = …)");
    };
    let mut out = Vec::new();
    for (key, v) in table {
        let direction = match key.as_str() {
            "maximize" => Direction::Maximize,
            "minimize" => Direction::Minimize,
            other => bail!("{f}: `objectives.{other}`: unknown key (maximize, minimize)"),
        };
        let names: Vec<&str> = match v {
            toml::Value::String(s) => vec![s.as_str()],
            toml::Value::Array(a) => a.iter().filter_map(toml::Value::as_str).collect(),
            _ => bail!("{f}: `objectives.{key}` must be a metric name or a list of them"),
        };
        for name in names {
            check_metric(name, &format!("{f}: `objectives.{key}`"))?;
            out.push(Objective {
                metric: name.to_string(),
                direction,
            });
        }
    }
    if out.is_empty() || out.len() > 2 {
        bail!(
            "{f}: `[objectives]` must name one or two metrics, not {}",
            out.len()
        );
    }
    // The maximised first: the front is drawn with the second on the x axis.
    out.sort_by_key(|o| o.direction == Direction::Minimize);
    Ok(out)
}

/// `[constraints]`: `metric = bound` (at most), or `{ min = …, max = … }`.
fn parse_constraints(value: Option<&toml::Value>, f: &str) -> Result<Vec<Constraint>> {
    let Some(value) = value else {
        return Ok(Vec::new());
    };
    let Some(table) = value.as_table() else {
        bail!("{f}: `constraints` must be a table (metric = largest value)");
    };
    let mut out = Vec::new();
    for (metric, v) in table {
        let at = format!("{f}: `constraints.{metric}`");
        check_metric(metric, &at)?;
        let number = |v: &toml::Value| v.as_float().or_else(|| v.as_integer().map(|i| i as f64));
        let (min, max) = match v {
            toml::Value::Table(t) => {
                if let Some(k) = t.keys().find(|k| !["min", "max"].contains(&k.as_str())) {
                    bail!("{at}: unknown key `{k}` (min, max)");
                }
                let get = |k: &str| match t.get(k) {
                    None => Ok(None),
                    Some(v) => number(v)
                        .map(Some)
                        .ok_or_else(|| invalid!("{at}: `{k}` must be a number")),
                };
                (get("min")?, get("max")?)
            }
            other => (
                None,
                Some(number(other).ok_or_else(|| {
                    invalid!("{at}: give the largest allowed value, or {{ min = …, max = … }}")
                })?),
            ),
        };
        if min.is_none() && max.is_none() {
            bail!("{at}: give `min` or `max`");
        }
        out.push(Constraint {
            metric: metric.clone(),
            min,
            max,
        });
    }
    Ok(out)
}

fn check_metric(name: &str, at: &str) -> Result<()> {
    if Aggregate::METRICS.contains(&name) {
        Ok(())
    } else {
        bail!(
            "{at}: unknown metric `{name}` (one of {})",
            Aggregate::METRICS.join(", ")
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const GOOD: &str = r#"
        scenes = ["paper-env1"]
        seeds = [1, 2]
        validation_seeds = [7]
        budget = 10
        batch = 2
        [parameters]
        "nbv.alpha_u" = { min = 0.5, max = 8.0, log = true }
        "nbv.max_views_per_object" = { min = 4, max = 16 }
        "nbv.objective" = ["paper", "rear-side-entropy"]
        [objectives]
        minimize = "views_per_object"
        maximize = "f_score_mean"
        [constraints]
        collisions = 0
        coverage = { min = 0.5 }
    "#;

    fn parse(text: &str) -> Result<TuneSpec> {
        TuneSpec::parse(text, Path::new("tune.toml"))
    }

    #[test]
    fn a_full_file_is_read() {
        let s = parse(GOOD).unwrap();
        assert_eq!((s.budget, s.batch, s.initial, s.seed), (10, 2, 7, 0));
        assert_eq!(s.training.len(), 2);
        assert_eq!(s.validation_seeds, [7]);
        assert_eq!(s.method, Method::Bayesian);
        let keys: Vec<_> = s.parameters.iter().map(|p| p.key.as_str()).collect();
        assert_eq!(
            keys,
            ["nbv.alpha_u", "nbv.max_views_per_object", "nbv.objective"]
        );
        assert_eq!(s.parameters[1].range, Range::Int { min: 4, max: 16 });
        assert_eq!(s.objectives[0].metric, "f_score_mean");
        assert_eq!(s.objectives[1].direction, Direction::Minimize);
        assert_eq!(s.constraints.len(), 2);
        assert!(s.constraints[0].holds(0.0) && !s.constraints[0].holds(1.0));
        assert!(s.constraints[1].holds(0.6) && !s.constraints[1].holds(0.4));
    }

    #[test]
    fn bad_files_name_the_key() {
        let cases = [
            (GOOD.replace("budget = 10", "budget = 0"), "`budget`"),
            (GOOD.replace("max = 8.0, log", "max = 0.1, log"), "alpha_u"),
            (
                GOOD.replace("min = 0.5, max", "min = -1.0, max"),
                "`log` range",
            ),
            (GOOD.replace("\"f_score_mean\"", "\"f_scor\""), "`f_scor`"),
            (
                GOOD.replace("collisions = 0", "collisions = \"no\""),
                "collisions",
            ),
            (
                GOOD.replace("seeds = [1, 2]\n", "seeds = [1, 2]\nfoo = 1\n"),
                "foo",
            ),
            (
                GOOD.replace("budget = 10", "budget = 10\ninitial = 11"),
                "`initial`",
            ),
            (
                GOOD.replace(
                    "[parameters]",
                    "[params]\n\"nbv.radius\" = [0.4, 0.5]\n[parameters]",
                ),
                "nbv.radius",
            ),
            (
                GOOD.replace(
                    "minimize = \"views_per_object\"",
                    "minimize = [\"views\", \"views_per_object\"]",
                ),
                "one or two",
            ),
        ];
        for (text, needle) in cases {
            let e = parse(&text).unwrap_err().to_string();
            assert!(
                e.contains("tune.toml") && e.contains(needle),
                "{needle}: {e}"
            );
        }
    }
}
