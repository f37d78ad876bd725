//! `nbv sweep submit` on a live Slurm cluster (`examples/slurm/local-cluster.sh start`; CI
//! starts one): a small grid through the array and the merge equals a local `nbv sweep
//! run` of the same grid (times aside), and after the array is cancelled mid-run a
//! resubmission makes it whole, with the same CSV again. Where no Slurm answers the test
//! says so and passes, unless `NBV_REQUIRE_SLURM=1` (CI) makes that a failure.

mod common;

use common::{nbv, text};
use std::path::Path;
use std::process::Command;

/// Whether a Slurm controller answers with a usable node.
fn slurm_up() -> bool {
    Command::new("sinfo")
        .args(["-h", "-o", "%T"])
        .output()
        .is_ok_and(|o| {
            o.status.success()
                && String::from_utf8_lossy(&o.stdout)
                    .lines()
                    .any(|l| ["idle", "mixed", "allocated"].contains(&l.trim()))
        })
}

/// results.csv without its time columns (`time_s`, `nbv_time_per_view`).
fn rows(dir: &Path) -> Vec<String> {
    let text = std::fs::read_to_string(dir.join("results.csv")).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let times: Vec<usize> = header
        .iter()
        .enumerate()
        .filter(|(_, h)| ["time_s", "nbv_time_per_view"].contains(h))
        .map(|(i, _)| i)
        .collect();
    assert_eq!(times.len(), 2);
    let keep = |l: &str| {
        l.split(',')
            .enumerate()
            .filter(|(i, _)| !times.contains(i))
            .map(|(_, v)| v)
            .collect::<Vec<_>>()
            .join(",")
    };
    std::iter::once(keep(&header.join(",")))
        .chain(lines.map(keep))
        .collect()
}

const GRID: &str =
    "generated = { seeds = [1], objects = 1 }\nseeds = [1, 2, 3, 4]\nmodes = [\"mid-only\"]\n";

#[test]
fn a_submitted_sweep_equals_a_local_one_and_is_made_whole_after_a_cancel() {
    if !slurm_up() {
        let why = "no Slurm controller answers (start one: examples/slurm/local-cluster.sh start)";
        assert!(
            std::env::var("NBV_REQUIRE_SLURM").is_err(),
            "NBV_REQUIRE_SLURM is set but {why}"
        );
        eprintln!("skipped: {why}");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let grid = dir.path().join("grid.toml");
    std::fs::write(&grid, GRID).unwrap();
    let grid = grid.to_str().unwrap();

    let local = dir.path().join("local");
    let run = nbv(&["sweep", "run", grid, "-o", local.to_str().unwrap(), "-q"]);
    assert!(run.status.success(), "{}", text(&run.stderr));

    // Submitted and waited for: the same rows.
    let slurm = dir.path().join("slurm");
    let submit = |extra: &[&str]| {
        let mut args = vec![
            "sweep",
            "submit",
            grid,
            "-o",
            slurm.to_str().unwrap(),
            "--shards",
            "2",
        ];
        args.extend_from_slice(extra);
        nbv(&args)
    };
    let run = submit(&["--wait", "--require", "collisions==0"]);
    assert!(
        run.status.success(),
        "{}\n{}",
        text(&run.stdout),
        text(&run.stderr)
    );
    assert_eq!(rows(&slurm), rows(&local));
    assert!(slurm.join("slurm/array.sbatch").is_file());

    // A fresh submission cancelled while its tasks run, then resubmitted: whole again.
    std::fs::remove_dir_all(&slurm).unwrap();
    let run = submit(&[]);
    assert!(run.status.success(), "{}", text(&run.stderr));
    let jobs: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(slurm.join("slurm/jobs.json")).unwrap())
            .unwrap();
    let array = jobs["array"].as_str().unwrap().to_string();
    // Wait until a task runs, then cancel the whole array.
    for _ in 0..120 {
        let q = Command::new("squeue")
            .args(["-h", "-j", &array, "-o", "%T"])
            .output()
            .unwrap();
        if String::from_utf8_lossy(&q.stdout).contains("RUNNING") {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(250));
    }
    let cancel = Command::new("scancel").arg(&array).output().unwrap();
    assert!(cancel.status.success(), "{}", text(&cancel.stderr));
    let run = submit(&["--wait"]);
    assert!(
        run.status.success(),
        "{}\n{}",
        text(&run.stdout),
        text(&run.stderr)
    );
    assert_eq!(rows(&slurm), rows(&local));
}

#[test]
fn dry_run_writes_readable_scripts_only() {
    let dir = tempfile::tempdir().unwrap();
    let grid = dir.path().join("grid.toml");
    std::fs::write(&grid, GRID).unwrap();
    let out = dir.path().join("out");
    let run = nbv(&[
        "sweep",
        "submit",
        grid.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--shards",
        "3",
        "--jobs",
        "2",
        "--sbatch-arg=--time=1:00:00",
        "--require",
        "f_score>=0.8",
        "--dry-run",
    ]);
    assert!(run.status.success(), "{}", text(&run.stderr));
    let array = std::fs::read_to_string(out.join("slurm/array.sbatch")).unwrap();
    assert!(array.starts_with("#!/bin/bash\n"));
    for line in [
        "#SBATCH --array=0-2",
        "#SBATCH --cpus-per-task=2",
        "#SBATCH --time=1:00:00",
    ] {
        assert!(array.contains(line), "{array}");
    }
    let merge = std::fs::read_to_string(out.join("slurm/merge.sbatch")).unwrap();
    assert!(
        merge.contains("sweep merge") && merge.contains("'f_score>=0.8'"),
        "{merge}"
    );
    assert!(!out.join("slurm/jobs.json").exists(), "nothing submitted");
    assert!(
        text(&run.stdout).contains("sbatch"),
        "{}",
        text(&run.stdout)
    );
}
