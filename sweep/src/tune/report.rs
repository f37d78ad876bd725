//! What a tuning writes: the settings it chooses, `summary.json` ([`Summary`]),
//! `trials.csv` ([`trials_csv`]) and the plots (`pareto.svg`, `convergence.svg`).

use crate::error::{Result, invalid};
use crate::tune::Evaluated;
use crate::tune::pareto;
use crate::tune::spec::{Constraint, Method, Objective, TuneSpec};
use crate::tune::trials::Measured;
use plotters::prelude::*;
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::Path;

/// A trial's scene values as a map.
fn params_map(e: &Evaluated) -> BTreeMap<String, toml::Value> {
    e.trial.params.iter().cloned().collect()
}

/// The best feasible trial in loss `k` (ties: the other losses, then the first).
fn best_in(trials: &[Evaluated], k: usize) -> Option<usize> {
    (0..trials.len())
        .filter(|&i| trials[i].measured.usable())
        .min_by(|&a, &b| {
            let (la, lb) = (&trials[a].measured.losses, &trials[b].measured.losses);
            la[k]
                .total_cmp(&lb[k])
                .then_with(|| la.iter().sum::<f64>().total_cmp(&lb.iter().sum()))
        })
}

/// The feasible trials' Pareto front (indices into `trials`).
fn feasible_front(trials: &[Evaluated]) -> Vec<usize> {
    let feasible: Vec<usize> = (0..trials.len())
        .filter(|&i| trials[i].measured.usable())
        .collect();
    let losses: Vec<Vec<f64>> = feasible
        .iter()
        .map(|&i| trials[i].measured.losses.clone())
        .collect();
    pareto::front(&losses)
        .into_iter()
        .map(|j| feasible[j])
        .collect()
}

/// The settings a tuning recommends, labelled: `best` for one objective; for two, the
/// best in each (`best-<metric>`) and the front's `knee`, without repeats. The first is
/// the one to use.
pub fn chosen(spec: &TuneSpec, trials: &[Evaluated]) -> Vec<(String, usize)> {
    if spec.objectives.len() == 1 {
        return best_in(trials, 0)
            .map(|i| vec![("best".to_string(), i)])
            .unwrap_or_default();
    }
    let front = feasible_front(trials);
    let losses: Vec<Vec<f64>> = trials.iter().map(|e| e.measured.losses.clone()).collect();
    let mut out: Vec<(String, usize)> = Vec::new();
    let candidates = std::iter::once(("knee".to_string(), pareto::knee(&losses, &front))).chain(
        spec.objectives
            .iter()
            .enumerate()
            .map(|(k, o)| (format!("best-{}", o.metric), best_in(trials, k))),
    );
    for (label, i) in candidates {
        if let Some(i) = i
            && !out.iter().any(|(_, j)| *j == i)
        {
            out.push((label, i));
        }
    }
    out
}

/// `summary.json`.
#[derive(Debug, Clone, Serialize)]
pub struct Summary {
    /// The objectives.
    pub objectives: Vec<Objective>,
    /// The constraints.
    pub constraints: Vec<Constraint>,
    /// How trials were proposed.
    pub method: Method,
    /// Trials.
    pub budget: usize,
    /// Training episodes per trial.
    pub episodes_per_trial: usize,
    /// The best feasible trial in each objective.
    pub best: Vec<Best>,
    /// The feasible trials no other feasible trial dominates (two objectives).
    pub pareto: Vec<Point>,
    /// The settings to use (the first chosen: `best`, or the front's `knee`).
    pub recommended: Option<Point>,
    /// The recommended settings against the scenes' own, episode by episode on the
    /// training episodes (both ran the same scenes and seeds): each objective's mean
    /// difference (recommended − default) and its standard error, so a lead within the
    /// seed-to-seed noise shows as such.
    pub against_default: Vec<Paired>,
    /// The chosen settings and the scenes' own, at the validation seeds, beside their
    /// training figures.
    pub validation: Vec<Validated>,
    /// The scenes' own settings (`default`) and the paper preset on the training episodes.
    pub reference: Vec<Reference>,
    /// Best so far after each trial (one objective: its value; two: the hypervolume the
    /// feasible trials dominate, as a share of the box between the best and worst values
    /// seen), for the tuned trials and random search's.
    pub convergence: Convergence,
}

