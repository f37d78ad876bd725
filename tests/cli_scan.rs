//! `nbv scan …` end to end: the real phase-1 sweep of a paper scene and a Dinast frame,
//! read back from the files; same seed, same bytes; bad input exits non-zero with a
//! message naming the problem and leaves no output file.

use nbv_core::cloud::io::{DEFAULT_DEPTH_SCALE, read_cloud, read_depth_png};
use nbv_core::rig::TruthLabel;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn nbv(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_nbv"))
        .args(args)
        .output()
        .expect("run nbv")
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

fn path_str(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn ok(out: &Output) {
    assert!(
        out.status.success(),
        "stdout: {}\nstderr: {}",
        text(&out.stdout),
        text(&out.stderr)
    );
}

/// Fails with a message containing every needle, and no file in `dir`.
fn fails(out: &Output, needles: &[&str], dir: &Path) {
    assert!(!out.status.success(), "{}", text(&out.stdout));
    let err = text(&out.stderr);
    for n in needles {
        assert!(err.contains(n), "`{n}` not in: {err}");
    }
    let left: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_none_or(|e| e != "toml"))
        .collect();
    assert!(left.is_empty(), "files left behind: {left:?}");
}

#[test]
fn mid_range_sweep_of_a_paper_scene() {
    let dir = tempfile::tempdir().unwrap();
    let ply = dir.path().join("cloud.ply");
    let out = nbv(&["scan", "mid", "--scene", "paper-env1", "-o", path_str(&ply)]);
    ok(&out);
    assert!(
        text(&out.stdout).contains("237 lines"),
        "{}",
        text(&out.stdout)
    );
    let cloud = read_cloud(&ply).unwrap();
    assert!(
        (40_000..=70_000).contains(&cloud.len()),
        "{} points",
        cloud.len()
    );
    let origins = cloud.origins.as_ref().unwrap();
    // Origins: the LMS400 window, about 1.2 m up, and points 0.7–3.0 m from it.
    for (p, o) in cloud.points.iter().zip(origins) {
        assert!((1.1..1.4).contains(&o.z), "{o}");
        let r = (p - o).norm();
        assert!((0.69..3.01).contains(&r), "{r}");
    }
    let labels = cloud.labels.as_ref().unwrap();
    assert!(labels.contains(&TruthLabel::Object(0).code()));
    assert_eq!(cloud.truth.as_ref().unwrap().len(), cloud.len());

    // Same seed: byte-identical, also as PCD; another seed: other noise.
    let again = dir.path().join("again.ply");
    ok(&nbv(&[
        "scan",
        "mid",
        "--scene",
        "paper-env1",
        "-o",
        path_str(&again),
    ]));
    assert_eq!(std::fs::read(&ply).unwrap(), std::fs::read(&again).unwrap());
    let pcd = dir.path().join("cloud.pcd");
    ok(&nbv(&[
        "scan",
        "mid",
        "--scene",
        "paper-env1",
        "--seed",
        "99",
        "-o",
        path_str(&pcd),
    ]));
    let other = read_cloud(&pcd).unwrap();
    assert_ne!(other.points, cloud.points);
}

#[test]
fn short_range_frame_with_depth_image() {
    let dir = tempfile::tempdir().unwrap();
    let ply = dir.path().join("frame.ply");
    let png = dir.path().join("depth.png");
    // 0.3 m above the jug's top (about 0.5 m above the table), looking straight down.
    let out = nbv(&[
        "scan",
        "short",
        "--scene",
        "paper-env1",
        "--view",
        "0.68 0.24 0.75 180 0 0",
        "-o",
        path_str(&ply),
        "--depth",
        path_str(&png),
        "--ascii",
    ]);
    ok(&out);
    let cloud = read_cloud(&ply).unwrap();
    let depth = read_depth_png(&png, DEFAULT_DEPTH_SCALE).unwrap();
    assert_eq!((depth.width, depth.height), (320, 240));
    let valid = depth.depth_m.iter().filter(|d| d.is_finite()).count();
    assert_eq!(valid, cloud.len());
    assert!(valid > 30_000, "{valid}");
    let origins = cloud.origins.as_ref().unwrap();
    for (p, o) in cloud.points.iter().zip(origins) {
        assert!((o.z - 0.75).abs() < 0.02);
        let r = (p - o).norm();
        assert!((0.1..=0.8).contains(&r), "{r}");
    }
    let labels = cloud.labels.as_ref().unwrap();
    assert!(labels.contains(&TruthLabel::Object(0).code()));
    assert!(labels.contains(&TruthLabel::Table.code()));
    // Depth is z along the optical axis, here close to the height drop.
    let max = depth.depth_m.iter().copied().filter(|d| d.is_finite());
    assert!(max.fold(0.0, f64::max) < 0.8);
}

#[test]
fn bad_input_is_reported_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let ply = d.join("out.ply");
    let png = d.join("depth.png");
    let o = path_str(&ply);
    let dp = path_str(&png);

    let out = nbv(&["scan", "mid", "--scene", "no-such-scene", "-o", o]);
    fails(&out, &["no-such-scene", "no such file"], d);

    let xyz = d.join("out.xyz");
    let out = nbv(&["scan", "mid", "--scene", "paper-env1", "-o", path_str(&xyz)]);
    fails(&out, &["out.xyz", "xyz"], d);

    let nowhere = d.join("missing/out.ply");
    let out = nbv(&[
        "scan",
        "mid",
        "--scene",
        "paper-env1",
        "-o",
        path_str(&nowhere),
    ]);
    fails(&out, &["missing", "does not exist"], d);

    let short = |view: &str| {
        nbv(&[
            "scan",
            "short",
            "--scene",
            "paper-env1",
            "--view",
            view,
            "-o",
            o,
            "--depth",
            dp,
        ])
    };
    fails(
        &short("1 2 3"),
        &["--view", "expected 6 numbers", "got 3"],
        d,
    );
    fails(&short("1 2 3 nan 0 0"), &["--view", "`nan`"], d);
    fails(
        &short("3.5 0 1 180 0 0"),
        &["--view", "cannot put the camera"],
        d,
    );
    // Inside the table.
    fails(
        &short("0.9 -0.5 0.15 180 0 0"),
        &["--view", "cannot stand there"],
        d,
    );
    let out = nbv(&[
        "scan",
        "short",
        "--scene",
        "paper-env1",
        "--view",
        "0.7 0 0.7 180 0 0",
        "-o",
        o,
        "--depth",
        path_str(&d.join("depth.tiff")),
    ]);
    fails(&out, &["--depth", "depth.tiff", ".png"], d);

    // Scene files: a bad key is named; a sweep that folds the wrist is a collision.
    let assets = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets");
    let base = nbv_scenes::builtin::text("paper-env1")
        .unwrap()
        .replace("../assets", path_str(&assets));
    let bad_key = d.join("bad-key.toml");
    std::fs::write(&bad_key, base.replace("fov_deg = 70.0", "fov_deg = -70.0")).unwrap();
    let out = nbv(&["scan", "mid", "--scene", path_str(&bad_key), "-o", o]);
    fails(&out, &["bad-key.toml", "sensors.mid_range.fov_deg"], d);
    let folded = d.join("folded.toml");
    std::fs::write(&folded, base.replace("112.0", "125.0")).unwrap();
    let out = nbv(&["scan", "mid", "--scene", path_str(&folded), "-o", o]);
    fails(&out, &["folded.toml", "sweep", "collision"], d);
}
