//! `nbv sweep run` killed (SIGKILL) while an episode is in progress, then run again: the
//! resumed sweep's CSV equals an uninterrupted run's (apart from the time column), its
//! directory holds exactly the files of the uninterrupted run's (no temporary file of an
//! interrupted atomic write, no partial output of the killed episode), and the rerun runs
//! only the episodes without a row.
//!
//! Nothing here waits on time for correctness: the kill is triggered by an observable state
//! (the directory of the second episode appears, i.e. the first has finished and the second
//! is writing its outputs) and then checked (the process died of the signal with rows
//! missing); a kill that lands too late is retried. The deadline is only a safety net.

mod common;

use common::text;
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// Three short hybrid episodes (at most two views) on a generated one-object scene.
const GRID: &str = r#"generated = { seeds = [3], objects = 1 }
seeds = [1, 2, 3]
[params]
"nbv.max_views_per_object" = [2]
"#;
const EPISODES: usize = 3;

/// Safety net for a wedged child; a sweep of this grid takes seconds.
const DEADLINE: Duration = Duration::from_secs(600);

fn sweep_command(grid: &Path, out: &Path) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_nbv"));
    c.args(["sweep", "run"])
        .arg(grid)
        .arg("-o")
        .arg(out)
        .args(["--jobs", "1", "-q"]);
    c
}

/// The CSV's lines without the last two columns, which must be the times.
fn csv_without_times(dir: &Path) -> Vec<String> {
    let csv = std::fs::read_to_string(dir.join("results.csv")).unwrap();
    // The last two columns are times (the NBV scoring time per view, the episode's).
    let lines: Vec<String> = csv
        .lines()
        .map(|l| l.rsplitn(3, ',').nth(2).unwrap().to_string())
        .collect();
    assert!(
        csv.lines()
            .next()
            .unwrap()
            .ends_with(",nbv_time_per_view,time_s"),
        "{csv}"
    );
    lines
}

/// Every file under `dir`, relative to it.
fn files(dir: &Path) -> BTreeSet<PathBuf> {
    let mut out = BTreeSet::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else {
                out.insert(p.strip_prefix(dir).unwrap().to_path_buf());
            }
        }
    }
    out
}

/// A temporary file of an atomic write (`.NAME.<random>.tmp`, `nbv_core::atomic_file`).
fn is_temporary(p: &Path) -> bool {
    let name = p.file_name().unwrap().to_string_lossy();
    name.starts_with('.') && name.ends_with(".tmp")
}

fn row_files(out: &Path) -> usize {
    std::fs::read_dir(out.join("episodes")).map_or(0, |d| {
        d.filter(|e| {
            e.as_ref()
                .is_ok_and(|e| e.file_name().to_string_lossy().ends_with(".row.json"))
        })
        .count()
    })
}

/// Whether episode 1's output directory exists (episode 0 has finished; 1 is writing).
fn second_episode_writing(out: &Path) -> bool {
    std::fs::read_dir(out.join("episodes")).is_ok_and(|d| {
        d.flatten()
            .any(|e| e.file_name().to_string_lossy().starts_with("0001-") && e.path().is_dir())
    })
}

/// Polls `child` until `ready(out)` holds, then SIGKILLs it. Whether the kill interrupted
/// the sweep: the child died of it (it had not exited) with rows still missing.
fn kill_when(mut child: Child, out: &Path, ready: impl Fn(&Path) -> bool) -> bool {
    let start = Instant::now();
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            // Finished before the state was seen: not an interruption.
            assert!(status.success(), "the sweep failed: {status}");
            return false;
        }
        if ready(out) {
            break;
        }
        assert!(
            start.elapsed() < DEADLINE,
            "safety deadline: the sweep never reached the state to kill it in"
        );
        std::thread::sleep(Duration::from_millis(2));
    }
    child.kill().unwrap(); // SIGKILL
    let status = child.wait().unwrap();
    !status.success() && status.code().is_none() && row_files(out) < EPISODES
}

#[test]
fn a_sweep_killed_mid_episode_resumes_to_the_uninterrupted_result() {
    let dir = tempfile::tempdir().unwrap();
    let grid = dir.path().join("grid.toml");
    std::fs::write(&grid, GRID).unwrap();

    let whole = dir.path().join("whole");
    let run = sweep_command(&grid, &whole).output().unwrap();
    assert!(run.status.success(), "{}", text(&run.stderr));
    let expected = csv_without_times(&whole);
    assert_eq!(expected.len(), 1 + EPISODES, "{expected:?}");
    assert!(
        !files(&whole).iter().any(|p| is_temporary(p)),
        "{:?}",
        files(&whole)
    );

    // Kill until a kill lands mid-sweep (practically the first time: two episodes are
    // still to run when the state is seen).
    let mut attempt = 0;
    let resumed = loop {
        attempt += 1;
        assert!(attempt <= 5, "no kill landed before the sweep finished");
        let out = dir.path().join(format!("killed-{attempt}"));
        let child = sweep_command(&grid, &out)
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        if kill_when(child, &out, second_episode_writing) {
            break out;
        }
    };
    let rows_before = row_files(&resumed);
    assert!((1..EPISODES).contains(&rows_before), "{rows_before} rows");
    let left = files(&resumed);
    eprintln!(
        "killed with {rows_before} row(s); temporary files left by the kill: {:?}",
        left.iter().filter(|p| is_temporary(p)).collect::<Vec<_>>()
    );
    // Whatever the kill interrupted, also the temporaries an interruption of the sweep's
    // own atomic writes leaves (the CSV, a row file) and one in the unfinished episode's
    // directory, so the cleaning is checked on every run, not only when the kill happened
    // to land inside a write.
    let unfinished = std::fs::read_dir(resumed.join("episodes"))
        .unwrap()
        .flatten()
        .map(|e| e.path())
        .find(|p| {
            let name = p.file_name().unwrap().to_string_lossy().into_owned();
            p.is_dir() && !resumed.join(format!("episodes/{name}.row.json")).exists()
        });
    let mut planted = vec![
        resumed.join(".results.csv.Ab12Cd.tmp"),
        resumed.join("episodes/.0002-x.row.json.Ef34Gh.tmp"),
    ];
    if let Some(u) = &unfinished {
        planted.push(u.join(".report.json.Ij56Kl.tmp"));
    }
    for p in &planted {
        std::fs::write(p, "half a file").unwrap();
    }

    let run = sweep_command(&grid, &resumed).output().unwrap();
    assert!(run.status.success(), "{}", text(&run.stderr));
    let says = format!(
        "{rows_before} already done, {} to run",
        EPISODES - rows_before
    );
    assert!(text(&run.stderr).contains(&says), "{}", text(&run.stderr));
    assert_eq!(csv_without_times(&resumed), expected);
    // The same files as the uninterrupted run: no temporary, no stale partial output.
    assert_eq!(files(&resumed), files(&whole));
    // And the resumed episodes' outputs are the uninterrupted run's.
    for f in files(&whole) {
        if f.extension().is_some_and(|e| e == "ply" || e == "nbvgrid") {
            assert!(
                std::fs::read(whole.join(&f)).unwrap() == std::fs::read(resumed.join(&f)).unwrap(),
                "{} differs",
                f.display()
            );
        }
    }
}
