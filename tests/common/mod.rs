//! The helpers of the CLI tests: the synthetic mid-range sweep as a cloud (a table top and
//! two boxes, `nbv_fixtures::SyntheticSweep::small`), running `nbv`, reading its output
//! and reports.

#![allow(dead_code)]

use nbv_core::cloud::PointCloud;
use nbv_fixtures::SyntheticSweep;

/// Height of the table top of the synthetic sweep.
pub fn table_top() -> f64 {
    SyntheticSweep::small().table_z
}

/// The boxes standing on the table of the synthetic sweep, (min, max).
pub fn boxes() -> Vec<([f64; 3], [f64; 3])> {
    SyntheticSweep::small().boxes
}

/// The small synthetic sweep as a cloud; with `origins`, each point carries its line's
/// sensor position.
pub fn synthetic_cloud(origins: bool) -> PointCloud {
    let (orgs, pts) = SyntheticSweep::small().scan();
    let mut cloud = PointCloud::from_points(pts);
    if origins {
        cloud.origins = Some(orgs);
    }
    cloud
}

/// Runs the `nbv` binary.
pub fn nbv(args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_nbv"))
        .args(args)
        .output()
        .expect("run nbv")
}

/// Lossy UTF-8 of a byte stream.
pub fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

/// A JSON report without its timings (everything else is deterministic).
pub fn without_times(v: &serde_json::Value) -> serde_json::Value {
    use serde_json::Value;
    match v {
        Value::Object(m) => Value::Object(
            m.iter()
                .filter(|(k, _)| k.as_str() != "times")
                .map(|(k, v)| (k.clone(), without_times(v)))
                .collect(),
        ),
        Value::Array(a) => Value::Array(a.iter().map(without_times).collect()),
        other => other.clone(),
    }
}

/// Runs `nbv explore --scene SCENE -o OUT -q EXTRA...`, asserts success and returns the
/// parsed `OUT/report.json`.
pub fn explore(scene: &str, out: &std::path::Path, extra: &[&str]) -> serde_json::Value {
    let mut args = vec![
        "explore",
        "--scene",
        scene,
        "-o",
        out.to_str().unwrap(),
        "-q",
    ];
    args.extend_from_slice(extra);
    let run = nbv(&args);
    assert!(
        run.status.success(),
        "{}\n{}",
        text(&run.stdout),
        text(&run.stderr)
    );
    serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap()
}
