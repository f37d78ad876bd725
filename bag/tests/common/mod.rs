//! A bag with one or more messages of every type the crate knows, shared by the
//! integration tests.
#![allow(dead_code)]

use std::path::{Path, PathBuf};

use nbv_bag::BagWriter;
use nbv_bag::messages::*;
use nbv_bag::point_cloud::cloud_from_points;

pub const S: u64 = 1_000_000_000;

pub fn header(t_ns: u64, frame: &str) -> Header {
    Header {
        stamp: Time::from_nanos(t_ns as i64),
        frame_id: frame.into(),
    }
}

pub fn tf(parent: &str, child: &str, t_ns: u64, x: f64) -> TransformStamped {
    TransformStamped {
        header: header(t_ns, parent),
        child_frame_id: child.into(),
        transform: Transform {
            translation: Vector3 { x, y: 0.5, z: 1.0 },
            rotation: Quaternion {
                x: 0.0,
                y: 0.0,
                z: (0.1f64).sin(),
                w: (0.1f64).cos(),
            },
        },
    }
}

pub fn image() -> Image {
    Image {
        header: header(11 * S, "camera_optical"),
        height: 2,
        width: 3,
        encoding: "32FC1".into(),
        is_bigendian: 0,
        step: 12,
        data: (0..24).collect(),
    }
}

pub fn camera_info() -> CameraInfo {
    CameraInfo {
        header: header(11 * S, "camera_optical"),
        height: 480,
        width: 640,
        distortion_model: "plumb_bob".into(),
        d: vec![0.1, -0.2, 0.001, 0.002, 0.05],
        k: [525.0, 0.0, 319.5, 0.0, 525.0, 239.5, 0.0, 0.0, 1.0],
        r: [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0],
        p: [
            525.0, 0.0, 319.5, 0.0, 0.0, 525.0, 239.5, 0.0, 0.0, 0.0, 1.0, 0.0,
        ],
        binning_x: 1,
        binning_y: 2,
        roi: RegionOfInterest {
            x_offset: 1,
            y_offset: 2,
            height: 3,
            width: 4,
            do_rectify: true,
        },
    }
}

pub fn joint_state() -> JointState {
    JointState {
        header: header(12 * S, ""),
        name: vec!["joint_1".into(), "joint_2".into()],
        position: vec![0.25, -1.5],
        velocity: vec![],
        effort: vec![3.0],
    }
}

pub fn markers() -> MarkerArray {
    MarkerArray {
        markers: vec![
            Marker {
                header: header(12 * S, "world"),
                ns: "views".into(),
                id: 7,
                r#type: Marker::CUBE_LIST,
                action: Marker::ADD,
                pose: Pose {
                    position: Point {
                        x: 1.0,
                        y: 2.0,
                        z: 3.0,
                    },
                    orientation: Quaternion::default(),
                },
                scale: Vector3 {
                    x: 0.1,
                    y: 0.1,
                    z: 0.1,
                },
                color: ColorRGBA {
                    r: 1.0,
                    g: 0.5,
                    b: 0.0,
                    a: 1.0,
                },
                lifetime: Duration { sec: 2, nanosec: 5 },
                frame_locked: true,
                points: vec![
                    Point {
                        x: 0.0,
                        y: 0.0,
                        z: 0.0,
                    },
                    Point {
                        x: 1.0,
                        y: 1.0,
                        z: 1.0,
                    },
                ],
                colors: vec![ColorRGBA {
                    r: 0.0,
                    g: 1.0,
                    b: 0.0,
                    a: 0.5,
                }],
                texture_resource: "package://x/t.png".into(),
                texture: CompressedImage {
                    header: header(12 * S, "world"),
                    format: "png".into(),
                    data: vec![0x89, b'P', b'N', b'G'],
                },
                uv_coordinates: vec![UVCoordinate { u: 0.25, v: 0.75 }],
                text: "hello".into(),
                mesh_resource: "package://x/m.stl".into(),
                mesh_file: MeshFile {
                    filename: "m.stl".into(),
                    data: vec![1, 2, 3],
                },
                mesh_use_embedded_materials: true,
            },
            Marker {
                r#type: Marker::TEXT_VIEW_FACING,
                text: "second".into(),
                ..Default::default()
            },
        ],
    }
}

/// Points of cloud `i`.
pub fn cloud_points(i: usize) -> Vec<[f32; 3]> {
    (0..50)
        .map(|k| [k as f32 * 0.01, i as f32, 2.0 - k as f32 * 0.02])
        .collect()
}

/// Writes the bag `parent/name` and returns its directory: 3 clouds, /tf bracketing
/// them, /tf_static, an image, camera info, joint states, markers, a robot description.
pub fn write_every_type(parent: &Path, name: &str) -> PathBuf {
    let mut w = BagWriter::create(parent.join(name)).unwrap();
    w.add_topic::<TFMessage>("/tf_static", true).unwrap();
    w.write(
        "/tf_static",
        10 * S,
        &TFMessage {
            transforms: vec![tf("world", "table", 10 * S, 0.0)],
        },
    )
    .unwrap();
    w.write(
        "/robot_description",
        10 * S,
        &RosString {
            data: "<robot name=\"r\"/>".into(),
        },
    )
    .unwrap();
    for i in 0..4u64 {
        let t = 10 * S + i * S;
        w.write(
            "/tf",
            t,
            &TFMessage {
                transforms: vec![
                    tf("world", "sensor", t, i as f64),
                    tf("sensor", "camera_optical", t, 0.0),
                ],
            },
        )
        .unwrap();
    }
    for i in 0..3usize {
        let t = 10 * S + i as u64 * S + S / 2;
        w.write(
            "/points",
            t,
            &cloud_from_points(header(t, "sensor"), &cloud_points(i)),
        )
        .unwrap();
    }
    w.write("/camera/depth", 11 * S, &image()).unwrap();
    w.write("/camera/camera_info", 11 * S, &camera_info())
        .unwrap();
    w.write("/joint_states", 12 * S, &joint_state()).unwrap();
    w.write("/markers", 12 * S, &markers()).unwrap();
    w.finish().unwrap()
}