/// The best trial in one objective.
#[derive(Debug, Clone, Serialize)]
pub struct Best {
    /// The objective's metric.
    pub metric: String,
    /// The trial.
    pub trial: usize,
    /// Its settings.
    pub params: BTreeMap<String, toml::Value>,
    /// Its value.
    pub value: f64,
    /// The standard error of that value over the training episodes.
    pub standard_error: f64,
}

/// A trial and its objectives.
#[derive(Debug, Clone, Serialize)]
pub struct Point {
    /// The trial.
    pub trial: usize,
    /// Its label when chosen (`best`, `knee`, `best-<metric>`).
    pub label: Option<String>,
    /// Its settings.
    pub params: BTreeMap<String, toml::Value>,
    /// Each objective's value.
    pub objectives: Vec<f64>,
    /// Each objective's standard error.
    pub standard_errors: Vec<f64>,
}

/// A paired difference over the same episodes.
#[derive(Debug, Clone, Serialize)]
pub struct Paired {
    /// The objective's metric.
    pub metric: String,
    /// Mean of the per-episode differences.
    pub difference: f64,
    /// Its standard error.
    pub standard_error: f64,
}

/// The paired differences `a − b` per objective over the same episodes.
fn paired(objectives: &[Objective], a: &Measured, b: &Measured) -> Vec<Paired> {
    objectives
        .iter()
        .enumerate()
        .filter_map(|(k, o)| {
            let (x, y) = (a.per_episode.get(k)?, b.per_episode.get(k)?);
            if x.len() != y.len() || x.is_empty() {
                return None;
            }
            let d: Vec<f64> = x.iter().zip(y).map(|(x, y)| x - y).collect();
            Some(Paired {
                metric: o.metric.clone(),
                difference: d.iter().sum::<f64>() / d.len() as f64,
                standard_error: crate::tune::trials::standard_error(&d),
            })
        })
        .collect()
}

/// A setting on the training and the validation episodes.
#[derive(Debug, Clone, Serialize)]
pub struct Validated {
    /// `best`, `knee`, `best-<metric>` or `default`.
    pub label: String,
    /// The trial (none: the scenes' own settings).
    pub trial: Option<usize>,
    /// Its settings.
    pub params: BTreeMap<String, toml::Value>,
    /// Each objective on the training episodes.
    pub training: Vec<f64>,
    /// Each objective at the validation seeds, with its standard error.
    pub validation: Vec<f64>,
    /// Standard errors at the validation seeds.
    pub validation_standard_errors: Vec<f64>,
    /// Whether the constraints hold at the validation seeds.
    pub feasible: bool,
}

/// A reference setting on the training episodes.
#[derive(Debug, Clone, Serialize)]
pub struct Reference {
    /// `default` or `paper`.
    pub label: String,
    /// What it measured.
    pub measured: Measured,
}

/// Best so far against trials.
#[derive(Debug, Clone, Serialize)]
pub struct Convergence {
    /// What is measured (`best f_score_mean`, `hypervolume`).
    pub measure: String,
    /// After each tuned trial (NaN before the first feasible one).
    pub tuned: Vec<f64>,
    /// After each random-search trial.
    pub random: Vec<f64>,
}

fn point(trials: &[Evaluated], i: usize, label: Option<String>) -> Point {
    Point {
        trial: i,
        label,
        params: params_map(&trials[i]),
        objectives: trials[i].measured.objectives.clone(),
        standard_errors: trials[i].measured.standard_errors.clone(),
    }
}

