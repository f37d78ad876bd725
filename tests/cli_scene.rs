//! `nbv scene …` end to end: the binary on good and bad scene files in a temporary
//! directory. Bad files exit non-zero with a message naming the problem.

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

fn meshes() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/meshes")
}

fn real_urdf() -> PathBuf {
    PathBuf::from(nbv_core::kinematics::COMAU_URDF)
}

/// A scene directory with a copy of the robot's URDF and a scene
/// referring to the repository's meshes.
fn scene_dir(objects: &str, extra: &str) -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    std::fs::copy(real_urdf(), dir.path().join("robot.urdf")).unwrap();
    let m = meshes().display().to_string();
    let body = format!(
        r#"name = "cli-test"
{extra}
[workspace]
min = [0.30, -0.70, 0.23]
max = [1.50, 0.70, 0.83]
[robot]
urdf = "robot.urdf"
[table]
min = [0.35, -0.70, 0.0]
max = [1.35, 0.70, 0.25]
{objects}
[[obstacles]]
name = "panel"
box = [0.04, 1.0, 0.4]
pose = {{ xyz = [1.27, 0.0, 0.25] }}
"#
    )
    .replace("MESHES", &m);
    let path = dir.path().join("scene.toml");
    std::fs::write(&path, body).unwrap();
    (dir, path)
}

const GOOD: &str = r#"
[[objects]]
name = "jug"
mesh = "MESHES/jug.stl"
pose = { xyz = [0.70, 0.20, 0.25], rpy_deg = [0, 0, 90] }
[[objects]]
name = "box"
mesh = "MESHES/box.stl"
pose = { xyz = [0.75, -0.20, 0.25] }
"#;

fn fails_with(path: &Path, needles: &[&str]) {
    let out = nbv(&["scene", "validate", &path.display().to_string()]);
    let err = text(&out.stderr);
    assert!(!out.status.success(), "should fail: {}", text(&out.stdout));
    assert!(
        out.stdout.is_empty(),
        "no output on failure: {}",
        text(&out.stdout)
    );
    for n in needles {
        assert!(err.contains(n), "stderr lacks {n:?}:\n{err}");
    }
}

