//! Cross-checks against the Python readers and writer (rosbags 0.11.9, mcap 1.6.0,
//! mcap-ros2-support 0.6.0). Run with `NBV_BAG_PYTHON=/path/to/venv/bin/python`; without
//! it each test prints that it was skipped and passes.

mod common;

use std::path::{Path, PathBuf};

use common::*;
use nalgebra::{Point3, Vector3};
use nbv_bag::BagReader;
use nbv_fixtures::python_check::{bag_python, run_python};

fn script(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/python")
        .join(name)
}

#[test]
fn python_readers_decode_our_bag() {
    let Some(python) = bag_python() else { return };
    let tmp = tempfile::tempdir().unwrap();
    let dir = write_every_type(tmp.path(), "every_type");
    let stdout = run_python(&python, &script("check_bag.py"), [&dir]);
    for count in [
        "\"/points\": 3",
        "\"/tf\": 4",
        "\"/tf_static\": 1",
        "\"/markers\": 1",
        "\"/camera/camera_info\": 1",
        "\"/camera/depth\": 1",
        "\"/joint_states\": 1",
        "\"/robot_description\": 1",
    ] {
        // rosbags, mcap_ros2, and rosbags' re-serialization byte-identical to ours.
        assert_eq!(
            stdout.matches(count).count(),
            3,
            "{count} in all three:\n{stdout}"
        );
    }
    assert!(stdout.contains("\"TRANSIENT_LOCAL\""), "{stdout}");
    // The bare .mcap too.
    run_python(
        &python,
        &script("check_bag.py"),
        [dir.join("every_type_0.mcap")],
    );
}

#[test]
fn we_read_a_rosbags_bag() {
    let Some(python) = bag_python() else { return };
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("ref");
    run_python(
        &python,
        &script("write_bag.py"),
        [dir.as_os_str(), "3".as_ref()],
    );
    let bag = BagReader::open(&dir).unwrap();
    assert!(
        bag.topic("/tf_static")
            .unwrap()
            .offered_qos_profiles
            .contains("durability: 1")
    );
    let clouds = bag.point_clouds("/points").unwrap();
    assert_eq!(clouds.len(), 3);
    let tf = bag.tf_buffer().unwrap();
    for (i, c) in clouds.iter().enumerate() {
        assert_eq!(c.header.frame_id, "sensor");
        assert_eq!(c.points.len(), 200);
        let t = c.header.stamp.to_nanos();
        assert_eq!(t as u64, c.log_time_ns);
        let pose = tf.lookup("world", "sensor", t).unwrap();
        let want = Vector3::new(i as f64 + 0.5, 0.0, 1.0);
        assert!((pose.translation.vector - want).norm() < 1e-12, "{pose}");
        // Every point on the sphere of radius 0.5 about (i + 0.5, 0, 3) in world.
        let centre = Point3::new(i as f64 + 0.5, 0.0, 3.0);
        for p in &c.points {
            let r = (pose * p - centre).norm();
            assert!((r - 0.5).abs() < 1e-6, "point {p} at radius {r}");
        }
    }
    let table = tf.lookup("world", "table", 0).unwrap();
    assert_eq!(table.translation.vector, Vector3::new(0.0, 0.0, 0.75));
    assert!(tf.lookup("world", "sensor", 9 * S as i64).is_err());
}
