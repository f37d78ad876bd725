//! The PCD reader: `DATA ascii`, `binary` and `binary_compressed` (LZF), organised clouds,
//! and the `VIEWPOINT` policy (see the module documentation of [`crate::cloud::io`]).

use std::io::Read;

use nalgebra::{Isometry3, Point3, Quaternion, Translation3, UnitQuaternion};

use super::columns::{CloudBuilder, FieldMap, ROLES};
use super::error::{CloudIoError, CloudIoErrorKind, Location, excerpt};
use super::lzf::{MAX_RATIO, lzf_decompress};
use super::non_finite::apply_policy;
use super::options::{CloudFile, ReadOptions};
use super::pcd_header::{PcdData, PcdHeader, parse_pcd_header};
use super::scalar::ScalarType;
use super::text_lines::TextLines;
use crate::cloud::PointCloud;

/// Reads a PCD cloud from a stream (the whole stream is read; memory is bounded by its
/// length, never by the counts the header declares).
///
/// ```
/// use nbv_core::cloud::io::{read_pcd, ReadOptions, NonFinite};
/// let text = "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS x y z\n\
///             SIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 2\nHEIGHT 1\n\
///             VIEWPOINT 0 0 0 1 0 0 0\nPOINTS 2\nDATA ascii\n1 2 3\nnan nan nan\n";
/// let file = read_pcd(text.as_bytes(), &ReadOptions::default()).unwrap();
/// assert_eq!((file.cloud.len(), file.dropped_non_finite), (1, 1));
/// let keep = ReadOptions { non_finite: NonFinite::Keep };
/// assert_eq!(read_pcd(text.as_bytes(), &keep).unwrap().cloud.len(), 2);
/// ```
pub fn read_pcd(mut reader: impl Read, options: &ReadOptions) -> Result<CloudFile, CloudIoError> {
    let mut bytes = Vec::new();
    reader.read_to_end(&mut bytes).map_err(CloudIoError::io)?;
    parse_pcd(&bytes, options)
}

/// Reads a PCD cloud from the bytes of a whole file.
pub(crate) fn parse_pcd(bytes: &[u8], options: &ReadOptions) -> Result<CloudFile, CloudIoError> {
    let header = parse_pcd_header(bytes)?;
    let header_err = |msg: String| {
        CloudIoError::at(
            Location::Line(header.data_line),
            CloudIoErrorKind::Header(msg),
        )
    };
    let map = FieldMap::new(header.fields.iter().map(|f| f.name.as_str()))
        .map_err(|k| CloudIoError::at(Location::Line(header.data_line), k))?;
    for (f, role) in header.fields.iter().zip(&map.roles) {
        if role.is_some() && f.count != 1 {
            return Err(header_err(format!(
                "field `{}` has COUNT {}; expected 1",
                f.name, f.count
            )));
        }
    }
    let Some((record_size, values)) = header.record_size() else {
        return Err(header_err("the record size overflows".into()));
    };
    let mut cloud = match header.data {
        PcdData::Ascii => read_ascii(bytes, &header, &map, values)?,
        PcdData::Binary => read_binary(bytes, &header, &map, record_size)?,
        PcdData::BinaryCompressed => read_compressed(bytes, &header, &map, record_size)?,
    };
    let viewpoint = match header.viewpoint {
        None => None,
        Some([tx, ty, tz, qw, qx, qy, qz]) => {
            let q = Quaternion::new(qw, qx, qy, qz);
            if q.norm().is_nan() || q.norm() <= 1e-9 {
                return Err(header_err("VIEWPOINT quaternion is zero".into()));
            }
            Some(Isometry3::from_parts(
                Translation3::new(tx, ty, tz),
                UnitQuaternion::from_quaternion(q),
            ))
        }
    };
    if let Some(v) = viewpoint.filter(|v| !is_identity(v))
        && cloud.origins.is_none()
    {
        let o = Point3::from(v.translation.vector);
        cloud.origins = Some(vec![o; cloud.len()]);
    }
    let mut file = CloudFile {
        cloud,
        width: usize::try_from(header.width).unwrap_or(usize::MAX),
        height: usize::try_from(header.height).unwrap_or(usize::MAX),
        viewpoint,
        dropped_non_finite: 0,
        ignored_fields: map.ignored,
    };
    apply_policy(&mut file, options.non_finite)?;
    Ok(file)
}

