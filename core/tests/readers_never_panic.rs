//! The files users bring, on stable Rust (CI cannot run the cargo-fuzz targets in `fuzz/`):
//! the PLY and PCD cloud readers, the STL and OBJ mesh readers and the URDF loader get
//! arbitrary bytes and damaged valid files (truncations, byte flips, inserted garbage,
//! dropped lines, numbers replaced by NaN, infinities, negative or huge counts, wrong
//! types). None may panic (proptest reports a panic as a failure); what parses must be
//! consistent, and a parsed cloud must write back and re-read to the same file. Headers
//! that lie about their size must fail fast: the handcrafted cases declare 2^40 records or
//! more, which the process could not allocate (an attempt would abort the test binary).

use std::path::Path;

use nalgebra::Point3;
use nbv_core::cloud::PointCloud;
use nbv_core::cloud::io::{
    CloudIoErrorKind as K, Encoding, FloatType, ReadOptions, WriteOptions, read_cloud, read_pcd,
    read_ply, write_pcd, write_ply,
};
use nbv_core::kinematics::{Robot, UrdfError};
use nbv_core::mesh::TriMesh;
use nbv_core::mesh::io::{MeshIoError, obj_from_bytes, read_mesh, stl_from_bytes, stl_to_bytes};
use proptest::prelude::*;
use proptest::sample::Index;

/// The Comau URDF's text.
static URDF: std::sync::LazyLock<String> = std::sync::LazyLock::new(|| {
    std::fs::read_to_string(nbv_core::kinematics::COMAU_URDF).expect("the Comau URDF")
});

// ---------------------------------------------------------------------------------------
// Damage to a valid file.

/// Texts a number is replaced with: non-finite, negative, zero, huge, and wrong types.
const REPLACEMENTS: &[&str] = &[
    "nan",
    "inf",
    "-inf",
    "NaN",
    "-1",
    "0",
    "1e308",
    "-1e309",
    "4294967296",
    "1099511627776",
    "18446744073709551616",
    "\"x\"",
    "true",
    "[]",
    "",
];

/// One edit of a file's bytes.
#[derive(Debug, Clone)]
enum Edit {
    /// Set one byte.
    Flip(Index, u8),
    /// Insert bytes.
    Insert(Index, Vec<u8>),
    /// Remove up to `n` bytes.
    Delete(Index, usize),
    /// Cut the file.
    Truncate(Index),
    /// Remove one line.
    DropLine(Index),
    /// Repeat one line.
    RepeatLine(Index),
    /// Replace one number with one of [`REPLACEMENTS`].
    Number(Index, usize),
}

fn edit() -> impl Strategy<Value = Edit> {
    prop_oneof![
        (any::<Index>(), any::<u8>()).prop_map(|(i, b)| Edit::Flip(i, b)),
        (
            any::<Index>(),
            prop_oneof![
                proptest::collection::vec(any::<u8>(), 1..16),
                "[ -~\n]{1,24}".prop_map(String::into_bytes),
            ]
        )
            .prop_map(|(i, v)| Edit::Insert(i, v)),
        (any::<Index>(), 1usize..64).prop_map(|(i, n)| Edit::Delete(i, n)),
        any::<Index>().prop_map(Edit::Truncate),
        any::<Index>().prop_map(Edit::DropLine),
        any::<Index>().prop_map(Edit::RepeatLine),
        (any::<Index>(), 0..REPLACEMENTS.len()).prop_map(|(i, r)| Edit::Number(i, r)),
    ]
}

/// Byte ranges of the lines (with their `\n`).
fn lines(b: &[u8]) -> Vec<std::ops::Range<usize>> {
    let mut out = Vec::new();
    let mut start = 0;
    for (i, &c) in b.iter().enumerate() {
        if c == b'\n' {
            out.push(start..i + 1);
            start = i + 1;
        }
    }
    if start < b.len() {
        out.push(start..b.len());
    }
    out
}

