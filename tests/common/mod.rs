//! A synthetic mid-range sweep shared by the CLI tests: a table top at z = 0.25 m and two
//! boxes on it, scanned by a line scanner moving along y 1 m above the table, every return
//! with its sensor origin (an analytic ray cast, no randomness); and the helpers of the CLI
//! tests (running `nbv`, reading its output and reports).

#![allow(dead_code)]

use nalgebra::{Point3, Vector3};
use nbv_core::cloud::PointCloud;

/// Height of the table top.
pub const TABLE_TOP: f64 = 0.25;
/// The table top's extent in x and y.
pub const TABLE_XY: ([f64; 2], [f64; 2]) = ([0.35, 1.35], [-0.70, 0.70]);
/// The boxes standing on the table, (min, max).
pub const BOXES: [([f64; 3], [f64; 3]); 2] = [
    ([0.70, -0.30, 0.25], [0.85, -0.15, 0.40]),
    ([0.85, 0.10, 0.25], [0.97, 0.25, 0.45]),
];

/// Entry distance of the ray `o + t·d` into the box, if it hits it.
fn hit_box(o: &Point3<f64>, d: &Vector3<f64>, lo: [f64; 3], hi: [f64; 3]) -> Option<f64> {
    let (mut t0, mut t1) = (0.0f64, f64::INFINITY);
    for a in 0..3 {
        if d[a] == 0.0 {
            if o[a] < lo[a] || o[a] > hi[a] {
                return None;
            }
            continue;
        }
        let (ta, tb) = ((lo[a] - o[a]) / d[a], (hi[a] - o[a]) / d[a]);
        t0 = t0.max(ta.min(tb));
        t1 = t1.min(ta.max(tb));
    }
    (t0 <= t1).then_some(t0)
}

/// Nearest return of a ray: the boxes or the table top.
fn cast(o: &Point3<f64>, d: &Vector3<f64>) -> Option<f64> {
    let mut best: Option<f64> = None;
    if d.z < 0.0 {
        let t = (TABLE_TOP - o.z) / d.z;
        let p = o + d * t;
        if (TABLE_XY.0[0]..=TABLE_XY.0[1]).contains(&p.x)
            && (TABLE_XY.1[0]..=TABLE_XY.1[1]).contains(&p.y)
        {
            best = Some(t);
        }
    }
    for (lo, hi) in BOXES {
        if let Some(t) = hit_box(o, d, lo, hi)
            && best.is_none_or(|b| t < b)
        {
            best = Some(t);
        }
    }
    best
}

/// The sweep: 120 lines × 160 rays fanned 12°–60° from the vertical towards +x, the
/// scanner at x = 0.05, z = 1.25 moving from y = −0.6 to 0.6. With `origins`, each point
/// carries its line's sensor position.
pub fn synthetic_cloud(origins: bool) -> PointCloud {
    let (lines, rays) = (120, 160);
    let mut pts = Vec::new();
    let mut orgs = Vec::new();
    for l in 0..lines {
        let o = Point3::new(0.05, -0.6 + 1.2 * l as f64 / (lines - 1) as f64, 1.25);
        for r in 0..rays {
            let a = (12.0 + 48.0 * r as f64 / (rays - 1) as f64).to_radians();
            let d = Vector3::new(a.sin(), 0.0, -a.cos());
            if let Some(t) = cast(&o, &d) {
                pts.push(o + d * t);
                orgs.push(o);
            }
        }
    }
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