#[test]
fn good_scene_validates_and_describes() {
    let (_dir, path) = scene_dir(GOOD, "");
    let p = path.display().to_string();
    let out = nbv(&["scene", "validate", &p]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let s = text(&out.stdout);
    assert!(s.starts_with("ok: cli-test"), "{s}");
    assert!(
        s.contains("2 objects, 1 obstacles") && s.contains("126000 voxels"),
        "{s}"
    );
    let out = nbv(&["scene", "describe", &p]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let s = text(&out.stdout);
    assert!(s.contains("60 x 70 x 30 = 126000 voxels"), "{s}");
    assert!(
        s.contains("jug") && s.contains("box") && s.contains("panel"),
        "{s}"
    );
    assert!(
        s.contains("0.150  0.100  0.080"),
        "box size in the table:\n{s}"
    );
}

#[test]
fn unknown_key() {
    let (_d, path) = scene_dir(GOOD, "colour = \"red\"");
    fails_with(&path, &["scene.toml", "unknown field `colour`", "line 2"]);
}

#[test]
fn missing_mesh() {
    let (_d, path) = scene_dir(&GOOD.replace("box.stl", "crate.stl"), "");
    fails_with(&path, &["objects[1].mesh", "crate.stl", "does not exist"]);
}

#[test]
fn object_outside_workspace() {
    let (_d, path) = scene_dir(
        &GOOD.replace("[0.75, -0.20, 0.25]", "[0.75, -0.67, 0.25]"),
        "",
    );
    fails_with(&path, &["objects[1].pose.xyz", "outside the workspace"]);
}

#[test]
fn overlapping_objects() {
    let (_d, path) = scene_dir(
        &GOOD.replace("[0.75, -0.20, 0.25]", "[0.72, 0.16, 0.25]"),
        "",
    );
    fails_with(
        &path,
        &["objects[0].pose", "`jug` and `box`", "touch or intersect"],
    );
}

#[test]
fn nan_value() {
    let (_d, path) = scene_dir(
        &GOOD.replace("rpy_deg = [0, 0, 90]", "rpy_deg = [0, 0, nan]"),
        "",
    );
    fails_with(&path, &["objects[0].pose.rpy_deg", "must be finite"]);
}

#[test]
fn syntax_error_and_missing_file() {
    let (_d, path) = scene_dir(GOOD, "seed = [");
    fails_with(&path, &["scene.toml", "TOML parse error"]);
    fails_with(Path::new("/nonexistent/scene.toml"), &["no such file"]);
}

#[test]
fn generate_is_deterministic_valid_and_atomic() {
    let dir = tempfile::tempdir().unwrap();
    let urdf = dir.path().join("robot.urdf");
    std::fs::copy(real_urdf(), &urdf).unwrap();
    let u = urdf.display().to_string();
    let gen_to = |name: &str, seed: &str| {
        let out_path = dir.path().join(name);
        let out = nbv(&[
            "scene",
            "generate",
            "--seed",
            seed,
            "--objects",
            "4",
            "-o",
            &out_path.display().to_string(),
            "--urdf",
            &u,
        ]);
        assert!(out.status.success(), "{}", text(&out.stderr));
        std::fs::read(out_path).unwrap()
    };
    let a = gen_to("a.toml", "11");
    let b = gen_to("b.toml", "11");
    let c = gen_to("c.toml", "12");
    assert_eq!(a, b);
    assert_ne!(a, c);
    let out = nbv(&[
        "scene",
        "validate",
        &dir.path().join("a.toml").display().to_string(),
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(text(&out.stdout).contains("4 objects"));
    // An unwritable destination: non-zero exit, nothing left behind.
    let bad = dir.path().join("missing-dir/x.toml");
    let out = nbv(&[
        "scene",
        "generate",
        "--seed",
        "1",
        "-o",
        &bad.display().to_string(),
        "--urdf",
        &u,
    ]);
    assert!(!out.status.success());
    assert!(
        text(&out.stderr).contains("writing"),
        "{}",
        text(&out.stderr)
    );
    assert!(!bad.exists());
    // A missing URDF: refused before anything is written.
    let none = dir.path().join("none.toml");
    let out = nbv(&[
        "scene",
        "generate",
        "--seed",
        "1",
        "-o",
        &none.display().to_string(),
        "--urdf",
        "/nonexistent/robot.urdf",
    ]);
    assert!(!out.status.success());
    assert!(
        text(&out.stderr).contains("robot.urdf"),
        "{}",
        text(&out.stderr)
    );
    assert!(!none.exists());
    let leftovers: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().contains(".tmp-"))
        .collect();
    assert!(leftovers.is_empty());
}

#[test]
fn meshes_command_reproduces_the_stored_meshes() {
    let dir = tempfile::tempdir().unwrap();
    let out = nbv(&["scene", "meshes", "-o", &dir.path().display().to_string()]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    for name in ["jug", "bottle-a", "bottle-b", "mallet", "horse", "box"] {
        let file = format!("{name}.stl");
        let fresh = std::fs::read(dir.path().join(&file)).unwrap();
        let stored = std::fs::read(meshes().join(&file)).unwrap();
        assert!(fresh == stored, "{file} differs");
    }
}

#[test]
fn list_names_the_builtin_scenes() {
    let out = nbv(&["scene", "list"]);
    assert!(out.status.success());
    assert_eq!(text(&out.stdout), "paper-env1\npaper-env2\n");
}

#[test]
fn a_closed_stdout_ends_the_program_quietly() {
    use std::process::Stdio;
    let mut child = Command::new(env!("CARGO_BIN_EXE_nbv"))
        .args(["scene", "describe", "paper-env2"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run nbv");
    // The reader goes away before the first line (as `| head -0` would).
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    let stderr = text(&out.stderr);
    assert!(!stderr.contains("panicked"), "{stderr}");
    // 141 once it writes to the closed pipe; 0 only if it wrote everything first.
    assert!(
        matches!(out.status.code(), Some(141) | Some(0)),
        "{:?}",
        out.status
    );
}
