//! `nbv sweep` end to end on fast episodes (the mid-only baseline on a generated one-object
//! scene): three shards merged equal the unsharded run, `--report-only` gives the same
//! rows and keeps each episode's report alone, an interrupted sweep resumes
//! without losing or duplicating rows, gates exit 4 naming the failed gate, and bad grids
//! fail clearly.

mod common;

use common::{nbv, text};
use std::path::Path;

const GRID: &str = r#"generated = { seeds = [3], objects = 1 }
modes = ["mid-only"]
seeds = [1, 2]
[params]
"nbv.alpha_u" = [2.0, 4.0, 8.0]
"#;

fn write_grid(dir: &Path, text: &str) -> String {
    let p = dir.join("grid.toml");
    std::fs::write(&p, text).unwrap();
    p.display().to_string()
}

fn sweep(args: &[&str]) -> std::process::Output {
    let mut a = vec!["sweep"];
    a.extend_from_slice(args);
    nbv(&a)
}

/// The CSV without its last column (the episode times).
fn without_times(dir: &Path) -> Vec<String> {
    std::fs::read_to_string(dir.join("results.csv"))
        .unwrap()
        .lines()
        .map(|l| l.rsplit_once(',').unwrap().0.to_string())
        .collect()
}

#[test]
fn shards_merged_equal_the_whole_and_resume_does_not_duplicate() {
    let dir = tempfile::tempdir().unwrap();
    let grid = write_grid(dir.path(), GRID);
    let whole = dir.path().join("whole");
    let out = sweep(&[
        "run",
        &grid,
        "-o",
        whole.to_str().unwrap(),
        "-q",
        "--jobs",
        "2",
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let rows = without_times(&whole);
    assert_eq!(rows.len(), 7, "{rows:?}"); // header + 6 episodes
    assert!(rows[0].starts_with("index,id,scene,mode,seed,nbv.alpha_u,objects,"));
    assert!(rows[1].starts_with("0,0000-") && rows[6].starts_with("5,0005-"));

    // `--report-only`: the same rows; each episode's directory holds its report alone,
    // where the whole run's hold the sweep cloud, the grids and the models too.
    let lean = dir.path().join("lean");
    let out = sweep(&[
        "run",
        &grid,
        "-o",
        lean.to_str().unwrap(),
        "-q",
        "--jobs",
        "2",
        "--report-only",
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert_eq!(without_times(&lean), rows);
    let files = |run: &Path| -> Vec<Vec<String>> {
        let mut dirs: Vec<_> = std::fs::read_dir(run.join("episodes"))
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.is_dir())
            .collect();
        dirs.sort();
        dirs.iter()
            .map(|d| {
                let mut names: Vec<String> = std::fs::read_dir(d)
                    .unwrap()
                    .map(|f| f.unwrap().file_name().into_string().unwrap())
                    .collect();
                names.sort();
                names
            })
            .collect()
    };
    let lean_files = files(&lean);
    assert_eq!(lean_files.len(), 6);
    assert!(
        lean_files.iter().all(|f| f == &["report.json"]),
        "{lean_files:?}"
    );
    assert!(
        files(&whole)
            .iter()
            .all(|f| f.iter().any(|n| n == "mid_range.ply"))
    );

    let mut shards = Vec::new();
    for i in 0..3 {
        let d = dir.path().join(format!("shard{i}"));
        let out = sweep(&[
            "run",
            &grid,
            "-o",
            d.to_str().unwrap(),
            "-q",
            "--shard",
            &format!("{i}/3"),
        ]);
        assert!(out.status.success(), "{}", text(&out.stderr));
        assert_eq!(without_times(&d).len(), 3, "shard {i}");
        shards.push(d.display().to_string());
    }
    let merged = dir.path().join("merged");
    let mut args = vec!["merge"];
    args.extend(shards.iter().map(String::as_str));
    args.extend(["-o", merged.to_str().unwrap()]);
    let out = sweep(&args);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert_eq!(without_times(&merged), rows);
    // Merging a shard twice does not duplicate its rows.
    let out = sweep(&[
        "merge",
        &shards[0],
        &shards[0],
        &shards[1],
        &shards[2],
        "-o",
        merged.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert_eq!(without_times(&merged), rows);

    // Interrupted: one finished episode lost; the rerun runs exactly that one.
    let lost = std::fs::read_dir(whole.join("episodes"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| {
            p.to_string_lossy().contains("0003-") && p.to_string_lossy().ends_with(".row.json")
        })
        .unwrap();
    std::fs::remove_file(&lost).unwrap();
    let out = sweep(&["run", &grid, "-o", whole.to_str().unwrap(), "-q"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(
        text(&out.stderr).contains("5 already done, 1 to run"),
        "{}",
        text(&out.stderr)
    );
    assert_eq!(without_times(&whole), rows);
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(whole.join("summary.json")).unwrap())
            .unwrap();
    assert_eq!(summary["episodes_finished"], 6);
    assert_eq!(summary["missing"].as_array().unwrap().len(), 0);
    assert!(whole.join("plots/heatmap_coverage.svg").is_file());
    assert!(whole.join("plots/coverage_vs_views.svg").is_file());
}

#[test]
fn gates_fail_with_status_4_and_name_the_gate() {
    let dir = tempfile::tempdir().unwrap();
    let grid = write_grid(
        dir.path(),
        "generated = { seeds = [3], objects = 1 }\nmodes = [\"mid-only\"]\n",
    );
    let out_dir = dir.path().join("g");
    let out = sweep(&[
        "run",
        &grid,
        "-o",
        out_dir.to_str().unwrap(),
        "-q",
        "--require",
        "collisions==0",
        "--require",
        "coverage>=0.99",
        "--require",
        "f_score>0",
    ]);
    assert_eq!(out.status.code(), Some(4), "{}", text(&out.stderr));
    let s = text(&out.stdout);
    assert!(s.contains("gate collisions==0: pass"), "{s}");
    assert!(s.contains("gate f_score>0: pass"), "{s}");
    assert!(s.contains("best by F-score: mode=mid-only"), "{s}");
    assert!(
        s.contains("gate coverage>=0.99: FAILED (measured 0."),
        "{s}"
    );
    // The outputs are written all the same.
    assert!(out_dir.join("summary.json").is_file());
    let out = sweep(&[
        "run",
        &grid,
        "-o",
        out_dir.to_str().unwrap(),
        "-q",
        "--require",
        "collisions==0",
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let out = sweep(&[
        "run",
        &grid,
        "-o",
        out_dir.to_str().unwrap(),
        "--require",
        "speed>1",
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out.stderr).contains("unknown metric `speed`"));
}

#[test]
fn bad_grids_fail_clearly() {
    let dir = tempfile::tempdir().unwrap();
    let grid = write_grid(
        dir.path(),
        "scenes = [\"paper-env1\"]\nmodes = [\"fast\"]\n",
    );
    let out = sweep(&["run", &grid, "-o", dir.path().join("o").to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1));
    let e = text(&out.stderr);
    assert!(
        e.contains("grid.toml") && e.contains("unknown mode `fast`"),
        "{e}"
    );
    assert!(!dir.path().join("o").exists());

    // A misspelt scene key names itself; the sweep stops with the episode's error.
    let grid = write_grid(
        dir.path(),
        "generated = { seeds = [3], objects = 1 }\nmodes = [\"mid-only\"]\n[params]\n\"nbv.alpha_x\" = [1.0]\n",
    );
    let out = sweep(&[
        "run",
        &grid,
        "-o",
        dir.path().join("o2").to_str().unwrap(),
        "-q",
    ]);
    assert_eq!(out.status.code(), Some(1));
    let e = text(&out.stderr);
    assert!(e.contains("no key `nbv.alpha_x`"), "{e}");
    // A value the scene's validation rejects names the key.
    let grid = write_grid(
        dir.path(),
        "generated = { seeds = [3], objects = 1 }\nmodes = [\"mid-only\"]\n[params]\n\"nbv.alpha_u\" = [-1.0]\n",
    );
    let out = sweep(&[
        "run",
        &grid,
        "-o",
        dir.path().join("o3").to_str().unwrap(),
        "-q",
    ]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        text(&out.stderr).contains("nbv.alpha_u"),
        "{}",
        text(&out.stderr)
    );
}
