//! Round trips of random clouds through every format × encoding × float type × column
//! combination, determinism of the writers, and the file-level API (dispatch, atomicity).

use nalgebra::{Point3, Vector3};
use nbv_core::cloud::PointCloud;
use nbv_core::cloud::io::{
    CloudFormat, CloudIoErrorKind, Encoding, FloatType, NonFinite, ReadOptions, WriteOptions,
    read_cloud, read_cloud_with, read_pcd, read_ply, write_cloud, write_pcd, write_ply,
};
use proptest::prelude::*;

const FORMATS: [(CloudFormat, Encoding); 5] = [
    (CloudFormat::Ply, Encoding::Ascii),
    (CloudFormat::Ply, Encoding::Binary),
    (CloudFormat::Pcd, Encoding::Ascii),
    (CloudFormat::Pcd, Encoding::Binary),
    (CloudFormat::Pcd, Encoding::BinaryCompressed),
];

fn write(format: CloudFormat, cloud: &PointCloud, opts: &WriteOptions) -> Vec<u8> {
    let mut out = Vec::new();
    match format {
        CloudFormat::Ply => write_ply(&mut out, cloud, opts).unwrap(),
        CloudFormat::Pcd => write_pcd(&mut out, cloud, opts).unwrap(),
    }
    out
}

fn read(format: CloudFormat, bytes: &[u8], opts: &ReadOptions) -> PointCloud {
    match format {
        CloudFormat::Ply => read_ply(bytes, opts).unwrap().cloud,
        CloudFormat::Pcd => read_pcd(bytes, opts).unwrap().cloud,
    }
}

/// What the cloud must read back as: coordinates rounded to the written float type.
fn expected(cloud: &PointCloud, float: FloatType) -> PointCloud {
    let r = |v: f64| match float {
        FloatType::F32 => f64::from(v as f32),
        FloatType::F64 => v,
    };
    let p = |p: &Point3<f64>| Point3::new(r(p.x), r(p.y), r(p.z));
    PointCloud {
        points: cloud.points.iter().map(p).collect(),
        origins: cloud.origins.as_ref().map(|c| c.iter().map(p).collect()),
        normals: cloud.normals.as_ref().map(|c| {
            c.iter()
                .map(|v| Vector3::new(r(v.x), r(v.y), r(v.z)))
                .collect()
        }),
        labels: cloud.labels.clone(),
        views: cloud.views.clone(),
        truth: cloud.truth.as_ref().map(|c| c.iter().map(p).collect()),
    }
}

fn coord() -> impl Strategy<Value = f64> {
    prop_oneof![
        8 => -100.0..100.0f64,
        1 => Just(0.0),
        1 => -1e-30..1e-30f64,
        1 => -1e30..1e30f64,
    ]
}

fn point() -> impl Strategy<Value = Point3<f64>> {
    (coord(), coord(), coord()).prop_map(|(x, y, z)| Point3::new(x, y, z))
}

