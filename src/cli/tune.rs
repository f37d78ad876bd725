//! `nbv tune`: scene parameters tuned by Bayesian optimisation over training episodes
//! ([`nbv_sweep::tune`]); this file parses the arguments, shows progress and prints the
//! settings to use and how they held on the validation seeds.

use anyhow::Result;
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use nbv_sweep::tune::report::{Point, Summary};
use nbv_sweep::tune::{Progress, TuneRun};
use std::path::PathBuf;
use std::sync::Mutex;

/// Arguments of `nbv tune`.
#[derive(Debug, Args)]
#[command(after_long_help = "\
TUNE FILE (TOML)
  scenes = [\"paper-env1\", \"paper-env2\"]            # training episodes, as in a sweep grid
  generated = { seeds = [1, 2, 3], objects = 3, shapes = \"all\" }
  seeds = [1, 2]
  validation_seeds = [101, 102]                     # the chosen settings re-run at these
  budget = 24                                       # trials
  batch = 2                                         # trials proposed and run together
  initial = 7                                       # Latin-hypercube start (default 2d+1)
  seed = 1
  method = \"bayesian\"                               # or \"random\"
  random_baseline = true                            # random search too, for comparison
  [params]                                          # fixed for every trial (one value each)
  \"nbv.max_views_per_object\" = [12]
  [parameters]                                      # tuned: ranges or choices
  \"nbv.alpha_u\" = { min = 0.5, max = 8.0, log = true }
  \"nbv.alpha_o\" = { min = 0.25, max = 4.0, log = true }
  \"nbv.gain_threshold\" = { min = 1.0, max = 20.0 }
  \"nbv.objective\" = [\"paper\", \"rear-side-entropy\"]
  [objectives]                                      # one or two sweep metrics
  maximize = \"f_score_mean\"
  minimize = \"views_per_object\"
  [constraints]                                     # metric = largest value, or { min, max }
  collisions = 0
  missed = 0

OUTPUTS
  DIR/trials.csv, DIR/summary.json (best, pareto, recommended, validation, reference,
  convergence), DIR/plots/pareto.svg (two objectives), DIR/plots/convergence.svg.
  Started again with the same command, a killed run resumes from its stored trials.")]
pub struct TuneArgs {
    /// The tune file.
    file: PathBuf,
    /// Output directory (created; a resumed run: the same).
    #[arg(short, long)]
    output: PathBuf,
    /// Episodes run at once (the trials do not depend on it).
    #[arg(long, default_value_t = 1)]
    jobs: usize,
    /// No progress bar.
    #[arg(long, short)]
    quiet: bool,
}

/// Runs `nbv tune`.
pub fn run(args: TuneArgs) -> Result<()> {
    let bar = Mutex::new(if args.quiet {
        ProgressBar::hidden()
    } else {
        ProgressBar::new(0)
    });
    if let Ok(b) = bar.lock() {
        b.set_style(
            ProgressStyle::with_template("[{elapsed_precise}] {msg} {bar:30} {pos}/{len} episodes")
                .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
    }
    let progress = |p: Progress| {
        let Ok(b) = bar.lock() else { return };
        match p {
            Progress::Batch(label, n) => {
                b.set_message(label);
                b.set_position(0);
                b.set_length(n as u64);
            }
            Progress::Episode => b.inc(1),
        }
    };
    let tuned = TuneRun {
        spec_file: args.file.clone(),
        output: args.output.clone(),
        jobs: args.jobs,
    }
    .run(&progress);
    if let Ok(b) = bar.lock() {
        b.finish_and_clear();
    }
    let tuned = tuned?;
    print!("{}", summary_text(&tuned.summary));
    println!(
        "wrote {}: trials.csv, summary.json, plots/{}",
        args.output.display(),
        tuned.plots.join(", plots/")
    );
    Ok(())
}

/// `key=value, …`.
fn settings(p: &std::collections::BTreeMap<String, toml::Value>) -> String {
    if p.is_empty() {
        return "the scenes' own settings".into();
    }
    p.iter()
        .map(|(k, v)| format!("{k}={v}"))
        .collect::<Vec<_>>()
        .join(" ")
}

/// `f_score_mean 0.951 ± 0.004, views_per_object 8.2 ± 0.3`.
fn figures(s: &Summary, values: &[f64], errors: &[f64]) -> String {
    s.objectives
        .iter()
        .zip(values.iter().zip(errors))
        .map(|(o, (v, e))| format!("{} {v:.3} ± {e:.3}", o.metric))
        .collect::<Vec<_>>()
        .join(", ")
}

fn summary_text(s: &Summary) -> String {
    let mut t = format!(
        "{} trial(s) of {} episode(s) each ({:?})",
        s.budget, s.episodes_per_trial, s.method
    );
    if s.objectives.len() == 2 {
        t += &format!("; {} on the front", s.pareto.len());
    }
    t += "\n";
    for r in &s.reference {
        t += &format!(
            "  {:<8} {}{}\n",
            r.label,
            figures(s, &r.measured.objectives, &r.measured.standard_errors),
            if r.measured.feasible {
                ""
            } else {
                " (infeasible)"
            }
        );
    }
    match &s.recommended {
        Some(Point {
            trial,
            label,
            params,
            objectives,
            standard_errors,
        }) => {
            t += &format!(
                "use ({}, trial {trial}): {}\n  training: {}\n",
                label.as_deref().unwrap_or("best"),
                settings(params),
                figures(s, objectives, standard_errors)
            );
        }
        None => t += "no trial met the constraints\n",
    }
    if !s.against_default.is_empty() {
        let d: Vec<String> = s
            .against_default
            .iter()
            .map(|p| {
                format!(
                    "{} {:+.3} ± {:.3}",
                    p.metric, p.difference, p.standard_error
                )
            })
            .collect();
        t += &format!(
            "  against the scenes' own, episode by episode: {}\n",
            d.join(", ")
        );
    }
    for v in &s.validation {
        t += &format!(
            "  validation seeds, {:<8} {}{}\n",
            v.label,
            figures(s, &v.validation, &v.validation_standard_errors),
            if v.feasible { "" } else { " (infeasible)" }
        );
    }
    t
}
