//! `nbv register …` end to end: views of a known bumpy surface written to a temporary
//! directory (PLY binary, PLY ASCII with extra properties, PCD binary), registered by both
//! methods; the poses written must recover the known transforms. Degenerate input exits
//! non-zero with a message naming the file and writes nothing; views that do not overlap
//! give the documented non-convergence status.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use nalgebra::{Isometry3, Matrix4, Point3, Vector3};

fn nbv(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_nbv"))
        .args(args)
        .output()
        .expect("run nbv")
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

/// Height of the test surface (metres) at (x, y).
fn surface(x: f64, y: f64) -> f64 {
    0.015 * (70.0 * x).sin() * (55.0 * y).cos() + 0.008 * (90.0 * x * y + 1.0).sin()
}

/// A fixed pseudo-random number in [−0.5, 0.5) for grid cell (i, j).
fn jitter(i: usize, j: usize, salt: f64) -> f64 {
    let v = ((i as f64 * 12.9898 + j as f64 * 78.233 + salt).sin() * 43758.5453).fract();
    v.abs() - 0.5
}

/// Points of the surface over columns `cols` of a 4 mm grid (40 rows), each cell sampled
/// at a fixed irregular position (shared by all views, so overlapping views hold the same
/// samples and no grid aliasing arises), in the frame of a sensor at `pose` (view → world).
fn view(cols: std::ops::Range<usize>, pose: &Isometry3<f64>) -> Vec<Point3<f64>> {
    let inv = pose.inverse();
    cols.flat_map(|i| (0..40).map(move |j| (i, j)))
        .map(|(i, j)| {
            let x = (i as f64 + 0.8 * jitter(i, j, 0.0)) * 0.004;
            let y = (j as f64 + 0.8 * jitter(i, j, 1.7)) * 0.004;
            inv * Point3::new(x, y, surface(x, y))
        })
        .collect()
}

fn write_ply_binary(path: &Path, points: &[Point3<f64>]) {
    let mut bytes = format!(
        "ply\nformat binary_little_endian 1.0\nelement vertex {}\nproperty double x\n\
         property double y\nproperty double z\nend_header\n",
        points.len()
    )
    .into_bytes();
    for p in points {
        for c in [p.x, p.y, p.z] {
            bytes.extend_from_slice(&c.to_le_bytes());
        }
    }
    std::fs::write(path, bytes).unwrap();
}

fn write_ply_ascii_extra(path: &Path, points: &[Point3<f64>]) {
    let mut s = format!(
        "ply\nformat ascii 1.0\ncomment extra properties\nelement vertex {}\n\
         property float intensity\nproperty double x\nproperty double y\nproperty double z\n\
         property uchar red\nend_header\n",
        points.len()
    );
    for (k, p) in points.iter().enumerate() {
        s.push_str(&format!(
            "{} {:.17} {:.17} {:.17} {}\n",
            k % 100,
            p.x,
            p.y,
            p.z,
            k % 256
        ));
    }
    std::fs::write(path, s).unwrap();
}

fn write_pcd_binary(path: &Path, points: &[Point3<f64>]) {
    let mut bytes = format!(
        "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z rgb\nSIZE 8 8 8 4\nTYPE F F F F\n\
         COUNT 1 1 1 1\nWIDTH {n}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {n}\nDATA binary\n",
        n = points.len()
    )
    .into_bytes();
    for p in points {
        for c in [p.x, p.y, p.z] {
            bytes.extend_from_slice(&c.to_le_bytes());
        }
        bytes.extend_from_slice(&0.5f32.to_le_bytes());
    }
    std::fs::write(path, bytes).unwrap();
}

fn matrix_json(pose: &Isometry3<f64>) -> serde_json::Value {
    let m = pose.to_homogeneous();
    serde_json::json!(
        (0..4)
            .map(|r| (0..4).map(|c| m[(r, c)]).collect::<Vec<f64>>())
            .collect::<Vec<_>>()
    )
}

fn read_poses(path: &Path) -> serde_json::Map<String, serde_json::Value> {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn pose_of(map: &serde_json::Map<String, serde_json::Value>, name: &str) -> Isometry3<f64> {
    let rows: Vec<Vec<f64>> = serde_json::from_value(map[name].clone()).unwrap();
    let m = Matrix4::from_fn(|r, c| rows[r][c]);
    nalgebra::try_convert(m).unwrap()
}

/// Three overlapping views with known sensor poses, in three file formats, and initial
/// poses off by 2.45 mm and about 1° (sensor pose; 0.4 m away from the surface). On this
/// coarse (4 mm), nearly 2.5-D sampling p-ICP-GPA settles 4–8 mm from the truth from any
/// such start (it is tested for recovery in core/tests/registration.rs instead).
struct Scene {
    dir: tempfile::TempDir,
    files: Vec<PathBuf>,
    truth: Vec<Isometry3<f64>>,
    init: PathBuf,
}

/// The error of each view's initial pose (the first view is the reference).
fn start_errors() -> [Isometry3<f64>; 3] {
    [
        Isometry3::identity(),
        Isometry3::new(
            Vector3::new(0.002, -0.001, 0.001),
            Vector3::new(0.01, -0.012, 0.008),
        ),
        Isometry3::new(
            Vector3::new(-0.001, 0.002, -0.001),
            Vector3::new(-0.008, 0.01, 0.012),
        ),
    ]
}

fn scene() -> Scene {
    let dir = tempfile::tempdir().unwrap();
    let truth = vec![
        Isometry3::new(Vector3::new(0.05, 0.08, 0.4), Vector3::new(3.1, 0.0, 0.0)),
        Isometry3::new(Vector3::new(0.09, 0.07, 0.38), Vector3::new(3.0, 0.2, 0.1)),
        Isometry3::new(
            Vector3::new(0.14, 0.09, 0.41),
            Vector3::new(3.05, -0.15, -0.1),
        ),
    ];
    let errors = start_errors();
    let names = ["a.ply", "b.ply", "c.pcd"];
    let ranges = [0..25, 8..33, 16..41];
    let mut files = Vec::new();
    let mut init = serde_json::Map::new();
    for (k, name) in names.iter().enumerate() {
        // The views share their samples where they overlap (no jitter): the true
        // correspondences exist, so every method must recover the transforms closely.
        let pts = view(ranges[k].clone(), &truth[k]);
        let path = dir.path().join(name);
        match k {
            0 => write_ply_binary(&path, &pts),
            1 => write_ply_ascii_extra(&path, &pts),
            _ => write_pcd_binary(&path, &pts),
        }
        init.insert(name.to_string(), matrix_json(&(truth[k] * errors[k])));
        files.push(path);
    }
    let init_path = dir.path().join("init.json");
    std::fs::write(&init_path, serde_json::Value::Object(init).to_string()).unwrap();
    Scene {
        dir,
        files,
        truth,
        init: init_path,
    }
}

fn args<'a>(scene: &'a Scene, extra: &[&'a str]) -> Vec<String> {
    let mut a = vec!["register".to_string()];
    a.extend(scene.files.iter().map(|f| f.display().to_string()));
    a.extend(extra.iter().map(|s| s.to_string()));
    a
}

fn run(a: &[String]) -> Output {
    nbv(&a.iter().map(String::as_str).collect::<Vec<_>>())
}

#[test]
fn recovers_known_transforms_with_both_methods() {
    let s = scene();
    let mut bad = Vec::new();
    for method in ["gpa", "map", "icp", "icp-plane"] {
        let model = s.dir.path().join(format!("model-{method}.ply"));
        let poses = s.dir.path().join(format!("poses-{method}.json"));
        let out = run(&args(
            &s,
            &[
                "--init",
                s.init.to_str().unwrap(),
                "--method",
                method,
                "--max-distance",
                "0.006",
                "-o",
                model.to_str().unwrap(),
                "--poses",
                poses.to_str().unwrap(),
            ],
        ));
        assert!(out.status.success(), "{method}: {}", text(&out.stderr));
        assert!(
            text(&out.stdout).contains("converged"),
            "{}",
            text(&out.stdout)
        );
        let map = read_poses(&poses);
        assert_eq!(map.len(), 3);
        for (k, name) in ["a.ply", "b.ply", "c.pcd"].iter().enumerate() {
            let d = s.truth[k].inverse() * pose_of(&map, name);
            let (r, t) = (d.rotation.angle().to_degrees(), d.translation.vector.norm());
            println!("{method} {name}: {r:.4}° {:.3} mm", t * 1e3);
            bad.push((method, name, r, t));
        }
        // The reference view keeps its initial pose (up to the JSON round trip).
        let a = (pose_of(&map, "a.ply").to_homogeneous() - s.truth[0].to_homogeneous()).amax();
        assert!(a < 1e-12, "{a}");
        // The model holds every point with its view index.
        let cloud = nbv_core::cloud::read_cloud(&model).unwrap();
        assert_eq!(cloud.len(), 3 * 25 * 40);
        let views = cloud.views.unwrap();
        assert_eq!((views[0], views[1000], views[2999]), (0, 1, 2));
    }
    // Every method but the paper's p-ICP-GPA ends within half of each view's starting
    // error (2.45 mm, 1°); the reference view keeps its pose (checked above). p-ICP-GPA
    // converges (checked above) but its point-to-point steps slide on these smooth
    // patches: measured 0.25° / 4.3 mm (b) and 1.06° / 7.5 mm (c), which is why `map` is
    // the command's default.
    for (method, name, r, t) in bad.into_iter().filter(|b| b.1 != &"a.ply" && b.0 != "gpa") {
        let k = ["a.ply", "b.ply", "c.pcd"]
            .iter()
            .position(|n| n == name)
            .unwrap();
        let e = start_errors()[k];
        let (r0, t0) = (e.rotation.angle().to_degrees(), e.translation.vector.norm());
        assert!(
            r <= 0.5 * r0 && t <= 0.5 * t0,
            "{method} {name}: {r}° {t} m from {r0}° {t0} m"
        );
    }
}

#[test]
fn results_do_not_depend_on_the_thread_count() {
    let s = scene();
    let mut outputs = Vec::new();
    for threads in ["1", "2"] {
        let poses = s.dir.path().join(format!("poses-{threads}.json"));
        let model = s.dir.path().join(format!("model-{threads}.pcd"));
        let out = run(&args(
            &s,
            &[
                "--init",
                s.init.to_str().unwrap(),
                "--threads",
                threads,
                "-o",
                model.to_str().unwrap(),
                "--poses",
                poses.to_str().unwrap(),
            ],
        ));
        assert!(out.status.success(), "{}", text(&out.stderr));
        outputs.push((
            std::fs::read(&poses).unwrap(),
            std::fs::read(&model).unwrap(),
        ));
    }
    assert_eq!(outputs[0], outputs[1]);
}

/// Runs a failing command; checks the status, the message and that nothing was written.
fn fails(s: &Scene, a: Vec<String>, status: i32, message: &str) {
    let out = run(&a);
    let err = text(&out.stderr);
    assert_eq!(out.status.code(), Some(status), "{a:?}: {err}");
    assert!(
        err.contains(message),
        "{a:?}: expected {message:?} in {err}"
    );
    let leftovers: Vec<_> = std::fs::read_dir(s.dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with("out") || n.starts_with('.'))
        .collect();
    assert!(leftovers.is_empty(), "{a:?} left {leftovers:?}");
}

#[test]
fn degenerate_input_is_an_error_naming_the_file() {
    let s = scene();
    let d = s.dir.path();
    let model = d.join("out.ply").display().to_string();
    let poses = d.join("out.json").display().to_string();
    let outs = [
        "-o".to_string(),
        model.clone(),
        "--poses".into(),
        poses.clone(),
    ];
    let with = |files: &[PathBuf], extra: &[&str]| {
        let mut a = vec!["register".to_string()];
        a.extend(files.iter().map(|f| f.display().to_string()));
        a.extend(extra.iter().map(|s| s.to_string()));
        a.extend(outs.iter().cloned());
        a
    };
    // One view.
    fails(&s, with(&s.files[..1], &[]), 1, "at least 2 views");
    // An empty view.
    let empty = d.join("empty.ply");
    write_ply_binary(&empty, &[]);
    fails(&s, with(&[s.files[0].clone(), empty], &[]), 1, "empty.ply");
    // A view whose every point is NaN.
    let nan = d.join("nan.ply");
    write_ply_ascii_extra(&nan, &[Point3::new(f64::NAN, 0.0, 0.0)]);
    fails(&s, with(&[s.files[0].clone(), nan], &[]), 1, "nan.ply");
    // Unreadable and missing files.
    let junk = d.join("junk.pcd");
    std::fs::write(&junk, "not a point cloud\n").unwrap();
    fails(&s, with(&[s.files[0].clone(), junk], &[]), 1, "junk.pcd");
    let missing = d.join("missing.ply");
    fails(
        &s,
        with(&[s.files[0].clone(), missing], &[]),
        1,
        "missing.ply",
    );
    // Bad initial poses: missing entry, not a rotation, not JSON.
    let init = d.join("bad-init.json");
    std::fs::write(
        &init,
        r#"{"a.ply": [[1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]]}"#,
    )
    .unwrap();
    let init_arg = init.display().to_string();
    fails(
        &s,
        with(&s.files, &["--init", &init_arg]),
        1,
        "no pose for view b.ply",
    );
    std::fs::write(
        &init,
        r#"{"a.ply": [[2,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]],
            "b.ply": [[1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]],
            "c.pcd": [[1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]]}"#,
    )
    .unwrap();
    fails(
        &s,
        with(&s.files, &["--init", &init_arg]),
        1,
        "not a rotation",
    );
    std::fs::write(&init, "[1, 2").unwrap();
    fails(
        &s,
        with(&s.files, &["--init", &init_arg]),
        1,
        "bad-init.json",
    );
    // Reference out of range, bad d_max, an output that is an input, duplicate names.
    fails(&s, with(&s.files, &["--reference", "3"]), 1, "out of range");
    fails(
        &s,
        with(&s.files, &["--max-distance", "0"]),
        1,
        "max_correspondence_distance",
    );
    let sub = d.join("sub");
    std::fs::create_dir(&sub).unwrap();
    std::fs::copy(&s.files[0], sub.join("a.ply")).unwrap();
    fails(
        &s,
        with(&[s.files[0].clone(), sub.join("a.ply")], &[]),
        1,
        "same file name",
    );
    let clobber = vec![
        "register".to_string(),
        s.files[0].display().to_string(),
        s.files[1].display().to_string(),
        "-o".into(),
        s.files[1].display().to_string(),
        "--poses".into(),
        poses.clone(),
    ];
    fails(&s, clobber, 1, "is also an input view");
    // Usage errors are clap's (status 2).
    fails(
        &s,
        vec!["register".into(), s.files[0].display().to_string()],
        2,
        "--output",
    );
}

#[test]
fn views_without_overlap_report_non_convergence() {
    let s = scene();
    let d = s.dir.path();
    // Two views 1 m apart in the world: no correspondence within d_max.
    let far = d.join("far.ply");
    let shifted = Isometry3::translation(1.0, 0.0, 0.0) * s.truth[1];
    write_ply_binary(&far, &view(8..33, &shifted));
    let model = d.join("far-model.ply");
    let poses = d.join("far-poses.json");
    let out = nbv(&[
        "register",
        s.files[0].to_str().unwrap(),
        far.to_str().unwrap(),
        "--method",
        "gpa",
        "-o",
        model.to_str().unwrap(),
        "--poses",
        poses.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(3), "{}", text(&out.stderr));
    assert!(text(&out.stdout).contains("NOT converged"));
    assert!(text(&out.stdout).contains("NoCorrespondences"));
    assert!(text(&out.stderr).contains("did not converge"));
    // The (unchanged) poses are written: the identity for both views.
    let map = read_poses(&poses);
    assert_eq!(pose_of(&map, "far.ply"), Isometry3::identity());
    assert!(model.exists());
}

#[test]
fn nan_points_are_dropped_and_reported() {
    let s = scene();
    let d = s.dir.path();
    let mut pts = view(8..33, &s.truth[1]);
    pts.push(Point3::new(f64::NAN, 1.0, 2.0));
    let with_nan = d.join("b.ply");
    write_ply_ascii_extra(&with_nan, &pts);
    let model = d.join("nan-model.ply");
    let poses = d.join("nan-poses.json");
    let out = nbv(&[
        "register",
        s.files[0].to_str().unwrap(),
        with_nan.to_str().unwrap(),
        s.files[2].to_str().unwrap(),
        "--init",
        s.init.to_str().unwrap(),
        "-o",
        model.to_str().unwrap(),
        "--poses",
        poses.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(
        text(&out.stderr).contains("b.ply: dropped 1 points"),
        "{}",
        text(&out.stderr)
    );
}

#[test]
fn help_documents_the_pose_format_and_exit_status() {
    let out = nbv(&["register", "--help"]);
    let help = text(&out.stdout);
    assert!(out.status.success());
    for needle in [
        "row-major",
        "view-to-world",
        "EXIT STATUS",
        "did not converge",
        "--reference",
    ] {
        assert!(help.contains(needle), "{needle} missing from --help");
    }
}

/// The scene's views as a ROS 2 bag written by nbv-bag: clouds on `/scans` in frame
/// `sensor` stamped 10 + k s, their starting poses on `/tf` (`odom → sensor`, sampled
/// 0.1 s before and after each stamp and 2 mm apart along x, so tf2's interpolation gives
/// the pose at the stamp) under a static `world → odom` offset; with `covariance`, each
/// cloud's sensor-pose covariance on `/scan_pose` at its stamp.
fn write_bag(s: &Scene, path: &Path, covariance: Option<[f64; 36]>) {
    use nbv_bag::messages::{
        Header, PoseWithCovariance, PoseWithCovarianceStamped, TFMessage, Time, Transform,
        TransformStamped,
    };
    const S: i64 = 1_000_000_000;
    let odom = Isometry3::new(Vector3::new(0.5, -0.25, 0.1), Vector3::new(0.0, 0.0, 0.5));
    let stamped = |parent: &str, child: &str, t: i64, pose: &Isometry3<f64>| TFMessage {
        transforms: vec![TransformStamped {
            header: Header {
                stamp: Time::from_nanos(t),
                frame_id: parent.into(),
            },
            child_frame_id: child.into(),
            transform: Transform::from_isometry(pose),
        }],
    };
    let mut w = nbv_bag::BagWriter::create(path).unwrap();
    w.write("/tf_static", 1, &stamped("world", "odom", 0, &odom))
        .unwrap();
    let init = read_poses(&s.init);
    for (k, file) in s.files.iter().enumerate() {
        let t = (10 + k as i64) * S;
        let start = pose_of(&init, &file.file_name().unwrap().to_string_lossy());
        for (dt, dx) in [(-S / 10, -0.002), (S / 10, 0.002)] {
            let link = Isometry3::translation(dx, 0.0, 0.0) * odom.inverse() * start;
            let msg = stamped("odom", "sensor", t + dt, &link);
            w.write("/tf", u64::try_from(t + dt).unwrap(), &msg)
                .unwrap();
        }
        let points = nbv_core::cloud::read_cloud(file).unwrap().points;
        let header = Header {
            stamp: Time::from_nanos(t),
            frame_id: "sensor".into(),
        };
        if let Some(covariance) = covariance {
            let msg = PoseWithCovarianceStamped {
                header: header.clone(),
                pose: PoseWithCovariance {
                    covariance,
                    ..Default::default()
                },
            };
            w.write("/scan_pose", u64::try_from(t).unwrap(), &msg)
                .unwrap();
        }
        let cloud = nbv_bag::point_cloud::cloud_from_points_f64(header, &points);
        w.write("/scans", u64::try_from(t).unwrap(), &cloud)
            .unwrap();
    }
    w.finish().unwrap();
}

/// `nbv register --bag`: the bag's views register to the poses their files do (the clouds
/// narrowed to 32-bit floats on the wire, the starting poses through tf), in `world`
/// without --fixed-frame; a rosbags-written bag of the same scans (organised clouds with
/// padding and NaN, an optical frame under a moving link) too, when `NBV_BAG_PYTHON`
/// names a Python with rosbags.
#[test]
fn a_bag_registers_as_its_files_do() {
    let s = scene();
    let dir = s.dir.path();
    let register = |input: &[String], tag: &str| {
        let poses = dir.join(format!("poses-{tag}.json"));
        let mut a = vec!["register".to_string()];
        a.extend(input.iter().cloned());
        a.extend(
            [
                "--max-distance",
                "0.006",
                "-o",
                dir.join(format!("model-{tag}.ply")).to_str().unwrap(),
                "--poses",
                poses.to_str().unwrap(),
            ]
            .map(String::from),
        );
        let out = run(&a);
        assert!(out.status.success(), "{tag}: {}", text(&out.stderr));
        read_poses(&poses)
    };
    let mut files: Vec<String> = s.files.iter().map(|f| f.display().to_string()).collect();
    files.extend(["--init".to_string(), s.init.display().to_string()]);
    let from_files = register(&files, "files");
    let bag = dir.join("scans");
    write_bag(&s, &bag, None);
    let mut bags = vec![bag];
    if let Some(python) = nbv_fixtures::python_check::bag_python() {
        let scans: Vec<serde_json::Value> = s
            .files
            .iter()
            .map(|f| {
                let name = f.file_name().unwrap().to_string_lossy().into_owned();
                let points = nbv_core::cloud::read_cloud(f).unwrap().points;
                serde_json::json!({
                    "points": points.iter().map(|p| [p.x, p.y, p.z]).collect::<Vec<_>>(),
                    "pose": matrix_json(&pose_of(&read_poses(&s.init), &name)),
                })
            })
            .collect();
        let json = dir.join("scans.json");
        std::fs::write(&json, serde_json::json!({ "scans": scans }).to_string()).unwrap();
        let written = dir.join("rosbags-scans");
        let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("bag/tests/python/bag_of_scans.py");
        nbv_fixtures::python_check::run_python(&python, &script, [&written, &json]);
        bags.push(written);
    }
    for bag in bags {
        let tag = bag.file_name().unwrap().to_string_lossy().into_owned();
        let from_bag = register(
            &[
                "--bag".into(),
                bag.display().to_string(),
                "--topic".into(),
                "/scans".into(),
            ],
            &tag,
        );
        for (k, file) in s.files.iter().enumerate() {
            let a = pose_of(&from_files, &file.file_name().unwrap().to_string_lossy());
            let b = pose_of(&from_bag, &format!("/scans#{k}"));
            let d = a.inverse() * b;
            let (r, t) = (d.rotation.angle(), d.translation.vector.norm());
            assert!(r < 1e-5 && t < 1e-5, "{tag} view {k}: {r} rad {t} m apart");
        }
    }
}

/// A missing topic, a cloud outside the transforms' time span and an output that is the
/// bag are clear errors, and nothing is written.
#[test]
fn bad_bags_are_clear_errors_and_write_nothing() {
    let s = scene();
    let dir = s.dir.path();
    let bag = dir.join("scans");
    write_bag(&s, &bag, None);
    let model = dir.join("model.ply");
    let poses = dir.join("poses.json");
    let run_bag = |extra: &[&str]| {
        let mut a = vec!["register", "--bag", bag.to_str().unwrap()];
        a.extend_from_slice(extra);
        a.extend([
            "-o",
            model.to_str().unwrap(),
            "--poses",
            poses.to_str().unwrap(),
        ]);
        nbv(&a)
    };
    let out = run_bag(&["--topic", "/nothing"]);
    assert!(!out.status.success());
    let err = text(&out.stderr);
    assert!(
        err.contains("no topic /nothing") && err.contains("/scans"),
        "{err}"
    );
    let out = run_bag(&["--topic", "/tf"]);
    assert!(
        text(&out.stderr).contains("not sensor_msgs/msg/PointCloud2"),
        "{}",
        text(&out.stderr)
    );
    let out = run_bag(&["--topic", "/scans", "--fixed-frame", "map"]);
    let err = text(&out.stderr);
    assert!(
        !out.status.success() && err.contains("message 0") && err.contains("map"),
        "{err}"
    );
    assert!(!model.exists() && !poses.exists());
}

/// `--pose-covariance-topic`: a bag whose every view carries the covariance of 2° and 5 mm
/// registers to the poses `--pose-sigma 2,0.005` gives; the topic of another type, a view
/// with no covariance before it, and the option with `--pose-sigma` or without `--bag` are
/// errors that write nothing.
#[test]
fn a_bags_pose_covariance_is_each_views_prior() {
    let s = scene();
    let dir = s.dir.path();
    let (r, t) = (2f64.to_radians(), 0.005);
    let mut covariance = [0.0; 36];
    for i in 0..3 {
        covariance[7 * i] = t * t;
        covariance[7 * (i + 3)] = r * r;
    }
    let bag = dir.join("scans");
    write_bag(&s, &bag, Some(covariance));
    let model = dir.join("model.ply");
    let register = |extra: &[&str], tag: &str| {
        let poses = dir.join(format!("poses-{tag}.json"));
        let mut a = vec![
            "register",
            "--bag",
            bag.to_str().unwrap(),
            "--topic",
            "/scans",
            "--max-distance",
            "0.006",
            "-o",
            model.to_str().unwrap(),
            "--poses",
            poses.to_str().unwrap(),
        ];
        a.extend_from_slice(extra);
        (nbv(&a), poses)
    };
    let (out, from_topic) = register(&["--pose-covariance-topic", "/scan_pose"], "topic");
    assert!(out.status.success(), "{}", text(&out.stderr));
    let printed = text(&out.stdout);
    assert!(
        printed.contains(
            "pose priors from /scan_pose: rotation σ 2.000–2.000°, translation σ 5.000–5.000 mm"
        ),
        "{printed}"
    );
    let (out, from_sigma) = register(&["--pose-sigma", "2,0.005"], "sigma");
    assert!(out.status.success(), "{}", text(&out.stderr));
    let (a, b) = (read_poses(&from_topic), read_poses(&from_sigma));
    for k in 0..s.files.len() {
        let name = format!("/scans#{k}");
        let d = pose_of(&a, &name).inverse() * pose_of(&b, &name);
        let (dr, dt) = (d.rotation.angle(), d.translation.vector.norm());
        assert!(dr < 1e-9 && dt < 1e-9, "view {k}: {dr} rad {dt} m apart");
    }
    std::fs::remove_file(&model).unwrap();
    for (extra, status, message) in [
        (vec!["--pose-covariance-topic", "/tf"], 1, "topic /tf"),
        (
            vec![
                "--pose-covariance-topic",
                "/scan_pose",
                "--pose-sigma",
                "2,0.005",
            ],
            2,
            "cannot be used with",
        ),
    ] {
        let (out, poses) = register(&extra, "bad");
        let err = text(&out.stderr);
        assert_eq!(out.status.code(), Some(status), "{extra:?}: {err}");
        assert!(err.contains(message), "{extra:?}: {err}");
        assert!(!model.exists() && !poses.exists(), "{extra:?} wrote output");
    }
    // A bag whose covariances start after the first view.
    let late = dir.join("late");
    write_bag(&s, &late, None);
    let out = nbv(&[
        "register",
        "--bag",
        late.to_str().unwrap(),
        "--topic",
        "/scans",
        "--pose-covariance-topic",
        "/scan_pose",
        "-o",
        model.to_str().unwrap(),
        "--poses",
        dir.join("late.json").to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        text(&out.stderr).contains("/scan_pose"),
        "{}",
        text(&out.stderr)
    );
    let out = nbv(&[
        "register",
        s.files[0].to_str().unwrap(),
        s.files[1].to_str().unwrap(),
        "--pose-covariance-topic",
        "/scan_pose",
        "-o",
        model.to_str().unwrap(),
        "--poses",
        dir.join("files.json").to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(2), "{}", text(&out.stderr));
    assert!(!model.exists());
}

#[path = "../core/tests/registration_data/mod.rs"]
mod registration_data;

/// A user's scans: a turntable ring of ten views all round a bumpy object (each in its own
/// sensor frame, no sensor origins in the files, 0.3 mm of range noise), every pose but
/// the reference's 2° and 5 mm off — about 1 cm at the object. `nbv register` with its
/// defaults (MAP from coarse to fine, the noise estimated from the views, each sensor at
/// its file's origin) brings every view within 0.5 mm and 0.3° of the truth. (On a thin
/// object one stage at the views' noise without the sensor origins ends millimetres off:
/// docs/peers.md, "Users' scans".)
/// Registers a user's ring of ten scans (see the test below) with `nbv register` and
/// `extra` options: each view's error against the truth (m, degrees) and what it printed.
/// With `object_frames`, each view's points are given in a frame at the object's centre
/// with the sensor's axes (a turntable's frame: its origin is not the sensor).
fn register_users_ring(object_frames: bool, extra: &[&str]) -> (Vec<(f64, f64)>, String) {
    use nbv_core::cloud::PointCloud;
    use nbv_core::cloud::io::{WriteOptions, write_cloud};
    use registration_data::{Spec, generate};

    let spec = Spec {
        views: 10,
        points_per_view: 3000,
        noise: 0.0003,
        rotation_error_deg: 2.0,
        translation_error: 0.005,
        azimuth_step_deg: 36.0,
        top_view: false,
        ..Spec::default()
    };
    let data = generate(&spec);
    let dir = tempfile::tempdir().unwrap();
    let mut files = Vec::new();
    let mut init = serde_json::Map::new();
    // Each view's frame (view → world) and its points in it.
    let centre: nalgebra::Vector3<f64> = data
        .truth
        .iter()
        .zip(&data.views)
        .flat_map(|(t, v)| v.points.iter().map(move |p| (t * p).coords))
        .sum::<nalgebra::Vector3<f64>>()
        / data.views.iter().map(|v| v.len()).sum::<usize>() as f64;
    let frames: Vec<Isometry3<f64>> = data
        .truth
        .iter()
        .map(|t| {
            if object_frames {
                Isometry3::from_parts(nalgebra::Translation3::from(centre), t.rotation)
            } else {
                *t
            }
        })
        .collect();
    let points: Vec<Vec<nalgebra::Point3<f64>>> = data
        .views
        .iter()
        .zip(&data.truth)
        .zip(&frames)
        .map(|((v, t), f)| v.points.iter().map(|p| f.inverse() * (t * p)).collect())
        .collect();
    for (k, ((view, pose), truth)) in points
        .iter()
        .zip(&data.initial)
        .zip(&data.truth)
        .enumerate()
    {
        let path = dir.path().join(format!("scan_{k}.ply"));
        assert!(data.views[k].origins.is_none());
        write_cloud(
            &path,
            &PointCloud::from_points(view.clone()),
            &WriteOptions::default(),
        )
        .unwrap();
        // The same pose error in the new frame.
        init.insert(
            format!("scan_{k}.ply"),
            matrix_json(&(pose * truth.inverse() * frames[k])),
        );
        files.push(path.display().to_string());
    }
    let init_path = dir.path().join("init.json");
    std::fs::write(&init_path, serde_json::to_string(&init).unwrap()).unwrap();
    let errors = |extra: &[&str]| {
        let poses = dir.path().join("poses.json");
        let model = dir.path().join("model.ply");
        let mut a: Vec<&str> = vec!["register"];
        a.extend(files.iter().map(String::as_str));
        a.extend([
            "--init",
            init_path.to_str().unwrap(),
            "-o",
            model.to_str().unwrap(),
            "--poses",
            poses.to_str().unwrap(),
        ]);
        a.extend(extra);
        let out = nbv(&a);
        assert!(out.status.success(), "{}", text(&out.stderr));
        let got = read_poses(&poses);
        let per_view: Vec<(f64, f64)> = points
            .iter()
            .zip(&frames)
            .enumerate()
            .map(|(k, (view, truth))| {
                let est = pose_of(&got, &format!("scan_{k}.ply"));
                let rms = (view
                    .iter()
                    .map(|p| (est * p - truth * p).norm_squared())
                    .sum::<f64>()
                    / view.len() as f64)
                    .sqrt();
                (
                    rms,
                    (est.rotation * truth.rotation.inverse())
                        .angle()
                        .to_degrees(),
                )
            })
            .collect();
        (per_view, text(&out.stdout))
    };
    errors(extra)
}

#[test]
fn a_users_ring_of_scans_registers_with_the_defaults() {
    let (defaults, printed) = register_users_ring(false, &[]);
    let sigma: f64 = printed
        .split("estimated from the views: ")
        .nth(1)
        .and_then(|t| t.split(' ').next())
        .and_then(|t| t.parse().ok())
        .unwrap_or_else(|| panic!("no estimate in {printed}"));
    assert!((0.2..0.6).contains(&sigma), "estimated σ {sigma} mm");
    for (k, &(rms, deg)) in defaults.iter().enumerate() {
        assert!(
            rms < 0.0005 && deg < 0.3,
            "view {k}: {:.3} mm, {deg:.3}°",
            rms * 1e3
        );
    }
    assert!(!printed.contains("seen along"), "{printed}");
}

/// The same ring in a turntable's frames (the Stanford scans' layout): each frame's origin
/// at the object's centre, behind what the view saw. The default `--sensor-origin auto`
/// sees the views along the directions estimated from their surfaces (6 of 10 here; the
/// rest without a sensor: one frame that is not a sensor's means none is), and every view
/// ends within 0.25 mm and 0.2° of the truth (0.19 mm and 0.13° at worst; kept at their
/// frames' origins, four of them ended 2–15° off). A view without a sensor takes no part
/// in the test of which way a surface faces: from its centroid, behind its rim, it
/// rejected true matches and the worst view ended 0.27 mm and 0.22° off.
#[test]
fn a_ring_in_a_turntables_frames_is_seen_along_the_estimated_directions() {
    let (auto, printed) = register_users_ring(true, &[]);
    assert!(printed.contains("views seen along"), "{printed}");
    for (k, &(rms, deg)) in auto.iter().enumerate() {
        assert!(
            rms < 0.00025 && deg < 0.2,
            "view {k}: {:.3} mm, {deg:.3}°",
            rms * 1e3
        );
    }
    let (_, printed) = register_users_ring(true, &["--sensor-origin", "frame"]);
    assert!(!printed.contains("seen along"), "{printed}");
}
