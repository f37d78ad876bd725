//! Unknown fields of every type, size and count, placed anywhere among the known ones, are
//! skipped correctly in every encoding (PLY ASCII / little / big endian with scalar and list
//! properties; PCD ASCII / binary / binary_compressed with any TYPE, SIZE and COUNT).

use nalgebra::Point3;
use nbv_core::cloud::io::{ReadOptions, read_pcd, read_ply};
use proptest::prelude::*;

/// (PLY name, PCD TYPE, size) of every scalar type.
const TYPES: [(&str, &str, usize); 10] = [
    ("char", "I", 1),
    ("uchar", "U", 1),
    ("short", "I", 2),
    ("ushort", "U", 2),
    ("int", "I", 4),
    ("uint", "U", 4),
    ("float", "F", 4),
    ("double", "F", 8),
    ("int8", "I", 1),
    ("float64", "F", 8),
];

/// An unknown field: its type, and for PLY a list length type and length (PCD: count).
#[derive(Debug, Clone)]
struct Extra {
    ty: usize,
    list: Option<(usize, u8)>,
    count: usize,
    before: usize,
}

fn extra() -> impl Strategy<Value = Extra> {
    (
        0usize..10,
        proptest::option::of((0usize..6, 0u8..5)),
        1usize..5,
        0usize..4,
    )
        .prop_map(|(ty, list, count, before)| Extra {
            ty,
            list,
            count,
            before,
        })
}

/// Bytes of a value 1 of the given type (any bit pattern would do; 1 is valid text too).
fn one(ty: usize, big_endian: bool) -> Vec<u8> {
    let (name, _, _) = TYPES[ty];
    let mut b = match name {
        "char" | "int8" => vec![1u8],
        "uchar" => vec![1],
        "short" => 1i16.to_le_bytes().to_vec(),
        "ushort" => 1u16.to_le_bytes().to_vec(),
        "int" => 1i32.to_le_bytes().to_vec(),
        "uint" => 1u32.to_le_bytes().to_vec(),
        "float" => 1f32.to_le_bytes().to_vec(),
        _ => 1f64.to_le_bytes().to_vec(),
    };
    if big_endian {
        b.reverse();
    }
    b
}

fn len_bytes(ty: usize, n: u8, big_endian: bool) -> Vec<u8> {
    let mut b = match TYPES[ty].0 {
        "char" | "int8" | "uchar" => vec![n],
        "short" | "ushort" => u16::from(n).to_le_bytes().to_vec(),
        _ => u32::from(n).to_le_bytes().to_vec(),
    };
    if big_endian {
        b.reverse();
    }
    b
}

fn points() -> Vec<Point3<f64>> {
    vec![
        Point3::new(0.5, -2.0, 3.25),
        Point3::new(1.0, 2.0, 4.0),
        Point3::new(-8.0, 0.0, 0.125),
    ]
}

/// Field order: extras with `before == k` go before the k-th of x y z (3: after z).
fn layout(extras: &[Extra]) -> Vec<Result<usize, usize>> {
    let mut out = Vec::new();
    for k in 0..4 {
        for (i, e) in extras.iter().enumerate() {
            if e.before == k {
                out.push(Err(i));
            }
        }
        if k < 3 {
            out.push(Ok(k));
        }
    }
    out
}

fn ply_file(extras: &[Extra], format: &str) -> Vec<u8> {
    let be = format == "binary_big_endian";
    let mut f = format!("ply\nformat {format} 1.0\nelement vertex 3\n");
    let order = layout(extras);
    for slot in &order {
        match slot {
            Ok(k) => f.push_str(&format!("property float {}\n", ["x", "y", "z"][*k])),
            Err(i) => {
                let e = &extras[*i];
                let ty = TYPES[e.ty].0;
                match e.list {
                    Some((lt, _)) => f.push_str(&format!(
                        "property list {} {ty} extra{i}\n",
                        ["uchar", "char", "ushort", "short", "uint", "int"][lt]
                    )),
                    None => f.push_str(&format!("property {ty} extra{i}\n")),
                }
            }
        }
    }
    f.push_str("end_header\n");
    let mut bytes = f.into_bytes();
    let list_ty = |lt: usize| [1usize, 0, 3, 2, 5, 4][lt];
    for p in points() {
        let mut line: Vec<String> = Vec::new();
        for slot in &order {
            match slot {
                Ok(k) => {
                    let v = p[*k] as f32;
                    if format == "ascii" {
                        line.push(v.to_string());
                    } else {
                        let mut b = v.to_le_bytes();
                        if be {
                            b.reverse();
                        }
                        bytes.extend_from_slice(&b);
                    }
                }
                Err(i) => {
                    let e = &extras[*i];
                    let n = e.list.map(|(_, n)| n);
                    if format == "ascii" {
                        if let Some(n) = n {
                            line.push(n.to_string());
                        }
                        for _ in 0..n.map_or(1, usize::from) {
                            line.push("1".into());
                        }
                    } else {
                        if let Some((lt, n)) = e.list {
                            bytes.extend_from_slice(&len_bytes(list_ty(lt), n, be));
                        }
                        for _ in 0..n.map_or(1, usize::from) {
                            bytes.extend_from_slice(&one(e.ty, be));
                        }
                    }
                }
            }
        }
        if format == "ascii" {
            bytes.extend_from_slice(line.join(" ").as_bytes());
            bytes.push(b'\n');
        }
    }
    bytes
}