impl Summary {
    /// The summary of a finished tuning, with its [`chosen`] settings.
    pub fn new(
        spec: &TuneSpec,
        trials: &[Evaluated],
        random: &[Evaluated],
        chosen: &[(String, usize)],
        reference: Vec<(String, Measured)>,
        validation: Vec<(String, Option<usize>, Measured)>,
    ) -> Self {
        let label_of = |i: usize| chosen.iter().find(|(_, j)| *j == i).map(|(l, _)| l.clone());
        let best = spec
            .objectives
            .iter()
            .enumerate()
            .filter_map(|(k, o)| {
                let i = best_in(trials, k)?;
                Some(Best {
                    metric: o.metric.clone(),
                    trial: i,
                    params: params_map(&trials[i]),
                    value: trials[i].measured.objectives[k],
                    standard_error: trials[i].measured.standard_errors[k],
                })
            })
            .collect();
        let pareto = if spec.objectives.len() == 2 {
            feasible_front(trials)
                .into_iter()
                .map(|i| point(trials, i, label_of(i)))
                .collect()
        } else {
            Vec::new()
        };
        let validation = validation
            .into_iter()
            .map(|(label, trial, m)| Validated {
                label,
                trial,
                params: trial.map(|i| params_map(&trials[i])).unwrap_or_default(),
                training: match trial {
                    Some(i) => trials[i].measured.objectives.clone(),
                    None => reference
                        .iter()
                        .find(|(l, _)| l == "default")
                        .map(|(_, m)| m.objectives.clone())
                        .unwrap_or_default(),
                },
                validation: m.objectives,
                validation_standard_errors: m.standard_errors,
                feasible: m.feasible,
            })
            .collect();
        let default = reference.iter().find(|(l, _)| l == "default");
        let against_default = match (chosen.first(), default) {
            (Some((_, i)), Some((_, d))) => paired(&spec.objectives, &trials[*i].measured, d),
            _ => Vec::new(),
        };
        Self {
            against_default,
            objectives: spec.objectives.clone(),
            constraints: spec.constraints.clone(),
            method: spec.method,
            budget: spec.budget,
            episodes_per_trial: spec.training.len(),
            best,
            pareto,
            recommended: chosen
                .first()
                .map(|(l, i)| point(trials, *i, Some(l.clone()))),
            validation,
            reference: reference
                .into_iter()
                .map(|(label, measured)| Reference { label, measured })
                .collect(),
            convergence: convergence(spec, trials, random),
        }
    }
}

/// Best so far after each trial of both arms.
fn convergence(spec: &TuneSpec, trials: &[Evaluated], random: &[Evaluated]) -> Convergence {
    let ok = |e: &&Evaluated| e.measured.usable();
    if spec.objectives.len() == 1 {
        let o = &spec.objectives[0];
        let curve = |arm: &[Evaluated]| -> Vec<f64> {
            let mut best = f64::INFINITY;
            arm.iter()
                .map(|e| {
                    if ok(&e) {
                        best = best.min(e.measured.losses[0]);
                    }
                    if best.is_finite() {
                        o.loss(best)
                    } else {
                        f64::NAN
                    }
                })
                .collect()
        };
        return Convergence {
            measure: format!("best {}", o.metric),
            tuned: curve(trials),
            random: curve(random),
        };
    }
    // The box: the best and worst feasible losses of both arms.
    let all: Vec<&Evaluated> = trials.iter().chain(random).filter(ok).collect();
    let lo = |k: usize| {
        all.iter()
            .map(|e| e.measured.losses[k])
            .fold(f64::INFINITY, f64::min)
    };
    let hi = |k: usize| {
        all.iter()
            .map(|e| e.measured.losses[k])
            .fold(f64::NEG_INFINITY, f64::max)
    };
    let (ideal, nadir) = ([lo(0), lo(1)], [hi(0), hi(1)]);
    let span = [
        (nadir[0] - ideal[0]).max(1e-12),
        (nadir[1] - ideal[1]).max(1e-12),
    ];
    // The reference point 10 % beyond the worst, so the extreme points count.
    let reference = [1.1, 1.1];
    let curve = |arm: &[Evaluated]| -> Vec<f64> {
        let mut seen: Vec<Vec<f64>> = Vec::new();
        arm.iter()
            .map(|e| {
                if ok(&e) {
                    let l = &e.measured.losses;
                    seen.push(vec![
                        (l[0] - ideal[0]) / span[0],
                        (l[1] - ideal[1]) / span[1],
                    ]);
                }
                pareto::hypervolume(&seen, reference) / (1.1 * 1.1)
            })
            .collect()
    };
    Convergence {
        measure: "hypervolume".into(),
        tuned: curve(trials),
        random: curve(random),
    }
}

