//! Files written by hand exactly as Open3D and PCL write them, and the odd corners of the
//! formats (big-endian, faces, lists, CRLF, organised clouds, VIEWPOINT, compression).

use nalgebra::{Point3, Vector3};
use nbv_core::cloud::PointCloud;
use nbv_core::cloud::io::{
    CloudFile, Encoding, NonFinite, ReadOptions, WriteOptions, read_pcd, read_ply, write_pcd,
};

fn keep() -> ReadOptions {
    ReadOptions {
        non_finite: NonFinite::Keep,
    }
}

fn ply(bytes: &[u8]) -> CloudFile {
    read_ply(bytes, &ReadOptions::default()).unwrap()
}

fn pcd(bytes: &[u8], opts: &ReadOptions) -> CloudFile {
    read_pcd(bytes, opts).unwrap()
}

#[test]
fn open3d_binary_ply_with_doubles_normals_and_colours() {
    let mut f =
        b"ply\nformat binary_little_endian 1.0\ncomment Created by Open3D\nelement vertex 2\n\
property double x\nproperty double y\nproperty double z\nproperty double nx\nproperty double ny\n\
property double nz\nproperty uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n"
            .to_vec();
    for (p, n, rgb) in [
        ([0.1, 0.2, 0.3], [0.0, 0.0, 1.0], [255u8, 0, 0]),
        ([-1.5, 2.25, 1e-3], [1.0, 0.0, 0.0], [1, 2, 3]),
    ] {
        for v in p.iter().chain(&n) {
            f.extend_from_slice(&f64::to_le_bytes(*v));
        }
        f.extend_from_slice(&rgb);
    }
    let file = ply(&f);
    let c = &file.cloud;
    assert_eq!(
        c.points,
        vec![Point3::new(0.1, 0.2, 0.3), Point3::new(-1.5, 2.25, 1e-3)]
    );
    assert_eq!(
        c.normals.as_deref(),
        Some(&[Vector3::new(0.0, 0.0, 1.0), Vector3::new(1.0, 0.0, 0.0)][..])
    );
    assert!(c.origins.is_none() && c.labels.is_none());
    assert_eq!(file.ignored_fields, ["red", "green", "blue"]);
}

#[test]
fn open3d_ascii_ply_and_crlf_comments_trailing_spaces() {
    let text = "ply\r\nformat ascii 1.0\r\ncomment Created by Open3D\r\nobj_info scanner\r\n\
element vertex 3\r\nproperty float x\r\nproperty float y\r\nproperty float z\r\n\
property int label  \r\nend_header\r\n0.5 1 2 7 \r\n\r\n-1e-2 3.5 4 8\r\n0 0 0 9\r\n\r\n";
    let c = ply(text.as_bytes()).cloud;
    assert_eq!(c.len(), 3);
    assert_eq!(c.points[1], Point3::new(f64::from(-1e-2f32), 3.5, 4.0));
    assert_eq!(c.labels, Some(vec![7, 8, 9]));
}

#[test]
fn pcl_ascii_ply_with_camera_element() {
    // PCL's PLYWriter appends a `camera` element after the vertices.
    let text = "ply\nformat ascii 1.0\ncomment PCL generated\nelement vertex 2\nproperty float x\n\
property float y\nproperty float z\nproperty float normal_x\nproperty float normal_y\n\
property float normal_z\nproperty float curvature\nelement camera 1\nproperty float view_px\n\
property float view_py\nproperty float view_pz\nproperty float x_axisx\nproperty float x_axisy\n\
property float x_axisz\nproperty int viewportx\nproperty int viewporty\nend_header\n\
1 2 3 0 0 1 0.01\n4 5 6 0 1 0 0.02\n0 0 0 1 0 0 640 480\n";
    let file = ply(text.as_bytes());
    assert_eq!(file.cloud.points[1], Point3::new(4.0, 5.0, 6.0));
    assert_eq!(
        file.cloud.normals.as_ref().unwrap()[1],
        Vector3::new(0.0, 1.0, 0.0)
    );
    assert_eq!(file.ignored_fields, ["curvature"]);
}

