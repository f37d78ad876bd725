//! `bag/` read back with `nbv_bag::BagReader`: a short episode on a generated one-object
//! scene (two views at most) with `--bag`'s extra, then every topic, its type and its
//! counts checked against the episode's files and against the same episode run without
//! the bag (which must be the same episode: the same report apart from its times, the same
//! files byte for byte). With `NBV_BAG_PYTHON` set, the Python readers (rosbags, mcap)
//! decode the bag too (bag/tests/python/check_bag.py).

use nalgebra::Point3;
use nbv_bag::BagReader;
use nbv_bag::messages::{CameraInfo, Image, JointState, Marker, MarkerArray, RosString, TFMessage};
use nbv_core::pipeline::{ExploreMode, NoObserver};
use nbv_sweep::bag_recording::{STAMP_OFFSET_NS, topics};
use nbv_sweep::episode::{Extras, Outputs, explore_in_twin, finish_episode, run_episode};
use serde_json::Value;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use nbv_fixtures::without_timing;

/// Every file under `dir` (relative path → bytes), `bag/` left out.
fn files(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    fn walk(root: &Path, dir: &Path, out: &mut BTreeMap<PathBuf, Vec<u8>>) {
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            let rel = path.strip_prefix(root).unwrap().to_owned();
            if rel == Path::new("bag") {
                continue;
            }
            if path.is_dir() {
                walk(root, &path, out);
            } else {
                out.insert(rel, std::fs::read(&path).unwrap());
            }
        }
    }
    let mut out = BTreeMap::new();
    walk(dir, dir, &mut out);
    out
}

/// The vertex count a PLY file's header declares.
fn ply_points(path: &Path) -> usize {
    let bytes = std::fs::read(path).unwrap();
    let text = String::from_utf8_lossy(&bytes[..bytes.len().min(4096)]).into_owned();
    text.lines()
        .take_while(|l| *l != "end_header")
        .find_map(|l| l.strip_prefix("element vertex "))
        .unwrap_or_else(|| panic!("{}: no vertex count", path.display()))
        .trim()
        .parse()
        .unwrap()
}

fn report_json(dir: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(dir.join("report.json")).unwrap()).unwrap()
}

#[test]
fn an_episode_bag_holds_every_topic_and_the_same_episode() {
    let base = nbv_scenes::generator::generate(3, 1).unwrap();
    let scene = nbv_scenes::overrides::with_overrides(
        &base,
        &[("nbv.max_views_per_object".into(), toml::Value::Integer(2))],
        "test",
        "generated",
    )
    .unwrap();
    let tmp = tempfile::tempdir().unwrap();

    // With the bag, as `nbv explore --bag` runs it.
    let with = tmp.path().join("with");
    let extras = Extras {
        bag: true,
        ..Default::default()
    };
    let report = run_episode(&scene, ExploreMode::Hybrid, &with, extras, &mut NoObserver).unwrap();
    // Without, keeping the exploration (the reported sensor poses).
    let without = tmp.path().join("without");
    let (config, exploration) =
        explore_in_twin(&scene, ExploreMode::Hybrid, &mut NoObserver).unwrap();
    finish_episode(
        &scene,
        &config,
        &exploration,
        &without,
        false,
        None,
        Outputs::All,
    )
    .unwrap();
    same_episode(&with, &without);

    let dir = with.join("bag");
    assert!(dir.join("bag_0.mcap").is_file() && dir.join("metadata.yaml").is_file());
    let bag = BagReader::open(&dir).unwrap();
    let views = report.totals.views;
    assert_eq!(views, report.objects[0].views.len());
    assert!(views >= 1, "the episode took no view");
    let model_topic = topics::model_topic(&report.objects[0].name, 0);
    every_topic(&bag, &model_topic);
    let tf_samples = robot_frames(&bag, &scene);
    episode_data(&bag, &with, &scene, &report, &exploration);
    markers_models_events(&bag, &with, &report, &model_topic);
    python_cross_check(&dir, tf_samples);
}