/// Byte ranges of the numbers (`-`, digits, `.`, exponents) that start a token.
fn numbers(b: &[u8]) -> Vec<std::ops::Range<usize>> {
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        let starts = (b[i].is_ascii_digit() || b[i] == b'-')
            && (i == 0 || !b[i - 1].is_ascii_alphanumeric() && b[i - 1] != b'_');
        if starts {
            let mut j = i + 1;
            while j < b.len() && matches!(b[j], b'0'..=b'9' | b'.' | b'e' | b'E' | b'-' | b'+') {
                j += 1;
            }
            out.push(i..j);
            i = j;
        } else {
            i += 1;
        }
    }
    out
}

fn apply(bytes: &mut Vec<u8>, edit: &Edit) {
    match edit {
        Edit::Flip(i, b) if !bytes.is_empty() => {
            let i = i.index(bytes.len());
            bytes[i] = *b;
        }
        Edit::Insert(i, v) => {
            let i = i.index(bytes.len() + 1);
            bytes.splice(i..i, v.iter().copied());
        }
        Edit::Delete(i, n) if !bytes.is_empty() => {
            let i = i.index(bytes.len());
            let end = (i + n).min(bytes.len());
            bytes.drain(i..end);
        }
        Edit::Truncate(i) => bytes.truncate(i.index(bytes.len() + 1)),
        Edit::DropLine(i) | Edit::RepeatLine(i) => {
            let ls = lines(bytes);
            if !ls.is_empty() {
                let r = ls[i.index(ls.len())].clone();
                if matches!(edit, Edit::DropLine(_)) {
                    bytes.drain(r);
                } else {
                    let line = bytes[r.clone()].to_vec();
                    bytes.splice(r.start..r.start, line);
                }
            }
        }
        Edit::Number(i, k) => {
            let ns = numbers(bytes);
            if !ns.is_empty() {
                let r = ns[i.index(ns.len())].clone();
                bytes.splice(r, REPLACEMENTS[*k].bytes());
            }
        }
        _ => {}
    }
}

fn damaged(mut bytes: Vec<u8>, edits: &[Edit]) -> Vec<u8> {
    for e in edits {
        apply(&mut bytes, e);
    }
    bytes
}

fn edits() -> impl Strategy<Value = Vec<Edit>> {
    proptest::collection::vec(edit(), 1..5)
}

// ---------------------------------------------------------------------------------------
// Clouds.

fn sample_cloud() -> PointCloud {
    let n = 5;
    let mut cloud = PointCloud::from_points(
        (0..n)
            .map(|i| Point3::new(i as f64 * 0.25, -1.5, 2.0 + i as f64))
            .collect(),
    );
    cloud.labels = Some((0..n as u32).collect());
    cloud.views = Some(vec![7; n]);
    cloud.origins = Some(vec![Point3::new(0.0, 0.0, 1.0); n]);
    cloud.normals = Some(vec![nalgebra::Vector3::z(); n]);
    cloud
}

/// Valid PLY (ascii, binary) and PCD (ascii, binary, binary_compressed) files.
fn valid_clouds() -> Vec<(bool, Vec<u8>)> {
    let cloud = sample_cloud();
    let mut out = Vec::new();
    for encoding in [
        Encoding::Ascii,
        Encoding::Binary,
        Encoding::BinaryCompressed,
    ] {
        let o = WriteOptions {
            encoding,
            float: FloatType::F32,
        };
        if encoding != Encoding::BinaryCompressed {
            let mut b = Vec::new();
            write_ply(&mut b, &cloud, &o).unwrap();
            out.push((true, b));
        }
        let mut b = Vec::new();
        write_pcd(&mut b, &cloud, &o).unwrap();
        out.push((false, b));
    }
    out
}