/// `trials.csv`: per trial (tuned, then random search's) its arm, index, source, settings,
/// objectives with standard errors, constraint metrics, feasibility, whether on the
/// front, and each objective per training episode (`<metric>@<episode>`).
pub fn trials_csv(spec: &TuneSpec, trials: &[Evaluated], random: &[Evaluated]) -> Result<String> {
    let mut w = csv::Writer::from_writer(Vec::new());
    let episodes: Vec<String> = spec
        .training
        .episodes()
        .iter()
        .map(|e| {
            let seed = e.seed.map(|s| format!("/s{s}")).unwrap_or_default();
            format!("{}{seed}/{}", e.scene.label(), e.mode.name())
        })
        .collect();
    let mut header: Vec<String> = ["arm", "trial", "source"].map(String::from).to_vec();
    header.extend(spec.parameters.iter().map(|p| p.key.clone()));
    for o in &spec.objectives {
        header.push(o.metric.clone());
        header.push(format!("{}_se", o.metric));
    }
    header.extend(
        spec.constraints
            .iter()
            .map(|c| format!("constraint:{}", c.metric)),
    );
    header.extend(["feasible", "pareto"].map(String::from));
    for o in &spec.objectives {
        header.extend(episodes.iter().map(|e| format!("{}@{e}", o.metric)));
    }
    w.write_record(&header)?;
    for (arm, list) in [("tuned", trials), ("random", random)] {
        let front = feasible_front(list);
        for (i, e) in list.iter().enumerate() {
            let m = &e.measured;
            let mut rec = vec![
                arm.to_string(),
                e.trial.index.to_string(),
                serde_json::to_string(&e.trial.source)?
                    .trim_matches('"')
                    .to_string(),
            ];
            rec.extend(e.trial.params.iter().map(|(_, v)| match v {
                toml::Value::String(s) => s.clone(),
                other => other.to_string(),
            }));
            for (v, se) in m.objectives.iter().zip(&m.standard_errors) {
                rec.push(v.to_string());
                rec.push(se.to_string());
            }
            rec.extend(m.constraint_values.iter().map(f64::to_string));
            rec.push(m.feasible.to_string());
            rec.push((spec.objectives.len() == 2 && front.contains(&i)).to_string());
            for values in &m.per_episode {
                rec.extend(values.iter().map(f64::to_string));
            }
            w.write_record(&rec)?;
        }
    }
    let bytes = w.into_inner().map_err(|e| invalid!("csv: {e}"))?;
    Ok(String::from_utf8(bytes)?)
}

/// A plotting error as the crate's.
fn err(e: impl std::fmt::Display) -> crate::SweepError {
    invalid!("{e}")
}

fn save(path: &Path, svg: &str) -> Result<()> {
    nbv_scenes::paths::write_atomic(path, svg.as_bytes())
        .map_err(|e| invalid!("writing {}: {e}", path.display()))
}

/// Writes `plots/convergence.svg` and, with two objectives, `plots/pareto.svg`; the files.
pub fn plots(
    dir: &Path,
    spec: &TuneSpec,
    trials: &[Evaluated],
    random: &[Evaluated],
    summary: &Summary,
) -> Result<Vec<String>> {
    std::fs::create_dir_all(dir)?;
    let mut written = Vec::new();
    save(
        &dir.join("convergence.svg"),
        &convergence_svg(&summary.convergence)?,
    )?;
    written.push("convergence.svg".to_string());
    if spec.objectives.len() == 2 {
        save(
            &dir.join("pareto.svg"),
            &pareto_svg(spec, trials, random, summary)?,
        )?;
        written.push("pareto.svg".to_string());
    }
    Ok(written)
}