/// The report apart from its times and every other file byte for byte; nothing partial.
fn same_episode(with: &Path, without: &Path) {
    // The same episode: the report apart from times, every other file byte for byte.
    assert_eq!(
        without_timing(&report_json(with)),
        without_timing(&report_json(without))
    );
    let (mut a, mut b) = (files(with), files(without));
    let report_file = PathBuf::from("report.json");
    assert!(a.remove(&report_file).is_some() && b.remove(&report_file).is_some());
    assert!(b.len() > 5, "{:?}", b.keys());
    assert_eq!(a.keys().collect::<Vec<_>>(), b.keys().collect::<Vec<_>>());
    for (path, bytes) in &b {
        assert!(a[path] == *bytes, "{} differs", path.display());
    }
    // Nothing partial left beside the bag.
    let names: Vec<String> = std::fs::read_dir(with)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert!(names.iter().all(|n| !n.starts_with('.')), "{names:?}");
}

/// Every topic, with its type, none empty, the latched ones transient-local.
fn every_topic(bag: &BagReader, model_topic: &str) {
    // Every topic, with its type.
    let types: BTreeMap<&str, &str> = bag
        .topics()
        .map(|t| (t.name.as_str(), t.type_name.as_str()))
        .collect();
    let expected = [
        (topics::TF, "tf2_msgs/msg/TFMessage"),
        (topics::TF_STATIC, "tf2_msgs/msg/TFMessage"),
        (topics::JOINT_STATES, "sensor_msgs/msg/JointState"),
        (topics::ROBOT_DESCRIPTION, "std_msgs/msg/String"),
        (topics::SWEEP_POINTS, "sensor_msgs/msg/PointCloud2"),
        (topics::CAMERA_POINTS, "sensor_msgs/msg/PointCloud2"),
        (topics::CAMERA_DEPTH, "sensor_msgs/msg/Image"),
        (topics::CAMERA_INFO, "sensor_msgs/msg/CameraInfo"),
        (topics::GRID_OCCUPIED, "visualization_msgs/msg/MarkerArray"),
        (topics::GRID_UNKNOWN, "visualization_msgs/msg/MarkerArray"),
        (topics::CANDIDATES, "visualization_msgs/msg/MarkerArray"),
        (model_topic, "sensor_msgs/msg/PointCloud2"),
        (topics::EVENTS, "std_msgs/msg/String"),
    ];
    assert_eq!(types, BTreeMap::from(expected), "{types:?}");
    for t in bag.topics() {
        assert!(t.message_count >= 1, "{} is empty", t.name);
        let latched = t.name == topics::TF_STATIC || t.name == topics::ROBOT_DESCRIPTION;
        assert_eq!(
            t.offered_qos_profiles.contains("durability: 1"),
            latched,
            "{}: {}",
            t.name,
            t.offered_qos_profiles
        );
    }
}

