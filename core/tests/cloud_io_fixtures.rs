//! Files written by the real tools (PCL 1.13 `pcl-tools` and Open3D 0.20, generated once
//! and kept in `tests/data/`): PCL's zero padding after binary data, real LZF streams,
//! organised clouds with NaN pixels and a rotated VIEWPOINT, PCL's PLY `camera` element,
//! Open3D's double-precision PLY with colours.

use nalgebra::{Point3, Vector3};
use nbv_core::cloud::io::{NonFinite, ReadOptions, read_cloud, read_cloud_with};
use std::path::PathBuf;

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

fn keep() -> ReadOptions {
    ReadOptions {
        non_finite: NonFinite::Keep,
    }
}

fn f(v: f64) -> f64 {
    f64::from(v as f32)
}

#[test]
fn pcl_organised_clouds_binary_and_compressed() {
    for name in ["pcl_organised_binary.pcd", "pcl_organised_compressed.pcd"] {
        let file = read_cloud_with(data(name), &keep()).unwrap();
        assert_eq!(
            (file.width, file.height, file.cloud.len()),
            (3, 2, 6),
            "{name}"
        );
        assert!(file.cloud.points[1].x.is_nan() && file.cloud.points[5].z.is_nan());
        assert_eq!(file.cloud.points[4], Point3::new(f(0.1), f(0.1), f(1.1)));
        assert_eq!(file.ignored_fields, ["rgb"]);
        let v = file.viewpoint.unwrap();
        assert_eq!(v.translation.vector, Vector3::new(0.1, 0.2, 1.5));
        assert!((v.rotation.angle() - std::f64::consts::FRAC_PI_2).abs() < 1e-6);
        assert!((v.rotation * Vector3::z() - Vector3::x()).norm() < 1e-6);

        let dropped = read_cloud_with(data(name), &ReadOptions::default()).unwrap();
        assert_eq!((dropped.cloud.len(), dropped.dropped_non_finite), (4, 2));
        assert_eq!(
            dropped.cloud.origins,
            Some(vec![Point3::new(0.1, 0.2, 1.5); 4])
        );
    }
}

#[test]
fn pcl_normal_estimation_output_with_real_lzf_stream() {
    let input = read_cloud(data("flat_input.pcd")).unwrap();
    let file = read_cloud_with(data("pcl_normal_estimation_compressed.pcd"), &keep()).unwrap();
    assert_eq!(file.cloud.points, input.points);
    assert_eq!(file.ignored_fields, ["curvature"]);
    for n in file.cloud.normals.as_ref().unwrap() {
        assert!((n.norm() - 1.0).abs() < 1e-5, "{n}");
        assert!(n.z.abs() > 0.9, "a nearly flat patch: {n}");
    }
}

#[test]
fn pcl_ply_with_camera_element_and_our_columns() {
    // PCL's pcl_pcd2ply of one of our PCD files: `nx`, `vp_x`, `label`, then `face` and
    // `camera` elements.
    let c = read_cloud(data("pcl_pcd2ply_binary.ply")).unwrap();
    assert_eq!(c.len(), 5);
    for (i, p) in c.points.iter().enumerate() {
        assert_eq!(*p, Point3::new(f(i as f64 * 0.1), 1.0 - i as f64, 0.25));
    }
    assert_eq!(c.normals, Some(vec![Vector3::z(); 5]));
    assert_eq!(c.origins, Some(vec![Point3::new(0.0, 0.0, 2.0); 5]));
    assert_eq!(c.labels, Some(vec![10, 11, 12, 13, 14]));
}

#[test]
fn open3d_files_with_colours_and_a_nan_point() {
    let expected = [
        Point3::new(0.1, 1.0, 0.25),
        Point3::new(0.2, -1.0, 0.5),
        Point3::new(1.5, 2.5, 3.5),
    ];
    let ply = read_cloud_with(data("open3d_binary.ply"), &ReadOptions::default()).unwrap();
    assert_eq!(ply.cloud.points, expected);
    assert_eq!(ply.dropped_non_finite, 1);
    assert_eq!(ply.ignored_fields, ["red", "green", "blue"]);
    for name in ["open3d_compressed.pcd", "open3d_ascii.pcd"] {
        let file = read_cloud_with(data(name), &ReadOptions::default()).unwrap();
        let want: Vec<_> = expected.iter().map(|p| p.map(f)).collect();
        assert_eq!(file.cloud.points, want, "{name}");
        assert_eq!(file.cloud.normals, Some(vec![Vector3::z(); 3]));
        assert_eq!(file.ignored_fields, ["rgb"]);
    }
}