/// Writes a parsed cloud back (lossless doubles) and re-reads it: the second file must be
/// the same bytes as the first (a fixpoint; NaN in columns the readers keep compares
/// equal this way).
fn round_trips(cloud: &PointCloud) {
    for encoding in [
        Encoding::Ascii,
        Encoding::Binary,
        Encoding::BinaryCompressed,
    ] {
        let o = WriteOptions {
            encoding,
            float: FloatType::F64,
        };
        type Write = fn(&mut Vec<u8>, &PointCloud, &WriteOptions) -> Result<(), ()>;
        let writers: [(Write, bool); 2] = [
            (|w, c, o| write_ply(w, c, o).map_err(|_| ()), true),
            (|w, c, o| write_pcd(w, c, o).map_err(|_| ()), false),
        ];
        for (write, ply) in writers {
            if ply && encoding == Encoding::BinaryCompressed {
                continue;
            }
            let mut first = Vec::new();
            write(&mut first, cloud, &o).expect("a parsed cloud writes");
            let again = if ply {
                read_ply(&first[..], &ReadOptions::default())
            } else {
                read_pcd(&first[..], &ReadOptions::default())
            }
            .unwrap_or_else(|e| panic!("a written cloud re-reads: {e}"));
            assert_eq!(again.cloud.len(), cloud.len());
            let mut second = Vec::new();
            write(&mut second, &again.cloud, &o).unwrap();
            assert!(first == second, "write → read → write changed the file");
        }
    }
}

/// Reads `bytes` as PLY and as PCD; successes must be consistent and round-trip.
fn read_cloud_bytes(bytes: &[u8]) {
    for r in [
        read_ply(bytes, &ReadOptions::default()),
        read_pcd(bytes, &ReadOptions::default()),
    ]
    .into_iter()
    .flatten()
    {
        assert_eq!(r.cloud.validate(), Ok(()));
        round_trips(&r.cloud);
    }
}

#[test]
fn cloud_headers_that_lie_about_their_size_are_refused() {
    let xyz = "property float x\nproperty float y\nproperty float z\n";
    // A small ASCII PLY declaring a million vertices.
    let ply = format!("ply\nformat ascii 1.0\nelement vertex 1000000\n{xyz}end_header\n1 2 3\n");
    let e = read_ply(ply.as_bytes(), &ReadOptions::default()).unwrap_err();
    assert!(
        matches!(
            e.kind,
            K::MissingRecords {
                found: 1,
                expected: 1_000_000,
                ..
            }
        ),
        "{e}"
    );
    assert!(e.to_string().contains("line 9"), "{e}");
    // 2^40 vertices, ASCII and binary.
    for format in ["ascii", "binary_little_endian", "binary_big_endian"] {
        let ply = format!(
            "ply\nformat {format} 1.0\nelement vertex 1099511627776\n{xyz}end_header\n1 2 3\n"
        );
        let e = read_ply(ply.as_bytes(), &ReadOptions::default()).unwrap_err();
        assert!(
            matches!(e.kind, K::MissingRecords { .. } | K::Truncated { .. }),
            "{e}"
        );
    }
    // A face element with 2^40 records of 2^32-item lists.
    let mut ply = format!(
        "ply\nformat binary_little_endian 1.0\nelement vertex 0\n{xyz}element face 1099511627776\n\
         property list uint int vertex_indices\nend_header\n"
    )
    .into_bytes();
    ply.extend_from_slice(&[0xff; 4]);
    let e = read_ply(&ply[..], &ReadOptions::default()).unwrap_err();
    assert!(matches!(e.kind, K::Truncated { .. }), "{e}");
    // PCD: 2^40 points in every encoding, and WIDTH × HEIGHT overflowing.
    for data in ["ascii", "binary", "binary_compressed"] {
        let pcd = format!(
            "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 1099511627776\n\
             HEIGHT 1\nPOINTS 1099511627776\nDATA {data}\n1 2 3\n"
        );
        let e = read_pcd(pcd.as_bytes(), &ReadOptions::default()).unwrap_err();
        assert!(
            matches!(
                e.kind,
                K::MissingRecords { .. } | K::Truncated { .. } | K::Compressed(_)
            ),
            "{data}: {e}"
        );
    }
    let pcd = "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 18446744073709551615\n\
               HEIGHT 2\nDATA binary\n";
    let e = read_pcd(pcd.as_bytes(), &ReadOptions::default()).unwrap_err();
    assert!(e.to_string().contains("WIDTH"), "{e}");
}