#[test]
fn big_endian_ply_with_faces_and_lists_in_vertices() {
    let mut f = b"ply\nformat binary_big_endian 1.0\nelement face 1\n\
property list uchar int vertex_indices\nelement vertex 2\nproperty list uint16 float32 extra\n\
property float32 x\nproperty float32 y\nproperty float32 z\nproperty ushort view\nproperty char t\n\
element edge 2\nproperty int a\nproperty int b\nend_header\n"
        .to_vec();
    f.push(3);
    for i in [0i32, 1, 1] {
        f.extend_from_slice(&i.to_be_bytes());
    }
    for (k, p, view) in [(2u16, [1.0f32, 2.0, 3.0], 5u16), (0, [4.0, 5.0, 6.0], 6)] {
        f.extend_from_slice(&k.to_be_bytes());
        for _ in 0..k {
            f.extend_from_slice(&9.5f32.to_be_bytes());
        }
        for v in p {
            f.extend_from_slice(&v.to_be_bytes());
        }
        f.extend_from_slice(&view.to_be_bytes());
        f.push(0xff);
    }
    f.extend_from_slice(&[0; 16]);
    let file = ply(&f);
    assert_eq!(
        file.cloud.points,
        vec![Point3::new(1.0, 2.0, 3.0), Point3::new(4.0, 5.0, 6.0)]
    );
    assert_eq!(file.cloud.views, Some(vec![5, 6]));
    assert_eq!(file.ignored_fields, ["extra", "t"]);
}

#[test]
fn ascii_ply_faces_and_vertex_lists() {
    let text = "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty list uchar int idx\n\
property float y\nproperty float z\nelement face 2\nproperty list uchar int vertex_indices\n\
end_header\n1 2 7 8 2 3\n4 0 5 6\n3 0 1 1\n0\n";
    let c = ply(text.as_bytes()).cloud;
    assert_eq!(
        c.points,
        vec![Point3::new(1.0, 2.0, 3.0), Point3::new(4.0, 5.0, 6.0)]
    );
}

#[test]
fn sized_type_names_and_integer_coordinates() {
    let text = "ply\nformat ascii 1.0\nelement vertex 1\nproperty int16 x\nproperty uint8 y\n\
property float64 z\nproperty uint32 label\nproperty int8 view\nend_header\n-3 200 0.125 4000000000 5\n";
    let c = ply(text.as_bytes()).cloud;
    assert_eq!(c.points[0], Point3::new(-3.0, 200.0, 0.125));
    assert_eq!(c.labels, Some(vec![4_000_000_000]));
    assert_eq!(c.views, Some(vec![5]));
}

const PCL_HEADER_XYZRGB: &str = "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\n\
FIELDS x y z rgb\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 1 1 1 1\nWIDTH 3\nHEIGHT 1\n\
VIEWPOINT 0 0 0 1 0 0 0\nPOINTS 3\n";

#[test]
fn pcl_ascii_pcd_xyzrgb() {
    let text = format!(
        "{PCL_HEADER_XYZRGB}DATA ascii\n0.93773 0.33763 0 4.2108e+06\n0.90805 0.35641 0 4.2108e+06\n\
0.81915 0.32 0 4.2108e+06\n"
    );
    let file = pcd(text.as_bytes(), &ReadOptions::default());
    assert_eq!(file.cloud.len(), 3);
    assert_eq!(file.cloud.points[2].x, f64::from(0.81915f32));
    assert!(
        file.cloud.origins.is_none(),
        "identity viewpoint gives no origins"
    );
    assert_eq!(
        file.viewpoint.map(|v| v.translation.vector),
        Some(Vector3::zeros())
    );
    assert_eq!(file.ignored_fields, ["rgb"]);
    assert_eq!((file.width, file.height), (3, 1));
}

#[test]
fn pcl_binary_pcd_xyzrgb() {
    let mut f = format!("{PCL_HEADER_XYZRGB}DATA binary\n").into_bytes();
    for i in 0..3 {
        for v in [i as f32, 0.5, -2.0] {
            f.extend_from_slice(&v.to_le_bytes());
        }
        f.extend_from_slice(&0x00ff_8000u32.to_le_bytes());
    }
    let c = pcd(&f, &ReadOptions::default()).cloud;
    assert_eq!(c.points[2], Point3::new(2.0, 0.5, -2.0));
}

#[test]
fn pcl_point_normal_with_padding_and_label() {
    // PCL writes the memory layout of PointXYZRGBNormal-like types, with `_` padding fields.
    let header = "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\n\
FIELDS x y z _ normal_x normal_y normal_z _ curvature label\nSIZE 4 4 4 1 4 4 4 1 4 4\n\
TYPE F F F U F F F U F U\nCOUNT 1 1 1 4 1 1 1 4 1 1\nWIDTH 2\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\n\
POINTS 2\nDATA binary\n";
    let mut f = header.as_bytes().to_vec();
    for i in 0..2u32 {
        for v in [1.0f32 + i as f32, 2.0, 3.0] {
            f.extend_from_slice(&v.to_le_bytes());
        }
        f.extend_from_slice(&[0xAB; 4]);
        for v in [0.0f32, 0.0, 1.0] {
            f.extend_from_slice(&v.to_le_bytes());
        }
        f.extend_from_slice(&[0xCD; 4]);
        f.extend_from_slice(&0.25f32.to_le_bytes());
        f.extend_from_slice(&(10 + i).to_le_bytes());
    }
    let file = pcd(&f, &ReadOptions::default());
    assert_eq!(file.cloud.points[1], Point3::new(2.0, 2.0, 3.0));
    assert_eq!(
        file.cloud.normals.as_ref().unwrap()[0],
        Vector3::new(0.0, 0.0, 1.0)
    );
    assert_eq!(file.cloud.labels, Some(vec![10, 11]));
    assert_eq!(file.ignored_fields, ["_", "_", "curvature"]);
}