prop_compose! {
    fn random_cloud()(n in 0usize..40, mask in 0u8..32)(
        points in proptest::collection::vec(point(), n),
        origins in proptest::collection::vec(point(), n),
        normals in proptest::collection::vec(point(), n),
        labels in proptest::collection::vec(any::<u32>(), n),
        views in proptest::collection::vec(any::<u32>(), n),
        truth in proptest::collection::vec(point(), n),
        mask in Just(mask),
    ) -> PointCloud {
        let on = |bit: u8| mask & (1 << bit) != 0;
        PointCloud {
            points,
            origins: on(0).then_some(origins),
            normals: on(1).then(|| normals.into_iter().map(|p| p.coords).collect()),
            labels: on(2).then_some(labels),
            views: on(3).then_some(views),
            truth: on(4).then_some(truth),
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn every_format_round_trips(cloud in random_cloud()) {
        for float in [FloatType::F32, FloatType::F64] {
            let want = expected(&cloud, float);
            for (format, encoding) in FORMATS {
                let opts = WriteOptions { encoding, float };
                let bytes = write(format, &cloud, &opts);
                let back = read(format, &bytes, &ReadOptions::default());
                prop_assert_eq!(&back, &want, "{:?} {:?} {:?}", format, encoding, float);
                // Deterministic, and rewriting what was read changes nothing.
                prop_assert_eq!(&write(format, &cloud, &opts), &bytes);
                prop_assert_eq!(write(format, &back, &opts), bytes);
            }
        }
    }

    #[test]
    fn nan_points_survive_with_keep(n in 1usize..20, bad in 0usize..20) {
        let mut cloud = PointCloud::from_points((0..n).map(|i| Point3::new(i as f64, 1.0, 2.0)).collect());
        cloud.labels = Some((0..n as u32).collect());
        let bad = bad % n;
        cloud.points[bad].y = f64::NAN;
        for (format, encoding) in FORMATS {
            let bytes = write(format, &cloud, &WriteOptions { encoding, ..Default::default() });
            let kept = read(format, &bytes, &ReadOptions { non_finite: NonFinite::Keep });
            prop_assert_eq!(kept.len(), n);
            prop_assert!(kept.points[bad].y.is_nan());
            let dropped = read(format, &bytes, &ReadOptions::default());
            prop_assert_eq!(dropped.len(), n - 1);
            prop_assert!(!dropped.labels.as_ref().unwrap().contains(&(bad as u32)));
        }
    }
}

#[test]
fn f32_output_rejects_values_beyond_float_range() {
    let cloud = PointCloud::from_points(vec![Point3::new(0.0, 1e39, 0.0)]);
    let empty = write(
        CloudFormat::Ply,
        &PointCloud::default(),
        &WriteOptions::default(),
    );
    assert_eq!(
        read(CloudFormat::Ply, &empty, &ReadOptions::default()),
        PointCloud::default()
    );
    let e = write_ply(&mut Vec::new(), &cloud, &WriteOptions::default()).unwrap_err();
    assert!(
        matches!(
            e.kind,
            CloudIoErrorKind::NotRepresentable { column: "y", .. }
        ),
        "{e}"
    );
    let f64_opts = WriteOptions {
        float: FloatType::F64,
        ..Default::default()
    };
    let bytes = write(CloudFormat::Pcd, &cloud, &f64_opts);
    assert_eq!(
        read(CloudFormat::Pcd, &bytes, &ReadOptions::default()),
        cloud
    );
}

#[test]
fn inconsistent_cloud_is_refused_and_leaves_no_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.ply");
    std::fs::write(&path, b"previous").unwrap();
    let mut cloud = PointCloud::from_points(vec![Point3::origin(); 3]);
    cloud.labels = Some(vec![1]);
    let e = write_cloud(&path, &cloud, &WriteOptions::default()).unwrap_err();
    assert!(matches!(e.kind, CloudIoErrorKind::InvalidCloud(_)), "{e}");
    assert!(
        e.to_string().starts_with(&path.display().to_string()),
        "{e}"
    );
    // The old file is untouched and no temporary file is left behind.
    assert_eq!(std::fs::read(&path).unwrap(), b"previous");
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
}

#[test]
fn files_dispatch_on_extension_and_are_byte_identical() {
    let dir = tempfile::tempdir().unwrap();
    let mut cloud =
        PointCloud::from_points(vec![Point3::new(0.1, 0.2, 0.3), Point3::new(1.0, 2.0, 3.0)]);
    cloud.views = Some(vec![0, 1]);
    for name in ["a.ply", "b.PCD"] {
        let path = dir.path().join(name);
        let opts = WriteOptions {
            encoding: Encoding::Ascii,
            float: FloatType::F64,
        };
        write_cloud(&path, &cloud, &opts).unwrap();
        let first = std::fs::read(&path).unwrap();
        write_cloud(&path, &cloud, &opts).unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), first);
        assert_eq!(read_cloud(&path).unwrap(), cloud);
        let file = read_cloud_with(&path, &ReadOptions::default()).unwrap();
        assert_eq!((file.width, file.height), (2, 1));
    }
    let e = write_cloud(dir.path().join("c.xyz"), &cloud, &WriteOptions::default()).unwrap_err();
    assert!(matches!(e.kind, CloudIoErrorKind::UnknownExtension { .. }));
    let e = read_cloud(dir.path().join("missing.ply")).unwrap_err();
    assert!(matches!(e.kind, CloudIoErrorKind::Io(_)));
    assert!(e.to_string().contains("missing.ply"), "{e}");
    let e = write_cloud(
        dir.path().join("no/such/dir/x.pcd"),
        &cloud,
        &WriteOptions::default(),
    )
    .unwrap_err();
    assert!(matches!(e.kind, CloudIoErrorKind::Io(_)));
    let e = write_ply(
        &mut Vec::new(),
        &cloud,
        &WriteOptions {
            encoding: Encoding::BinaryCompressed,
            ..Default::default()
        },
    )
    .unwrap_err();
    assert!(matches!(e.kind, CloudIoErrorKind::Unsupported(_)));
}

#[test]
fn written_headers_match_the_documented_names() {
    let mut cloud = PointCloud::from_points(vec![Point3::origin()]);
    cloud.origins = Some(vec![Point3::origin()]);
    cloud.normals = Some(vec![Vector3::z()]);
    cloud.labels = Some(vec![1]);
    cloud.views = Some(vec![2]);
    cloud.truth = Some(vec![Point3::origin()]);
    let ply = String::from_utf8_lossy(&write(CloudFormat::Ply, &cloud, &WriteOptions::default()))
        .into_owned();
    let props: Vec<&str> = ply.lines().filter(|l| l.starts_with("property")).collect();
    assert_eq!(
        props,
        [
            "property float x",
            "property float y",
            "property float z",
            "property float nx",
            "property float ny",
            "property float nz",
            "property float ox",
            "property float oy",
            "property float oz",
            "property uint label",
            "property uint view",
            "property float tx",
            "property float ty",
            "property float tz",
        ]
    );
    assert!(
        ply.starts_with("ply\nformat binary_little_endian 1.0\ncomment generated by nbv-twin\n")
    );
    let pcd = String::from_utf8_lossy(&write(
        CloudFormat::Pcd,
        &cloud,
        &WriteOptions {
            encoding: Encoding::Ascii,
            float: FloatType::F64,
        },
    ))
    .into_owned();
    let header: Vec<&str> = pcd.lines().take(11).collect();
    assert_eq!(
        header,
        [
            "# .PCD v0.7 - Point Cloud Data file format",
            "VERSION 0.7",
            "FIELDS x y z normal_x normal_y normal_z vp_x vp_y vp_z label view tx ty tz",
            "SIZE 8 8 8 8 8 8 8 8 8 4 4 8 8 8",
            "TYPE F F F F F F F F F U U F F F",
            "COUNT 1 1 1 1 1 1 1 1 1 1 1 1 1 1",
            "WIDTH 1",
            "HEIGHT 1",
            "VIEWPOINT 0 0 0 1 0 0 0",
            "POINTS 1",
            "DATA ascii",
        ]
    );
    assert_eq!(pcd.lines().nth(11), Some("0 0 0 0 0 1 0 0 0 1 2 0 0 0"));
}
