//! Every schema text is the one rosbags 0.11.9 generates
//! (`typestore.generate_msgdef(type, ros_version=2)`, Humble store): byte for byte against
//! the live rosbags when `NBV_BAG_PYTHON` names a Python that has it (`.ci/run` installs
//! one), and by the lengths the facts record in any case.

use std::path::Path;

use nbv_bag::messages::*;

/// Each type's name and schema text.
fn ours() -> Vec<(&'static str, String)> {
    fn one<M: RosMessage>() -> (&'static str, String) {
        (M::TYPE_NAME, M::schema_text())
    }
    vec![
        one::<Time>(),
        one::<Duration>(),
        one::<Header>(),
        one::<RosString>(),
        one::<ColorRGBA>(),
        one::<Vector3>(),
        one::<Point>(),
        one::<Quaternion>(),
        one::<Pose>(),
        one::<PoseWithCovariance>(),
        one::<PoseWithCovarianceStamped>(),
        one::<Transform>(),
        one::<TransformStamped>(),
        one::<TFMessage>(),
        one::<PointField>(),
        one::<PointCloud2>(),
        one::<Image>(),
        one::<CompressedImage>(),
        one::<CameraInfo>(),
        one::<RegionOfInterest>(),
        one::<JointState>(),
        one::<UVCoordinate>(),
        one::<MeshFile>(),
        one::<Marker>(),
        one::<MarkerArray>(),
    ]
}

#[test]
fn schema_texts_have_the_lengths_rosbags_writes() {
    assert_eq!(PointCloud2::schema_text().len(), 724);
    assert_eq!(TFMessage::schema_text().len(), 990);
    assert_eq!(Image::schema_text().len(), 393);
    assert_eq!(CameraInfo::schema_text().len(), 666);
    assert_eq!(JointState::schema_text().len(), 375);
    assert_eq!(MarkerArray::schema_text().len(), 2504);
    assert_eq!(PoseWithCovarianceStamped::schema_text().len(), 968);
    assert_eq!(RosString::schema_text(), "string data\n");
}

#[test]
fn schema_texts_match_rosbags() {
    let Some(python) = nbv_fixtures::python_check::bag_python() else {
        return;
    };
    let ours = ours();
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/python/schemas.py");
    let stdout = nbv_fixtures::python_check::run_python(
        &python,
        &script,
        ours.iter().map(|(name, _)| *name),
    );
    for (name, text) in &ours {
        // The JSON string of our text, as Python's json.dumps writes it (ASCII only here).
        let mut quoted = String::from("\"");
        for c in text.chars() {
            match c {
                '\n' => quoted.push_str("\\n"),
                '"' => quoted.push_str("\\\""),
                '\\' => quoted.push_str("\\\\"),
                c => quoted.push(c),
            }
        }
        quoted.push('"');
        assert!(
            stdout.contains(&format!("\"{name}\": {quoted}")),
            "{name}: ours differs from rosbags'\nours: {text}\nrosbags: {stdout}"
        );
    }
}
