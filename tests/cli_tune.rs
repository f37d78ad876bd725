//! `nbv tune` end to end on short episodes (a generated one-object scene, at most two views
//! per object): the files and the printed summary, a resumed run's `trials.csv` equal to
//! the uninterrupted run's at another `--jobs`, and bad tune files.

mod common;

use common::{nbv, text};
use serde_json::Value;
use std::path::Path;

const TUNE: &str = r#"generated = { seeds = [3], objects = 1 }
seeds = [1]
validation_seeds = [2]
budget = 4
batch = 2
initial = 2
seed = 5
[params]
"nbv.max_views_per_object" = [2]
"registration.baselines" = [false]
[parameters]
"nbv.alpha_u" = { min = 0.5, max = 8.0, log = true }
"nbv.gain_threshold" = { min = 1.0, max = 40.0, log = true }
[objectives]
maximize = "f_score_mean"
minimize = "views_per_object"
[constraints]
collisions = 0
"#;

fn tune(file: &Path, out: &Path, jobs: &str) -> std::process::Output {
    nbv(&[
        "tune",
        file.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--jobs",
        jobs,
        "-q",
    ])
}

#[test]
fn tunes_writes_the_front_and_resumes_to_the_same_trials() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("tune.toml");
    std::fs::write(&file, TUNE).unwrap();
    let out = dir.path().join("run");
    let o = tune(&file, &out, "1");
    assert!(o.status.success(), "{}", text(&o.stderr));
    let stdout = text(&o.stdout);
    assert!(
        stdout.contains("4 trial(s) of 1 episode(s) each"),
        "{stdout}"
    );
    assert!(
        stdout.contains("use (") && stdout.contains("nbv.alpha_u="),
        "{stdout}"
    );
    assert!(stdout.contains("validation seeds, default"), "{stdout}");

    let csv = std::fs::read_to_string(out.join("trials.csv")).unwrap();
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(lines.len(), 5, "{csv}");
    assert!(lines[0].starts_with(
        "arm,trial,source,nbv.alpha_u,nbv.gain_threshold,f_score_mean,f_score_mean_se,\
         views_per_object,views_per_object_se,constraint:collisions,feasible,pareto,"
    ));
    assert!(lines[1].starts_with("tuned,0,initial,") && lines[3].starts_with("tuned,2,"));

    let s: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let labels: Vec<&str> = s["reference"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r["label"].as_str().unwrap())
        .collect();
    assert_eq!(labels, ["default", "paper"]);
    let front = s["pareto"].as_array().unwrap();
    assert!(!front.is_empty() && front.len() <= 4, "{s:#}");
    // Every front point is a trial whose F-score is in (0, 1] and views within the cap.
    for p in front {
        let (f, v) = (
            p["objectives"][0].as_f64().unwrap(),
            p["objectives"][1].as_f64().unwrap(),
        );
        assert!(f > 0.0 && f <= 1.0 && (1.0..=2.0).contains(&v), "{p}");
    }
    assert!(s["recommended"]["trial"].as_u64().unwrap() < 4);
    let validation = s["validation"].as_array().unwrap();
    assert_eq!(validation.last().unwrap()["label"], "default");
    assert_eq!(s["convergence"]["tuned"].as_array().unwrap().len(), 4);
    assert!(out.join("plots/pareto.svg").exists() && out.join("plots/convergence.svg").exists());
    assert!(!out.join(".work").exists());

    // Resume: the last trial's rows and the outputs removed, as a kill during that trial
    // leaves them; the rerun, at another --jobs, runs that trial alone and writes the same
    // trials.csv.
    std::fs::remove_dir_all(out.join("trials/0003")).unwrap();
    std::fs::remove_file(out.join("trials.csv")).unwrap();
    let o = tune(&file, &out, "2");
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert_eq!(
        std::fs::read_to_string(out.join("trials.csv")).unwrap(),
        csv
    );

    // Another tune file into the same directory is refused.
    std::fs::write(&file, TUNE.replace("seed = 5", "seed = 6")).unwrap();
    let o = tune(&file, &out, "1");
    assert!(!o.status.success());
    assert!(
        text(&o.stderr).contains("another tune file"),
        "{}",
        text(&o.stderr)
    );
}

#[test]
fn bad_tune_files_fail_naming_the_key() {
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        (TUNE.replace("budget = 4", "budget = 0"), "`budget`"),
        (
            TUNE.replace("min = 0.5, max = 8.0", "min = 8.0, max = 0.5"),
            "parameters.\"nbv.alpha_u\"",
        ),
        (
            TUNE.replace("\"f_score_mean\"", "\"f_score_best\""),
            "f_score_best",
        ),
        (
            TUNE.replace("collisions = 0", "collisions = \"none\""),
            "constraints.collisions",
        ),
        (
            TUNE.replace(
                "[parameters]\n",
                "[parameters]\n\"nbv\" = { min = 1.0, max = 2.0 }\n",
            ),
            "dotted",
        ),
    ];
    for (i, (text_, needle)) in cases.iter().enumerate() {
        let file = dir.path().join(format!("bad{i}.toml"));
        std::fs::write(&file, text_).unwrap();
        let out = dir.path().join(format!("out{i}"));
        let o = tune(&file, &out, "1");
        assert_eq!(o.status.code(), Some(1), "{needle}");
        let err = text(&o.stderr);
        assert!(
            err.contains(&format!("bad{i}.toml")) && err.contains(needle),
            "{needle}: {err}"
        );
        assert!(!out.join("trials.csv").exists());
    }
}