/// Whether a viewpoint is PCL's default `0 0 0 1 0 0 0` (no sensor pose recorded).
fn is_identity(v: &Isometry3<f64>) -> bool {
    v.translation.vector == nalgebra::Vector3::zeros() && v.rotation.angle() < 1e-12
}

/// Fields with a role: (byte offset in an AoS record, type, record slot, field index).
fn mapped_fields(header: &PcdHeader, map: &FieldMap) -> Vec<(usize, ScalarType, usize, usize)> {
    let mut out = Vec::new();
    let mut offset = 0usize;
    for (k, (f, role)) in header.fields.iter().zip(&map.roles).enumerate() {
        if let Some(role) = role {
            out.push((offset, f.ty, role.index(), k));
        }
        offset = offset.saturating_add(
            f.ty.size()
                .saturating_mul(usize::try_from(f.count).unwrap_or(usize::MAX)),
        );
    }
    out
}

fn read_ascii(
    bytes: &[u8],
    header: &PcdHeader,
    map: &FieldMap,
    values: u64,
) -> Result<PointCloud, CloudIoError> {
    let mut lines = TextLines::new(bytes, header.body_offset, header.body_line);
    let room = (bytes.len() - lines.pos().min(bytes.len())) / (2 * header.fields.len().max(1));
    let mut builder = CloudBuilder::new(map, header.points.min(room as u64 + 1) as usize);
    // Token index of each field's first value (ASCII records are checked to have exactly
    // `values` tokens, so these indices are in range).
    let mut starts = Vec::with_capacity(header.fields.len());
    let mut t = 0u64;
    for f in &header.fields {
        starts.push(t);
        t += f.count;
    }
    let mut tokens: Vec<&str> = Vec::new();
    for found in 0..header.points {
        let Some(next) = lines.next_nonblank() else {
            return Err(CloudIoError::at(
                Location::Line(lines.line()),
                CloudIoErrorKind::MissingRecords {
                    element: "point".into(),
                    expected: header.points,
                    found,
                },
            ));
        };
        let (n, text) = next?;
        let at = |k| CloudIoError::at(Location::Line(n), k);
        tokens.clear();
        tokens.extend(text.split_ascii_whitespace());
        if tokens.len() as u64 != values {
            return Err(at(CloudIoErrorKind::ValueCount {
                expected: usize::try_from(values).unwrap_or(usize::MAX),
                found: tokens.len(),
            }));
        }
        let mut rec = [0.0; ROLES];
        for (f, (role, &start)) in header.fields.iter().zip(map.roles.iter().zip(&starts)) {
            if let Some(role) = role {
                let tok = tokens.get(start as usize).copied().unwrap_or_default();
                rec[role.index()] = f.ty.parse(tok).ok_or_else(|| {
                    at(CloudIoErrorKind::BadValue {
                        token: excerpt(tok),
                        expected: f.ty.describe(),
                    })
                })?;
            }
        }
        builder.push(&rec).map_err(at)?;
    }
    if let Some(next) = lines.next_nonblank() {
        let (n, text) = next?;
        return Err(CloudIoError::at(
            Location::Line(n),
            CloudIoErrorKind::TrailingData {
                detail: format!("text `{}`", excerpt(text)),
            },
        ));
    }
    Ok(builder.finish())
}

fn byte_error(offset: usize, record: Option<u64>, kind: CloudIoErrorKind) -> CloudIoError {
    CloudIoError::at(
        Location::Byte {
            offset: offset as u64,
            record,
        },
        kind,
    )
}

/// Checks that `points` records of `record_size` bytes fit in `available` bytes at `pos`.
fn check_fits(
    pos: usize,
    available: usize,
    header: &PcdHeader,
    record_size: u64,
    what: &str,
) -> Result<usize, CloudIoError> {
    let needed = header.points.saturating_mul(record_size);
    if needed > available as u64 {
        let record = available as u64 / record_size.max(1);
        return Err(byte_error(
            pos + (record * record_size) as usize,
            Some(record),
            CloudIoErrorKind::Truncated {
                what: format!("{} {what} of {record_size} bytes", header.points),
                needed,
                available: available as u64,
            },
        ));
    }
    Ok(needed as usize)
}

/// Rejects data after the declared records, except zero bytes: PCL pads `binary` and
/// `binary_compressed` files with zeros (to a multiple of the memory-map page size).
fn trailing(bytes: &[u8], pos: usize) -> Result<(), CloudIoError> {
    let rest = bytes.get(pos..).unwrap_or_default();
    if let Some(k) = rest.iter().position(|&b| b != 0) {
        return Err(byte_error(
            pos + k,
            None,
            CloudIoErrorKind::TrailingData {
                detail: format!("{} non-zero bytes", rest.len() - k),
            },
        ));
    }
    Ok(())
}