fn convergence_svg(c: &Convergence) -> Result<String> {
    let mut svg = String::new();
    let finite = c
        .tuned
        .iter()
        .chain(&c.random)
        .copied()
        .filter(|v| v.is_finite());
    let (lo, hi) = finite.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
        (a.min(v), b.max(v))
    });
    let (lo, hi) = if lo.is_finite() {
        (lo, hi.max(lo + 1e-9))
    } else {
        (0.0, 1.0)
    };
    let pad = 0.05 * (hi - lo);
    let n = c.tuned.len().max(c.random.len()).max(2);
    let root = SVGBackend::with_string(&mut svg, (800, 500)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| invalid!("{e}"))?;
    let mut chart = ChartBuilder::on(&root)
        .caption(format!("{} against trials", c.measure), ("sans-serif", 20))
        .margin(20)
        .x_label_area_size(50)
        .y_label_area_size(70)
        .build_cartesian_2d(1f64..n as f64, (lo - pad)..(hi + pad))
        .map_err(|e| invalid!("{e}"))?;
    chart
        .configure_mesh()
        .x_desc("trials")
        .x_label_formatter(&|x| format!("{x:.0}"))
        .y_desc(c.measure.as_str())
        .draw()
        .map_err(|e| invalid!("{e}"))?;
    for (name, curve, color) in [
        ("tuned", &c.tuned, RGBColor(31, 119, 180)),
        ("random search", &c.random, RGBColor(255, 127, 14)),
    ] {
        let pts: Vec<(f64, f64)> = curve
            .iter()
            .enumerate()
            .filter(|(_, v)| v.is_finite())
            .map(|(i, &v)| ((i + 1) as f64, v))
            .collect();
        if pts.is_empty() {
            continue;
        }
        chart
            .draw_series(LineSeries::new(pts, color.stroke_width(2)))
            .map_err(|e| invalid!("{e}"))?
            .label(name)
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], color));
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(|e| invalid!("{e}"))?;
    root.present().map_err(|e| invalid!("{e}"))?;
    drop(chart);
    drop(root);
    Ok(svg)
}

