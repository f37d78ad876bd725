//! Write a bag with every message type, read it back and compare; damaged files are
//! errors, not panics.

mod common;

use common::*;
use nalgebra::Vector3 as NaVector3;
use nbv_bag::messages::*;
use nbv_bag::{BagError, BagReader};

#[test]
fn every_type_round_trips() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = write_every_type(tmp.path(), "run");
    assert!(dir.join("run_0.mcap").is_file());
    let bag = BagReader::open(&dir).unwrap();
    let topics: Vec<(&str, &str, usize)> = bag
        .topics()
        .map(|t| (t.name.as_str(), t.type_name.as_str(), t.message_count))
        .collect();
    assert_eq!(
        topics,
        vec![
            ("/camera/camera_info", "sensor_msgs/msg/CameraInfo", 1),
            ("/camera/depth", "sensor_msgs/msg/Image", 1),
            ("/joint_states", "sensor_msgs/msg/JointState", 1),
            ("/markers", "visualization_msgs/msg/MarkerArray", 1),
            ("/points", "sensor_msgs/msg/PointCloud2", 3),
            ("/robot_description", "std_msgs/msg/String", 1),
            ("/tf", "tf2_msgs/msg/TFMessage", 4),
            ("/tf_static", "tf2_msgs/msg/TFMessage", 1),
        ]
    );
    // Latched topics carry transient-local QoS, the others ''.
    assert!(
        bag.topic("/tf_static")
            .unwrap()
            .offered_qos_profiles
            .contains("durability: 1")
    );
    assert!(
        bag.topic("/robot_description")
            .unwrap()
            .offered_qos_profiles
            .contains("durability: 1")
    );
    assert_eq!(bag.topic("/tf").unwrap().offered_qos_profiles, "");

    assert_eq!(
        bag.read::<Image>("/camera/depth").unwrap(),
        vec![(11 * S, image())]
    );
    assert_eq!(
        bag.read::<CameraInfo>("/camera/camera_info").unwrap(),
        vec![(11 * S, camera_info())]
    );
    assert_eq!(
        bag.read::<JointState>("/joint_states").unwrap(),
        vec![(12 * S, joint_state())]
    );
    assert_eq!(
        bag.read::<MarkerArray>("/markers").unwrap(),
        vec![(12 * S, markers())]
    );
    assert_eq!(
        bag.read::<RosString>("/robot_description").unwrap()[0]
            .1
            .data,
        "<robot name=\"r\"/>"
    );
    let tfs = bag.read::<TFMessage>("/tf").unwrap();
    assert_eq!(tfs.len(), 4);
    assert_eq!(tfs[2].1.transforms[0], tf("world", "sensor", 12 * S, 2.0));

    let clouds = bag.point_clouds("/points").unwrap();
    assert_eq!(clouds.len(), 3);
    for (i, c) in clouds.iter().enumerate() {
        assert_eq!(c.header.frame_id, "sensor");
        assert_eq!(c.log_time_ns, 10 * S + i as u64 * S + S / 2);
        let want: Vec<_> = cloud_points(i)
            .iter()
            .map(|p| nalgebra::Point3::new(f64::from(p[0]), f64::from(p[1]), f64::from(p[2])))
            .collect();
        assert_eq!(c.points, want);
    }

    // tf through the bag: the sensor halfway between the samples at 11 s and 12 s.
    let buffer = bag.tf_buffer().unwrap();
    let stamp = clouds[1].header.stamp.to_nanos();
    let pose = buffer.lookup("world", "sensor", stamp).unwrap();
    assert!((pose.translation.vector - NaVector3::new(1.5, 0.5, 1.0)).norm() < 1e-12);
    assert!((pose.rotation.angle() - 0.2).abs() < 1e-12);
    let camera = buffer.lookup("table", "camera_optical", stamp).unwrap();
    assert!(camera.translation.vector.norm() > 0.0);
    assert!(buffer.lookup("world", "sensor", 9 * S as i64).is_err());

    // metadata.yaml counts and times.
    let yaml = std::fs::read_to_string(dir.join("metadata.yaml")).unwrap();
    assert!(yaml.contains("  message_count: 13\n"), "{yaml}");
    assert!(
        yaml.contains("nanoseconds_since_epoch: 10000000000"),
        "{yaml}"
    );
    assert!(yaml.contains("nanoseconds: 3000000000"), "{yaml}");
    assert!(
        yaml.contains("relative_file_paths:\n  - \"run_0.mcap\""),
        "{yaml}"
    );

    // The bare .mcap opens too, and so does a directory without metadata.yaml.
    let bare = BagReader::open(dir.join("run_0.mcap")).unwrap();
    assert_eq!(bare.topic("/points").unwrap().message_count, 3);
    std::fs::remove_file(dir.join("metadata.yaml")).unwrap();
    assert_eq!(BagReader::open(&dir).unwrap().topics().count(), 8);
}