fn organised_pcd() -> Vec<u8> {
    let header = "# .PCD v0.7 - Point Cloud Data file format\nVERSION .7\nFIELDS x y z\nSIZE 4 4 4\n\
TYPE F F F\nCOUNT 1 1 1\nWIDTH 2\nHEIGHT 2\nVIEWPOINT 0.5 0 1.5 1 0 0 0\nPOINTS 4\nDATA binary\n";
    let mut f = header.as_bytes().to_vec();
    for p in [
        [0.0f32, 0.0, 1.0],
        [f32::NAN; 3],
        [1.0, 0.0, 1.0],
        [1.0, 1.0, 1.0],
    ] {
        for v in p {
            f.extend_from_slice(&v.to_le_bytes());
        }
    }
    f
}

#[test]
fn organised_cloud_nan_policy_and_viewpoint_origins() {
    let f = organised_pcd();
    let kept = pcd(&f, &keep());
    assert_eq!((kept.width, kept.height, kept.cloud.len()), (2, 2, 4));
    assert!(kept.cloud.points[1].x.is_nan());
    let dropped = pcd(&f, &ReadOptions::default());
    assert_eq!((dropped.cloud.len(), dropped.dropped_non_finite), (3, 1));
    assert_eq!(dropped.cloud.points[1], Point3::new(1.0, 0.0, 1.0));
    // The viewpoint is not the identity and the file has no origins: its translation.
    assert_eq!(
        dropped.cloud.origins,
        Some(vec![Point3::new(0.5, 0.0, 1.5); 3])
    );
    assert_eq!(dropped.cloud.validate(), Ok(()));
    let err = read_pcd(
        &f[..],
        &ReadOptions {
            non_finite: NonFinite::Reject,
        },
    )
    .unwrap_err();
    assert_eq!(err.location, nbv_core::cloud::io::Location::Point(1));
    assert!(
        err.to_string().contains("point 1: point is not finite"),
        "{err}"
    );
}

#[test]
fn per_point_viewpoint_fields_win_over_header_viewpoint() {
    let text = "VERSION 0.7\nFIELDS x y z vp_x vp_y vp_z\nSIZE 8 8 8 4 4 4\nTYPE F F F F F F\n\
WIDTH 1\nVIEWPOINT 9 9 9 0 1 0 0\nPOINTS 1\nDATA ascii\n1 2 3 0.5 0.5 0.5\n";
    let file = pcd(text.as_bytes(), &ReadOptions::default());
    assert_eq!(file.cloud.origins, Some(vec![Point3::new(0.5, 0.5, 0.5)]));
    let v = file.viewpoint.unwrap();
    assert_eq!(v.translation.vector, Vector3::new(9.0, 9.0, 9.0));
    assert!((v.rotation.angle() - std::f64::consts::PI).abs() < 1e-12);
}

#[test]
fn pcd_v05_header_with_columns_and_no_count_or_viewpoint() {
    let text = "# .PCD v.5 - Point Cloud Data file format\r\nVERSION .5\r\nCOLUMNS x y z\r\nSIZE 4 4 4\r\n\
TYPE F F F\r\nWIDTH 2\r\nHEIGHT 1\r\nPOINTS 2\r\nDATA ascii\r\n1 2 3\r\n4 5 6  \r\n";
    let file = pcd(text.as_bytes(), &ReadOptions::default());
    assert_eq!(file.cloud.points[1], Point3::new(4.0, 5.0, 6.0));
    assert!(file.viewpoint.is_none());
}

#[test]
fn compressed_pcd_written_then_read_with_unknown_fields() {
    // Our writer's compressed layout is PCL's: check a file with an extra field decodes.
    let mut cloud =
        PointCloud::from_points((0..50).map(|i| Point3::new(i as f64, 0.5, -1.0)).collect());
    cloud.labels = Some((0..50).collect());
    let mut out = Vec::new();
    write_pcd(
        &mut out,
        &cloud,
        &WriteOptions {
            encoding: Encoding::BinaryCompressed,
            ..Default::default()
        },
    )
    .unwrap();
    let text = String::from_utf8_lossy(&out);
    assert!(text.contains("DATA binary_compressed\n"));
    assert_eq!(pcd(&out, &ReadOptions::default()).cloud, cloud);
}