/// The front: every trial (second objective across, first up), the front joined, the
/// scenes' own settings and the paper preset marked.
fn pareto_svg(
    spec: &TuneSpec,
    trials: &[Evaluated],
    random: &[Evaluated],
    summary: &Summary,
) -> Result<String> {
    let mut svg = String::new();
    let xy = |m: &Measured| (m.objectives[1], m.objectives[0]);
    let mut all: Vec<(f64, f64)> = trials
        .iter()
        .chain(random)
        .map(|e| xy(&e.measured))
        .collect();
    all.extend(summary.reference.iter().map(|r| xy(&r.measured)));
    all.retain(|p| p.0.is_finite() && p.1.is_finite());
    let range = |f: fn(&(f64, f64)) -> f64| {
        let (lo, hi) = all
            .iter()
            .map(f)
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                (a.min(v), b.max(v))
            });
        if lo.is_finite() {
            let pad = 0.08 * (hi - lo).max(1e-6);
            (lo - pad)..(hi + pad)
        } else {
            0.0..1.0
        }
    };
    let (xr, yr) = (range(|p| p.0), range(|p| p.1));
    let root = SVGBackend::with_string(&mut svg, (800, 600)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| invalid!("{e}"))?;
    let mut chart = ChartBuilder::on(&root)
        .caption(
            format!(
                "{} against {}",
                spec.objectives[0].metric, spec.objectives[1].metric
            ),
            ("sans-serif", 20),
        )
        .margin(20)
        .x_label_area_size(50)
        .y_label_area_size(70)
        .build_cartesian_2d(xr, yr)
        .map_err(|e| invalid!("{e}"))?;
    chart
        .configure_mesh()
        .x_desc(spec.objectives[1].metric.as_str())
        .y_desc(spec.objectives[0].metric.as_str())
        .draw()
        .map_err(|e| invalid!("{e}"))?;
    let grey = RGBColor(150, 150, 150);
    let blue = RGBColor(31, 119, 180);
    let red = RGBColor(214, 39, 40);
    let infeasible: Vec<&Evaluated> = trials.iter().filter(|e| !e.measured.feasible).collect();
    // Series with no point stay out of the legend.
    if !random.is_empty() {
        chart
            .draw_series(
                random
                    .iter()
                    .map(|e| Circle::new(xy(&e.measured), 3, grey.filled())),
            )
            .map_err(err)?
            .label("random search")
            .legend(move |(x, y)| Circle::new((x + 10, y), 3, grey.filled()));
    }
    chart
        .draw_series(
            trials
                .iter()
                .filter(|e| e.measured.feasible)
                .map(|e| Circle::new(xy(&e.measured), 4, blue.filled())),
        )
        .map_err(err)?
        .label("trials")
        .legend(move |(x, y)| Circle::new((x + 10, y), 4, blue.filled()));
    if !infeasible.is_empty() {
        chart
            .draw_series(
                infeasible
                    .iter()
                    .map(|e| Cross::new(xy(&e.measured), 4, red.stroke_width(2))),
            )
            .map_err(err)?
            .label("infeasible")
            .legend(move |(x, y)| Cross::new((x + 10, y), 4, red.stroke_width(2)));
    }
    let mut front: Vec<(f64, f64)> = summary
        .pareto
        .iter()
        .map(|p| (p.objectives[1], p.objectives[0]))
        .collect();
    front.sort_by(|a, b| a.0.total_cmp(&b.0));
    chart
        .draw_series(LineSeries::new(front, blue.stroke_width(2)))
        .map_err(err)?
        .label("front")
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], blue));
    for (r, color) in summary
        .reference
        .iter()
        .zip([RGBColor(44, 160, 44), RGBColor(255, 127, 14)])
    {
        let p = xy(&r.measured);
        chart
            .draw_series(std::iter::once(TriangleMarker::new(p, 9, color.filled())))
            .map_err(err)?
            .label(format!("{} settings", r.label))
            .legend(move |(x, y)| TriangleMarker::new((x + 10, y), 6, color.filled()));
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(err)?;
    root.present().map_err(err)?;
    drop(chart);
    drop(root);
    Ok(svg)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tune::proposer::Source;
    use crate::tune::trials::Trial;
    use proptest::prelude::*;
    use std::path::Path;

    const SPEC: &str = r#"generated = { seeds = [1], objects = 1 }
        [parameters]
        "nbv.alpha_u" = { min = 0.5, max = 8.0 }
        [objectives]
        maximize = "f_score_mean"
        minimize = "views_per_object"
        [constraints]
        collisions = 0
    "#;

    fn spec(text: &str) -> TuneSpec {
        TuneSpec::parse(text, Path::new("t.toml")).unwrap()
    }

    /// A trial measuring F-score `f` with `views` views, feasible or not.
    fn trial(index: usize, f: f64, views: f64, feasible: bool) -> Evaluated {
        Evaluated {
            trial: Trial {
                index,
                source: Source::Random,
                x: vec![index as f64],
                params: vec![("nbv.alpha_u".into(), toml::Value::Float(index as f64))],
            },
            measured: Measured {
                objectives: vec![f, views],
                losses: vec![-f, views],
                standard_errors: vec![0.0, 0.0],
                per_episode: vec![vec![f, f], vec![views, views]],
                constraint_values: vec![if feasible { 0.0 } else { 1.0 }],
                feasible,
            },
        }
    }

    #[test]
    fn chosen_settings_of_a_hand_made_front() {
        let s = spec(SPEC);
        let t = vec![
            trial(0, 0.80, 4.0, true),
            trial(1, 0.90, 6.0, true),
            trial(2, 0.95, 12.0, true),
            trial(3, 0.99, 3.0, false), // best in both, but infeasible
            trial(4, 0.85, 8.0, true),  // dominated by trial 1
        ];
        let chosen = chosen(&s, &t);
        assert_eq!(
            chosen,
            [
                ("knee".to_string(), 1),
                ("best-f_score_mean".to_string(), 2),
                ("best-views_per_object".to_string(), 0)
            ]
        );
        let summary = Summary::new(
            &s,
            &t,
            &[],
            &chosen,
            vec![("default".into(), t[4].measured.clone())],
            vec![],
        );
        let front: Vec<usize> = summary.pareto.iter().map(|p| p.trial).collect();
        assert_eq!(front, [0, 1, 2]);
        // Knee (trial 1) against the default (trial 4's figures): +0.05 F, −2 views.
        assert!((summary.against_default[0].difference - 0.05).abs() < 1e-12);
        assert!((summary.against_default[1].difference + 2.0).abs() < 1e-12);
    }

    proptest! {
        /// Best so far never worsens, with one objective or two (the hypervolume).
        #[test]
        fn convergence_never_worsens(
            trials in prop::collection::vec((0.0f64..1.0, 1.0f64..16.0, any::<bool>()), 1..20)
        ) {
            let t: Vec<Evaluated> = trials
                .iter()
                .enumerate()
                .map(|(i, &(f, v, ok))| trial(i, f, v, ok))
                .collect();
            let one = spec(&SPEC.replace("minimize = \"views_per_object\"", ""));
            for s in [spec(SPEC), one] {
                let c = convergence(&s, &t, &[]);
                let finite: Vec<f64> = c.tuned.iter().copied().filter(|v| v.is_finite()).collect();
                for w in finite.windows(2) {
                    prop_assert!(w[1] >= w[0] - 1e-12, "{:?}", c.tuned);
                }
            }
        }
    }
}