fn pcd_file(extras: &[Extra], data: &str) -> Vec<u8> {
    let order = layout(extras);
    let (mut names, mut sizes, mut types, mut counts) = (vec![], vec![], vec![], vec![]);
    for slot in &order {
        match slot {
            Ok(k) => {
                names.push(["x", "y", "z"][*k].to_string());
                sizes.push("4".to_string());
                types.push("F".to_string());
                counts.push("1".to_string());
            }
            Err(i) => {
                let (_, t, s) = TYPES[extras[*i].ty];
                names.push(if i % 2 == 0 {
                    "_".into()
                } else {
                    format!("extra{i}")
                });
                sizes.push(s.to_string());
                types.push(t.to_string());
                counts.push(extras[*i].count.to_string());
            }
        }
    }
    let mut bytes = format!(
        "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS {}\nSIZE {}\nTYPE {}\nCOUNT {}\n\
WIDTH 3\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 3\nDATA {data}\n",
        names.join(" "),
        sizes.join(" "),
        types.join(" "),
        counts.join(" ")
    )
    .into_bytes();
    let field_bytes = |slot: &Result<usize, usize>, p: &Point3<f64>| -> Vec<u8> {
        match slot {
            Ok(k) => (p[*k] as f32).to_le_bytes().to_vec(),
            Err(i) => one(extras[*i].ty, false).repeat(extras[*i].count),
        }
    };
    match data {
        "ascii" => {
            for p in points() {
                let mut line = Vec::new();
                for slot in &order {
                    match slot {
                        Ok(k) => line.push((p[*k] as f32).to_string()),
                        Err(i) => {
                            line.extend(std::iter::repeat_n("1".to_string(), extras[*i].count))
                        }
                    }
                }
                bytes.extend_from_slice(line.join(" ").as_bytes());
                bytes.push(b'\n');
            }
        }
        "binary" => {
            for p in points() {
                for slot in &order {
                    bytes.extend_from_slice(&field_bytes(slot, &p));
                }
            }
        }
        _ => {
            // Field-major, then an all-literal LZF stream (valid, if uncompressed).
            let mut raw = Vec::new();
            for slot in &order {
                for p in points() {
                    raw.extend_from_slice(&field_bytes(slot, &p));
                }
            }
            let mut lzf = Vec::new();
            for chunk in raw.chunks(32) {
                lzf.push((chunk.len() - 1) as u8);
                lzf.extend_from_slice(chunk);
            }
            bytes.extend_from_slice(&(lzf.len() as u32).to_le_bytes());
            bytes.extend_from_slice(&(raw.len() as u32).to_le_bytes());
            bytes.extend_from_slice(&lzf);
        }
    }
    bytes
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(96))]

    #[test]
    fn unknown_ply_properties_are_skipped(extras in proptest::collection::vec(extra(), 0..6)) {
        for format in ["ascii", "binary_little_endian", "binary_big_endian"] {
            let bytes = ply_file(&extras, format);
            let file = read_ply(&bytes[..], &ReadOptions::default())
                .map_err(|e| TestCaseError::fail(format!("{format}: {e}")))?;
            prop_assert_eq!(&file.cloud.points, &points(), "{}", format);
            prop_assert_eq!(file.ignored_fields.len(), extras.len());
        }
    }

    #[test]
    fn unknown_pcd_fields_are_skipped(extras in proptest::collection::vec(extra(), 0..6)) {
        for data in ["ascii", "binary", "binary_compressed"] {
            let bytes = pcd_file(&extras, data);
            let file = read_pcd(&bytes[..], &ReadOptions::default())
                .map_err(|e| TestCaseError::fail(format!("{data}: {e}")))?;
            prop_assert_eq!(&file.cloud.points, &points(), "{}", data);
            prop_assert_eq!(file.ignored_fields.len(), extras.len());
        }
    }
}
