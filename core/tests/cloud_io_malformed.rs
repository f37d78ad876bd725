//! Malformed files: each gives a typed error at the right place (never a panic), huge
//! declared counts are refused before any allocation, and random bytes or random damage to
//! valid files never panic.

use nalgebra::Point3;
use nbv_core::cloud::PointCloud;
use nbv_core::cloud::io::{
    CloudIoError, CloudIoErrorKind as K, Encoding, Location, ReadOptions, WriteOptions,
    decode_depth_png, read_pcd, read_ply, write_pcd, write_ply,
};
use proptest::prelude::*;

fn ply_err(bytes: &[u8]) -> CloudIoError {
    read_ply(bytes, &ReadOptions::default()).unwrap_err()
}

fn pcd_err(bytes: &[u8]) -> CloudIoError {
    read_pcd(bytes, &ReadOptions::default()).unwrap_err()
}

const PLY_ASCII: &str = "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n\
property float z\nend_header\n";

#[test]
fn ascii_ply_errors_name_the_line() {
    let e = ply_err(format!("{PLY_ASCII}1 2 3\n").as_bytes());
    assert!(
        matches!(
            e.kind,
            K::MissingRecords {
                expected: 2,
                found: 1,
                ..
            }
        ),
        "{e}"
    );
    assert_eq!(e.location, Location::Line(9));

    let e = ply_err(format!("{PLY_ASCII}1 2 3\n4 5\n").as_bytes());
    assert!(
        matches!(
            e.kind,
            K::ValueCount {
                expected: 3,
                found: 2
            }
        ),
        "{e}"
    );
    assert_eq!(e.location, Location::Line(9));
    assert_eq!(
        e.to_string(),
        "<stream>, line 9: expected 3 values on the line, found 2"
    );

    let e = ply_err(format!("{PLY_ASCII}1 2 3\n4 5 six\n").as_bytes());
    assert!(
        matches!(&e.kind, K::BadValue { token, .. } if token == "six"),
        "{e}"
    );

    let e = ply_err(format!("{PLY_ASCII}1 2 3\n4 5 6\n7 8 9\n").as_bytes());
    assert!(matches!(e.kind, K::TrailingData { .. }), "{e}");
    assert_eq!(e.location, Location::Line(10));

    let e = ply_err(format!("{PLY_ASCII}1 2 3\n4 5 6 7\n").as_bytes());
    assert!(
        matches!(
            e.kind,
            K::ValueCount {
                expected: 3,
                found: 4
            }
        ),
        "{e}"
    );
}