#[test]
fn cloud_errors_name_the_file_line_and_problem() {
    let dir = tempfile::tempdir().unwrap();
    let cases: [(&str, &str, &[&str]); 5] = [
        (
            "nan.ply",
            "ply\nformat ascii 1.0\nelement vertex 1\nproperty uchar x\nproperty float y\n\
             property float z\nend_header\nnan 1 2\n",
            &["nan.ply", "line 8", "`nan`", "8-bit unsigned"],
        ),
        (
            "count.ply",
            "ply\nformat ascii 1.0\nelement vertex -3\nend_header\n",
            &["count.ply", "line 3", "`-3`"],
        ),
        (
            "fields.pcd",
            "VERSION 0.7\nFIELDS x y\nSIZE 4 4\nTYPE F F\nWIDTH 1\nDATA ascii\n1 2\n",
            &["fields.pcd", "x, y and z"],
        ),
        (
            "size.pcd",
            "VERSION 0.7\nFIELDS x y z\nSIZE 4 4\nTYPE F F F\nWIDTH 1\nDATA ascii\n1 2 3\n",
            &["size.pcd", "line 3", "SIZE has 2 values"],
        ),
        (
            "extra.pcd",
            "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 1\nDATA ascii\n1 2 3\n4 5 6\n",
            &["extra.pcd", "line 8", "wrong count"],
        ),
    ];
    for (name, text, wanted) in cases {
        let path = dir.path().join(name);
        std::fs::write(&path, text).unwrap();
        let e = read_cloud(&path).unwrap_err().to_string();
        for w in wanted {
            assert!(e.contains(w), "{name}: `{e}` does not mention {w}");
        }
    }
}

#[test]
fn valid_clouds_round_trip() {
    for (ply, bytes) in valid_clouds() {
        let f = if ply {
            read_ply(&bytes[..], &ReadOptions::default())
        } else {
            read_pcd(&bytes[..], &ReadOptions::default())
        }
        .unwrap();
        assert_eq!(f.cloud, sample_cloud());
        round_trips(&f.cloud);
    }
}

// ---------------------------------------------------------------------------------------
// Meshes.

fn valid_stl() -> Vec<Vec<u8>> {
    let binary = stl_to_bytes(&TriMesh::cuboid([0.1, 0.2, 0.3]));
    let ascii = b"solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n\
vertex 0 1 0\nendloop\nendfacet\nfacet normal 0 0 1\nouter loop\nvertex 1 0 0\nvertex 1 1 0\n\
vertex 0 1 0\nendloop\nendfacet\nendsolid t\n"
        .to_vec();
    vec![binary, ascii]
}

const OBJ: &str = "# tetrahedron\no tet\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nvn 0 0 1\n\
vt 0 0\nusemtl none\ns off\nf 1/1/1 3/1/1 2/1/1\nf 1 2 4\nf 1 4 3\nf 2 3 4 1\ng other\n\
v 2 2 2\nv 3 2 2\nv 2 3 2\nf -3 -2 -1\n";

/// A mesh that parsed must be usable: finite vertices, indices in range, some triangles.
fn check_mesh(m: &TriMesh) {
    assert!(!m.triangles.is_empty());
    assert!(
        m.vertices
            .iter()
            .all(|p| p.coords.iter().all(|c| c.is_finite()))
    );
    let n = m.vertices.len();
    assert!(m.triangles.iter().flatten().all(|&i| (i as usize) < n));
}

/// A parsed STL mesh must also write back to bytes that re-read to the same mesh.
fn check_stl(m: &TriMesh) {
    check_mesh(m);
    let bytes = stl_to_bytes(m);
    let again = stl_from_bytes(&bytes, Path::new("again.stl")).expect("a written mesh reads");
    assert_eq!(again.triangles.len(), m.triangles.len());
    assert!(
        stl_to_bytes(&again) == bytes,
        "write → read → write changed the file"
    );
}