/// The URDF, the static frames, `/tf` and `/joint_states`; returns the `/tf` samples.
fn robot_frames(bag: &BagReader, scene: &nbv_scenes::Scene) -> usize {
    // The URDF and the static frames.
    let urdf = std::fs::read_to_string(&scene.robot.urdf).unwrap();
    let description = bag.read::<RosString>(topics::ROBOT_DESCRIPTION).unwrap();
    assert_eq!(description.len(), 1);
    assert_eq!(description[0].1.data, urdf);
    let statics = bag.read::<TFMessage>(topics::TF_STATIC).unwrap();
    assert_eq!(statics.len(), 1);
    let edges: Vec<(&str, &str)> = statics[0]
        .1
        .transforms
        .iter()
        .map(|t| (t.header.frame_id.as_str(), t.child_frame_id.as_str()))
        .collect();
    for edge in [
        ("world", "base_link"),
        ("world", "table"),
        ("link_6", "tool0"),
        ("tool0", "ee_bracket"),
        ("ee_bracket", "lms400"),
        ("ee_bracket", "dinast"),
    ] {
        assert!(edges.contains(&edge), "{edge:?} not in {edges:?}");
    }
    let table = &statics[0].1.transforms[1].transform.translation;
    assert!((table.z - scene.table.top()).abs() < 1e-12);

    // /tf and /joint_states: the six moving joints at the same samples, stamps never 0.
    let tf = bag.read::<TFMessage>(topics::TF).unwrap();
    let joints = bag.read::<JointState>(topics::JOINT_STATES).unwrap();
    assert_eq!(tf.len(), joints.len());
    assert!(tf.len() > 20, "{} /tf samples", tf.len());
    for ((t, m), (u, j)) in tf.iter().zip(&joints) {
        assert_eq!(t, u);
        assert_eq!(m.transforms.len(), 6);
        assert_eq!(m.transforms[0].header.stamp.to_nanos() as u64, *t);
        assert_eq!(j.position.len(), 6);
    }
    assert_eq!(
        joints[0].1.name,
        [
            "joint_1", "joint_2", "joint_3", "joint_4", "joint_5", "joint_6"
        ]
    );
    for t in bag.topics() {
        for m in bag.messages(&t.name).unwrap() {
            assert!(m.log_time_ns >= STAMP_OFFSET_NS, "{}", t.name);
        }
    }

    tf.len()
}

/// The sweep cloud, and each view's points, pose, depth image and camera info.
fn episode_data(
    bag: &BagReader,
    with: &Path,
    scene: &nbv_scenes::Scene,
    report: &nbv_sweep::report::ExploreReport,
    exploration: &nbv_core::pipeline::Exploration,
) {
    let views = report.totals.views;
    let name = report.objects[0].name.as_str();
    // The sweep cloud: as many points as mid_range.ply.
    let sweep = bag.point_clouds(topics::SWEEP_POINTS).unwrap();
    assert_eq!(sweep.len(), 1);
    assert_eq!(sweep[0].header.frame_id, "world");
    assert_eq!(
        sweep[0].points.len(),
        ply_points(&with.join("mid_range.ply"))
    );
    assert_eq!(sweep[0].points.len(), report.phase_one.points);

    // Each view: its points in the camera frame (as many as view_NN.ply), the camera's
    // pose from /tf at the view's stamp (the reported sensor pose), its depth image and
    // its camera info.
    let tfs = bag.tf_buffer().unwrap();
    let clouds = bag.point_clouds(topics::CAMERA_POINTS).unwrap();
    assert_eq!(clouds.len(), views);
    let taken = &exploration.objects[0].views;
    assert_eq!(taken.len(), views);
    let camera = scene.sensors.short_range.spec();
    for (k, (cloud, view)) in clouds.iter().zip(taken).enumerate() {
        let ply = with
            .join("objects")
            .join(name)
            .join(format!("views/view_{:02}.ply", k + 1));
        assert_eq!(cloud.points.len(), ply_points(&ply), "view {}", k + 1);
        assert_eq!(cloud.header.frame_id, camera.frame);
        let pose = tfs
            .lookup("world", &camera.frame, cloud.header.stamp.to_nanos())
            .unwrap();
        let dt = (pose.translation.vector - view.sensor_pose.translation.vector).norm();
        let dr = pose.rotation.angle_to(&view.sensor_pose.rotation);
        assert!(dt < 1e-6 && dr < 1e-6, "view {}: {dt} m, {dr} rad", k + 1);
        // The points back in the world frame are the view's (f32 on the wire).
        for (p, q) in cloud.points.iter().zip(&view.cloud.points) {
            let back: Point3<f64> = pose * p;
            assert!((back - q).norm() < 1e-5, "view {}: {back} vs {q}", k + 1);
        }
    }
    let depth = bag.read::<Image>(topics::CAMERA_DEPTH).unwrap();
    let info = bag.read::<CameraInfo>(topics::CAMERA_INFO).unwrap();
    assert_eq!((depth.len(), info.len()), (views, views));
    for ((_, image), view) in depth.iter().zip(taken) {
        assert_eq!(
            (
                image.encoding.as_str(),
                image.width,
                image.height,
                image.step
            ),
            (
                "32FC1",
                camera.width as u32,
                camera.height as u32,
                4 * camera.width as u32
            )
        );
        assert_eq!(image.data.len(), 4 * camera.width * camera.height);
        let valid = image
            .data
            .chunks_exact(4)
            .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .filter(|d| d.is_finite() && *d > 0.0)
            .count();
        assert_eq!(valid, view.frame_points);
    }
    let k = info[0].1.k;
    assert!((k[0] - camera.focal()).abs() < 1e-9 && (k[4] - camera.focal()).abs() < 1e-9);
    assert_eq!((k[2], k[5], k[8]), (159.5, 119.5, 1.0));
    assert_eq!(info[0].1.distortion_model, "plumb_bob");
    assert_eq!(info[0].1.d, vec![0.0; 5]);
}