#[test]
fn damaged_files_are_errors() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = write_every_type(tmp.path(), "run");
    let file = dir.join("run_0.mcap");
    let bytes = std::fs::read(&file).unwrap();
    let mut errors = 0;
    for cut in [
        0,
        7,
        8,
        30,
        bytes.len() / 3,
        bytes.len() / 2,
        bytes.len() - 9,
        bytes.len() - 1,
    ] {
        match BagReader::from_mcap_bytes(&file, &bytes[..cut]) {
            Err(e) => {
                assert!(
                    e.to_string().starts_with(&file.display().to_string()),
                    "{e}"
                );
                errors += 1;
            }
            Ok(_) => panic!("a file cut at {cut} of {} bytes opened", bytes.len()),
        }
    }
    assert_eq!(errors, 8);
    // Flipped bytes inside the zstd chunk: CRC or decompression error, never a panic.
    for at in (40..bytes.len() - 40).step_by(97) {
        let mut b = bytes.clone();
        b[at] ^= 0x5a;
        let _ = BagReader::from_mcap_bytes(&file, &b);
    }
    // A CDR message with a corrupt count: the error names file, topic and index.
    let mut w = nbv_bag::BagWriter::create(tmp.path().join("bad")).unwrap();
    w.add_topic::<TFMessage>("/tf", false).unwrap();
    w.write_raw("/tf", 1, &TFMessage::default().encode())
        .unwrap();
    w.write_raw("/tf", 2, &[0, 1, 0, 0, 0xff, 0xff, 0, 0])
        .unwrap();
    let bad = w.finish().unwrap();
    let e = BagReader::open(&bad).unwrap().tf_buffer().unwrap_err();
    assert!(matches!(e, BagError::Message { index: 1, .. }), "{e}");
    assert!(
        e.to_string()
            .contains("bad_0.mcap: topic /tf message 1: CDR truncated"),
        "{e}"
    );
    // Missing things.
    assert!(matches!(
        BagReader::open(tmp.path().join("nothing")),
        Err(BagError::Io { .. })
    ));
    let empty = tmp.path().join("empty");
    std::fs::create_dir(&empty).unwrap();
    assert!(matches!(
        BagReader::open(&empty),
        Err(BagError::Layout { .. })
    ));
}

/// Found by the `bag_file` fuzz target, each a panic inside mcap 0.26.0 before: a record
/// longer than what is left of its uncompressed chunk (rosbags writes uncompressed chunks;
/// an overflowing subtraction), the same in a chunk that runs past the end of the file,
/// and an attachment record shorter than its header (a slice out of bounds). All are
/// errors now.
#[test]
fn fuzz_findings_are_errors() {
    for name in [
        "fuzz_uncompressed_chunk_overrun.mcap",
        "fuzz_short_attachment.mcap",
        "fuzz_truncated_uncompressed_chunk.mcap",
    ] {
        let path = format!("{}/tests/data/{name}", env!("CARGO_MANIFEST_DIR"));
        let e = BagReader::open(&path).unwrap_err();
        assert!(matches!(e, BagError::Mcap { .. }), "{name}: {e}");
    }
}