#[test]
fn header_problems() {
    let e = ply_err(b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n");
    assert!(matches!(e.kind, K::MissingHeaderEnd { .. }), "{e}");
    let e = ply_err(b"ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float y\nend_header\n");
    assert!(matches!(e.kind, K::Header(_)), "{e}");
    let e = ply_err(b"ply\nformat ascii 1.0\nelement face 0\nend_header\n");
    assert!(e.to_string().contains("no `vertex` element"), "{e}");
    let e = ply_err(
        b"ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float y\nproperty float z\n\
property float nx\nproperty float normal_x\nend_header\n",
    );
    assert!(matches!(e.kind, K::Header(_)), "{e}");
    let e = ply_err(b"\x89PNG\r\n\x1a\n");
    assert!(matches!(e.kind, K::BadMagic { .. }), "{e}");
    let e = pcd_err(b"ply\n");
    assert!(matches!(e.kind, K::BadMagic { .. }), "{e}");
    let e = pcd_err(b"VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 2\nHEIGHT 2\nPOINTS 3\nDATA ascii\n");
    assert!(e.to_string().contains("does not equal POINTS"), "{e}");
    let e = pcd_err(b"VERSION 0.7\nFIELDS x y z\nSIZE 4 4\nTYPE F F F\nWIDTH 1\nDATA ascii\n");
    assert_eq!(e.location, Location::Line(3));
    let e = pcd_err(b"VERSION 0.7\nFIELDS x y z\nSIZE 4 4 2\nTYPE F F F\nWIDTH 1\nDATA ascii\n");
    assert!(e.to_string().contains("TYPE F with SIZE 2"), "{e}");
    let e = pcd_err(b"VERSION 0.8\nFIELDS x y z\n");
    assert!(matches!(e.kind, K::Unsupported(_)), "{e}");
    let e = pcd_err(b"VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 1\nPOINTS 1\n");
    assert!(matches!(e.kind, K::MissingHeaderEnd { .. }), "{e}");
    let e = pcd_err(b"VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 1\nVIEWPOINT 0 0 0 0 0 0 0\nDATA ascii\n1 2 3\n");
    assert!(e.to_string().contains("quaternion"), "{e}");
}

#[test]
fn binary_ply_truncation_names_byte_and_record() {
    let cloud = PointCloud::from_points(vec![Point3::new(1.0, 2.0, 3.0); 10]);
    let mut bytes = Vec::new();
    write_ply(&mut bytes, &cloud, &WriteOptions::default()).unwrap();
    let body = bytes.len() - 120;
    let header = bytes.len() - 10 * 12;
    let e = ply_err(&bytes[..bytes.len() - 5]);
    assert!(
        matches!(
            e.kind,
            K::Truncated {
                needed: 120,
                available: 115,
                ..
            }
        ),
        "{e}"
    );
    assert_eq!(
        e.location,
        Location::Byte {
            offset: (header + 9 * 12) as u64,
            record: Some(9)
        }
    );
    assert!(body > 0);
    // Extra bytes after the declared records.
    let mut longer = bytes.clone();
    longer.extend_from_slice(&[0; 12]);
    assert!(matches!(ply_err(&longer).kind, K::TrailingData { .. }));
}

#[test]
fn huge_declared_counts_are_refused_without_allocating() {
    let e = ply_err(
        b"ply\nformat binary_little_endian 1.0\nelement vertex 18446744073709551615\n\
property double x\nproperty double y\nproperty double z\nend_header\n\0\0\0",
    );
    assert!(
        matches!(
            e.kind,
            K::Truncated {
                needed: u64::MAX,
                available: 3,
                ..
            }
        ),
        "{e}"
    );
    // A list element whose records would each claim 4 G items.
    let e = ply_err(
        b"ply\nformat binary_little_endian 1.0\nelement vertex 0\nproperty float x\nproperty float y\n\
property float z\nelement face 1000000000\nproperty list uint int idx\nend_header\n\xff\xff\xff\xff\xff\xff\xff\xff",
    );
    assert!(matches!(e.kind, K::Truncated { .. }), "{e}");
    // ASCII: one record per line, so the count is checked as lines run out.
    let e = ply_err(
        b"ply\nformat ascii 1.0\nelement vertex 999999999999999\nproperty float x\nproperty float y\n\
property float z\nend_header\n1 2 3\n",
    );
    assert!(matches!(e.kind, K::MissingRecords { found: 1, .. }), "{e}");
    let e = pcd_err(b"VERSION 0.7\nFIELDS x y z\nSIZE 8 8 8\nTYPE F F F\nWIDTH 4294967295\nHEIGHT 4294967295\nDATA binary\n");
    assert!(matches!(e.kind, K::Truncated { .. }), "{e}");
    let e = pcd_err(b"VERSION 0.7\nFIELDS x y z h\nSIZE 4 4 4 8\nTYPE F F F F\nCOUNT 1 1 1 18446744073709551615\nWIDTH 1\nDATA binary\n");
    assert!(matches!(e.kind, K::Header(_)), "{e}");
    let e = pcd_err(b"VERSION 0.7\nFIELDS x y z h\nSIZE 4 4 4 8\nTYPE F F F F\nCOUNT 1 1 1 100000000000\nWIDTH 1\nDATA ascii\n1 2 3 4\n");
    assert!(matches!(e.kind, K::ValueCount { found: 4, .. }), "{e}");
    // Compressed: declared sizes checked against the file and LZF's best ratio.
    let mut f = b"VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 100000000\nDATA binary_compressed\n".to_vec();
    f.extend_from_slice(&4u32.to_le_bytes());
    f.extend_from_slice(&1_200_000_000u32.to_le_bytes());
    f.extend_from_slice(&[0; 4]);
    let e = pcd_err(&f);
    assert!(matches!(e.kind, K::Compressed(_)), "{e}");
}

#[test]
fn pcd_binary_and_compressed_damage() {
    let cloud = PointCloud::from_points((0..20).map(|i| Point3::new(i as f64, 0.0, 1.0)).collect());
    for encoding in [Encoding::Binary, Encoding::BinaryCompressed] {
        let mut bytes = Vec::new();
        write_pcd(
            &mut bytes,
            &cloud,
            &WriteOptions {
                encoding,
                ..Default::default()
            },
        )
        .unwrap();
        let e = pcd_err(&bytes[..bytes.len() - 1]);
        assert!(
            matches!(e.kind, K::Truncated { .. } | K::Compressed(_)),
            "{e}"
        );
        // PCL pads binary files with zeros to the page size: accepted.
        let mut padded = bytes.clone();
        padded.resize(4096, 0);
        let read = read_pcd(&padded[..], &ReadOptions::default()).unwrap();
        assert_eq!(read.cloud, cloud);
        // Anything else is a wrong count.
        let mut longer = bytes.clone();
        longer.extend_from_slice(&[0, 0, 7]);
        let e = pcd_err(&longer);
        assert!(matches!(e.kind, K::TrailingData { .. }), "{encoding:?}");
        assert_eq!(
            e.location,
            Location::Byte {
                offset: bytes.len() as u64 + 2,
                record: None
            }
        );
    }
}

#[test]
fn labels_must_be_u32_integers() {
    let e = ply_err(
        b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\n\
property float label\nend_header\n1 2 3 1.5\n",
    );
    assert!(
        matches!(
            e.kind,
            K::BadIndex {
                column: "label",
                ..
            }
        ),
        "{e}"
    );
    let e = ply_err(
        b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\n\
property int view\nend_header\n1 2 3 -4\n",
    );
    assert!(matches!(e.kind, K::BadIndex { column: "view", .. }), "{e}");
}

fn valid_files() -> Vec<(bool, Vec<u8>)> {
    let mut cloud = PointCloud::from_points(
        (0..6)
            .map(|i| Point3::new(i as f64 * 0.5, -1.0, 2.0))
            .collect(),
    );
    cloud.labels = Some(vec![1, 2, 3, 4, 5, 6]);
    cloud.origins = Some(vec![Point3::origin(); 6]);
    let mut out = Vec::new();
    for encoding in [
        Encoding::Ascii,
        Encoding::Binary,
        Encoding::BinaryCompressed,
    ] {
        let opts = WriteOptions {
            encoding,
            ..Default::default()
        };
        if encoding != Encoding::BinaryCompressed {
            let mut b = Vec::new();
            write_ply(&mut b, &cloud, &opts).unwrap();
            out.push((true, b));
        }
        let mut b = Vec::new();
        write_pcd(&mut b, &cloud, &opts).unwrap();
        out.push((false, b));
    }
    out
}

fn read_any(bytes: &[u8]) {
    // Whatever the outcome, it must be a value, not a panic; successes must be consistent.
    for r in [
        read_ply(bytes, &ReadOptions::default()),
        read_pcd(bytes, &ReadOptions::default()),
    ]
    .into_iter()
    .flatten()
    {
        let c = r.cloud;
        let n = c.len();
        assert!(c.labels.as_ref().is_none_or(|l| l.len() == n));
        assert!(c.origins.as_ref().is_none_or(|l| l.len() == n));
        assert_eq!(c.validate(), Ok(()));
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(400))]

    #[test]
    fn random_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..400)) {
        read_any(&bytes);
        let _ = decode_depth_png(&bytes, 0.001);
    }

    #[test]
    fn random_text_headers_never_panic(
        prefix in prop_oneof![Just("ply\nformat ascii 1.0\n"), Just("ply\nformat binary_little_endian 1.0\n"), Just("VERSION 0.7\n")],
        lines in proptest::collection::vec("(element|property|list|FIELDS|SIZE|TYPE|COUNT|WIDTH|HEIGHT|POINTS|DATA|VIEWPOINT|end_header|vertex|float|uchar|int|x|y|z|ascii|binary|binary_compressed|F|U|I|1|4|8|0|-1|99999999999| |\n){1,12}", 0..12),
        tail in proptest::collection::vec(any::<u8>(), 0..64),
    ) {
        let mut bytes = prefix.as_bytes().to_vec();
        for l in lines {
            bytes.extend_from_slice(l.as_bytes());
            bytes.push(b'\n');
        }
        bytes.extend_from_slice(&tail);
        read_any(&bytes);
    }

    #[test]
    fn damaged_valid_files_never_panic(
        which in 0usize..5,
        cut in any::<prop::sample::Index>(),
        flips in proptest::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 0..6),
        truncate in any::<bool>(),
    ) {
        let files = valid_files();
        let (_, mut bytes) = files[which % files.len()].clone();
        for (at, v) in flips {
            let i = at.index(bytes.len());
            bytes[i] = v;
        }
        if truncate {
            bytes.truncate(cut.index(bytes.len() + 1));
        }
        read_any(&bytes);
    }
}