#[test]
fn mesh_errors_name_the_file_and_problem() {
    // A binary STL claiming 2^32 - 1 triangles and holding one.
    let mut stl = stl_to_bytes(&TriMesh::cuboid([1.0; 3]));
    stl.truncate(84 + 50);
    stl[80..84].copy_from_slice(&u32::MAX.to_le_bytes());
    let e = stl_from_bytes(&stl, Path::new("lie.stl")).unwrap_err();
    assert!(matches!(e, MeshIoError::Stl { .. }), "{e}");
    assert!(e.to_string().starts_with("lie.stl: malformed STL"), "{e}");

    let nan = b"solid t\nfacet normal 0 0 1\nouter loop\nvertex nan 0 0\nvertex 1 0 0\n\
vertex 0 1 0\nendloop\nendfacet\nendsolid t\n";
    let e = stl_from_bytes(nan, Path::new("nan.stl")).unwrap_err();
    assert!(matches!(e, MeshIoError::Stl { .. }), "{e}");
    assert!(e.to_string().starts_with("nan.stl: malformed STL"), "{e}");
    assert!(e.to_string().contains("NaN"), "{e}");

    let cases: [(&str, &str); 5] = [
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n", "index.obj: "),
        (
            "v 0 0 0\nv 1 0 0\nv inf 1 0\nf 1 2 3\n",
            "index.obj: vertex 2 is not finite",
        ),
        (
            "v 0 0 0\nv 1 0 0\nv x 1 0\nf 1 2 3\n",
            "index.obj: malformed OBJ",
        ),
        ("v 0 0 0\n", "index.obj: the mesh has no triangle"),
        ("f 1 2 3\n", "index.obj: "),
    ];
    for (text, prefix) in cases {
        let e = obj_from_bytes(text.as_bytes(), Path::new("index.obj")).unwrap_err();
        assert!(e.to_string().starts_with(prefix), "{text:?}: {e}");
    }
    // Through a file: the error names the path.
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.obj");
    std::fs::write(&path, "v 0 0 0\nf 1 1 7\n").unwrap();
    let e = read_mesh(&path).unwrap_err();
    assert!(
        e.to_string().starts_with(&path.display().to_string()),
        "{e}"
    );
    for stl in valid_stl() {
        check_stl(&stl_from_bytes(&stl, Path::new("ok.stl")).unwrap());
    }
    let m = obj_from_bytes(OBJ.as_bytes(), Path::new("ok.obj")).unwrap();
    check_mesh(&m);
    assert_eq!(m.triangles.len(), 6);
}

// ---------------------------------------------------------------------------------------
// URDF.

#[test]
fn urdf_errors_name_the_file_and_item() {
    let dir = tempfile::tempdir().unwrap();
    let cases: [(&str, String, &[&str]); 5] = [
        (
            "cut.urdf",
            URDF[..URDF.len() / 2].to_owned(),
            &["cut.urdf", "not a valid URDF"],
        ),
        (
            "parent.urdf",
            URDF.replacen(
                "<parent link=\"base_link\"/>",
                "<parent link=\"nowhere\"/>",
                1,
            ),
            &["parent.urdf", "`nowhere`", "not defined"],
        ),
        (
            "limit.urdf",
            URDF.replacen("upper=\"", "upper=\"-100", 1),
            &["limit.urdf", "joint `joint_1`", "lower"],
        ),
        (
            "nan.urdf",
            URDF.replacen("<origin xyz=\"0 0 0\"", "<origin xyz=\"nan 0 0\"", 1),
            &["nan.urdf", "non-finite"],
        ),
        (
            "type.urdf",
            URDF.replacen("type=\"revolute\"", "type=\"prismatic\"", 1),
            &["type.urdf", "prismatic"],
        ),
    ];
    for (name, text, wanted) in cases {
        assert_ne!(text, *URDF, "{name}: the edit did not apply");
        let path = dir.path().join(name);
        std::fs::write(&path, &text).unwrap();
        let e = Robot::from_urdf_file(&path).unwrap_err().to_string();
        for w in wanted {
            assert!(e.contains(w), "{name}: `{e}` does not mention {w}");
        }
    }
    let e = Robot::from_urdf_str("<robot name='r'><link name='a'/><link name='a'/></robot>");
    assert!(
        matches!(e, Err(UrdfError::Duplicate { kind: "link", .. })),
        "{e:?}"
    );
}