/// The grid, the candidates, the model and the events.
fn markers_models_events(
    bag: &BagReader,
    with: &Path,
    report: &nbv_sweep::report::ExploreReport,
    model_topic: &str,
) {
    let views = report.totals.views;
    let object = &report.objects[0];
    let name = object.name.as_str();
    // The reduced map after phase 1 and after each view; the candidates.
    for topic in [topics::GRID_OCCUPIED, topics::GRID_UNKNOWN] {
        let grids = bag.read::<MarkerArray>(topic).unwrap();
        assert_eq!(grids.len(), 1 + views, "{topic}");
        let m = &grids[0].1.markers[0];
        assert_eq!(m.r#type, Marker::CUBE_LIST);
        assert_eq!(m.header.frame_id, "world");
        let phase_one = if topic == topics::GRID_OCCUPIED {
            report.phase_one.reduced_occupied
        } else {
            report.phase_one.reduced_unknown
        };
        assert_eq!(m.points.len(), phase_one, "{topic}");
        assert!(m.scale.x > 0.0 && m.scale.x == m.scale.z);
    }
    let candidates = bag.read::<MarkerArray>(topics::CANDIDATES).unwrap();
    assert!(candidates.len() >= views);
    let m = &candidates[0].1.markers[0];
    assert_eq!(m.r#type, Marker::SPHERE_LIST);
    assert!(!m.points.is_empty() && m.colors.len() == m.points.len());

    // The model: as many points as model.ply.
    let models = bag.point_clouds(model_topic).unwrap();
    assert_eq!(models.len(), 1);
    assert_eq!(
        models[0].points.len(),
        ply_points(&with.join("objects").join(name).join("model.ply"))
    );

    // The events: one JSON object each, in order.
    let events: Vec<Value> = bag
        .read::<RosString>(topics::EVENTS)
        .unwrap()
        .into_iter()
        .map(|(_, s)| serde_json::from_str(&s.data).unwrap())
        .collect();
    let kinds: Vec<&str> = events.iter().map(|e| e["kind"].as_str().unwrap()).collect();
    assert_eq!(kinds[0], "sweep_started");
    assert_eq!(kinds.last(), Some(&"registered"));
    assert_eq!(kinds.iter().filter(|k| **k == "view_taken").count(), views);
    assert_eq!(
        kinds.iter().filter(|k| **k == "grid_updated").count(),
        1 + views
    );
    let done = events.iter().find(|e| e["kind"] == "object_done").unwrap();
    assert_eq!(done["stop"], object.stop.as_str());
}

/// The Python readers (rosbags, mcap), when `NBV_BAG_PYTHON` names their Python.
fn python_cross_check(dir: &Path, tf_samples: usize) {
    if let Some(python) = nbv_fixtures::python_check::bag_python() {
        let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("../bag/tests/python/check_bag.py");
        let stdout = nbv_fixtures::python_check::run_python(&python, &script, [dir]);
        let tf_count = format!("\"{}\": {}", topics::TF, tf_samples);
        assert_eq!(
            stdout.matches(&tf_count).count(),
            3,
            "{tf_count}:\n{stdout}"
        );
    }
}