fn read_binary(
    bytes: &[u8],
    header: &PcdHeader,
    map: &FieldMap,
    record_size: u64,
) -> Result<PointCloud, CloudIoError> {
    let pos = header.body_offset.min(bytes.len());
    let needed = check_fits(pos, bytes.len() - pos, header, record_size, "point records")?;
    let fields = mapped_fields(header, map);
    let size = record_size as usize;
    let mut builder = CloudBuilder::new(map, header.points as usize);
    let mut rec = [0.0; ROLES];
    let data = bytes.get(pos..pos + needed).unwrap_or_default();
    for (i, chunk) in data.chunks_exact(size.max(1)).enumerate() {
        for &(off, ty, slot, _) in &fields {
            rec[slot] = chunk
                .get(off..)
                .and_then(|b| ty.decode(b, false))
                .unwrap_or(f64::NAN);
        }
        builder
            .push(&rec)
            .map_err(|k| byte_error(pos + i * size, Some(i as u64), k))?;
    }
    trailing(bytes, pos + needed)?;
    Ok(builder.finish())
}

fn read_compressed(
    bytes: &[u8],
    header: &PcdHeader,
    map: &FieldMap,
    record_size: u64,
) -> Result<PointCloud, CloudIoError> {
    let pos = header.body_offset.min(bytes.len());
    let word = |at: usize| -> Result<usize, CloudIoError> {
        let b: [u8; 4] = bytes
            .get(at..at + 4)
            .and_then(|b| b.try_into().ok())
            .ok_or_else(|| {
                byte_error(
                    at,
                    None,
                    CloudIoErrorKind::Truncated {
                        what: "the compressed block sizes".into(),
                        needed: 8,
                        available: (bytes.len() - pos) as u64,
                    },
                )
            })?;
        Ok(u32::from_le_bytes(b) as usize)
    };
    let compressed = word(pos)?;
    let uncompressed = word(pos + 4)?;
    let start = pos + 8;
    let available = bytes.len() - start;
    if compressed > available {
        return Err(byte_error(
            start,
            None,
            CloudIoErrorKind::Truncated {
                what: "the compressed block".into(),
                needed: compressed as u64,
                available: available as u64,
            },
        ));
    }
    let expected = header.points.checked_mul(record_size);
    if expected != Some(uncompressed as u64) {
        return Err(byte_error(
            pos + 4,
            None,
            CloudIoErrorKind::Compressed(format!(
                "the block declares {uncompressed} bytes but POINTS × record size = {} × {record_size}",
                header.points
            )),
        ));
    }
    if uncompressed as u64 > compressed as u64 * MAX_RATIO {
        return Err(byte_error(
            pos,
            None,
            CloudIoErrorKind::Compressed(format!(
                "{compressed} compressed bytes cannot hold {uncompressed} bytes"
            )),
        ));
    }
    let data = if uncompressed == 0 {
        Vec::new()
    } else {
        lzf_decompress(&bytes[start..start + compressed], uncompressed)
            .map_err(|m| byte_error(start, None, CloudIoErrorKind::Compressed(m)))?
    };
    trailing(bytes, start + compressed)?;
    // Field-major layout: all points' values of field 0, then of field 1, ...
    let n = header.points as usize;
    let mut bases = Vec::with_capacity(header.fields.len());
    let mut base = 0usize;
    for f in &header.fields {
        bases.push(base);
        base += n * f.ty.size() * f.count as usize;
    }
    let fields: Vec<(usize, usize, ScalarType, usize)> = mapped_fields(header, map)
        .into_iter()
        .map(|(_, ty, slot, k)| {
            let stride = ty.size() * header.fields[k].count as usize;
            (bases[k], stride, ty, slot)
        })
        .collect();
    let mut builder = CloudBuilder::new(map, n);
    let mut rec = [0.0; ROLES];
    for i in 0..n {
        for &(base, stride, ty, slot) in &fields {
            rec[slot] = data
                .get(base + i * stride..)
                .and_then(|b| ty.decode(b, false))
                .unwrap_or(f64::NAN);
        }
        builder
            .push(&rec)
            .map_err(|k| CloudIoError::at(Location::Point(i), k))?;
    }
    Ok(builder.finish())
}