// ---------------------------------------------------------------------------------------
// Properties.

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn arbitrary_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..512)) {
        read_cloud_bytes(&bytes);
        if let Ok(m) = stl_from_bytes(&bytes, Path::new("f.stl")) {
            check_stl(&m);
        }
        if let Ok(m) = obj_from_bytes(&bytes, Path::new("f.obj")) {
            check_mesh(&m);
        }
        let _ = Robot::from_urdf_str(&String::from_utf8_lossy(&bytes));
    }

    #[test]
    fn damaged_clouds_never_panic(which in any::<Index>(), edits in edits()) {
        let files = valid_clouds();
        let (_, bytes) = files[which.index(files.len())].clone();
        read_cloud_bytes(&damaged(bytes, &edits));
    }

    #[test]
    fn damaged_meshes_never_panic(which in any::<Index>(), edits in edits()) {
        let files = valid_stl();
        let stl = damaged(files[which.index(files.len())].clone(), &edits);
        if let Ok(m) = stl_from_bytes(&stl, Path::new("f.stl")) {
            check_stl(&m);
        }
        let obj = damaged(OBJ.as_bytes().to_vec(), &edits);
        match obj_from_bytes(&obj, Path::new("f.obj")) {
            Ok(m) => check_mesh(&m),
            Err(e) => prop_assert!(e.to_string().starts_with("f.obj: "), "{}", e),
        }
    }

    #[test]
    fn damaged_urdf_never_panics(edits in edits()) {
        let text = damaged(URDF.as_bytes().to_vec(), &edits);
        if let Err(e) = Robot::from_urdf_str(&String::from_utf8_lossy(&text)) {
            prop_assert!(e.to_string().starts_with("<string>: "), "{}", e);
        }
    }
}

// ---------------------------------------------------------------------------------------
// The reconstruction-system layout's text files (`nbv fuse`).

/// A valid trajectory.log of two frames and a camera_intrinsic.json.
const TRAJECTORY: &str = "0 0 1\n1 0 0 0.5\n0 1 0 0\n0 0 1 0.25\n0 0 0 1\n\
                          1 1 2\n0 -1 0 0\n1 0 0 0.1\n0 0 1 0\n0 0 0 1\n";
const INTRINSICS: &str = r#"{"width": 320, "height": 240, "intrinsic_matrix": [190.7, 0, 0, 0, 190.7, 0, 159.5, 119.5, 1]}"#;

/// What parses is rigid poses and a camera; errors name the file.
fn check_layout_texts(trajectory: &[u8], intrinsics: &[u8]) {
    use nbv_core::surface::{parse_intrinsics, parse_trajectory};
    match parse_trajectory(&String::from_utf8_lossy(trajectory), Path::new("t.log")) {
        Ok(poses) => assert!(poses.iter().all(|p| {
            let m = p.to_homogeneous();
            m.iter().all(|x| x.is_finite())
                && (p.rotation.to_rotation_matrix().matrix().determinant() - 1.0).abs() < 1e-6
        })),
        Err(e) => assert!(e.to_string().starts_with("t.log line "), "{e}"),
    }
    match parse_intrinsics(&String::from_utf8_lossy(intrinsics), Path::new("k.json")) {
        Ok(k) => assert!(k.is_valid()),
        Err(e) => assert!(e.to_string().starts_with("k.json"), "{e}"),
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn damaged_layout_texts_never_panic(edits in edits(), bytes in proptest::collection::vec(any::<u8>(), 0..256)) {
        check_layout_texts(&damaged(TRAJECTORY.as_bytes().to_vec(), &edits), &damaged(INTRINSICS.as_bytes().to_vec(), &edits));
        check_layout_texts(&bytes, &bytes);
    }
}
