//! The PLY reader: ASCII, binary little- and big-endian; the `vertex` element becomes the
//! cloud, every other element (faces, PCL's `camera`, ...) is checked and skipped.

use std::io::Read;

use super::columns::{CloudBuilder, FieldMap, ROLES, Record, Role};
use super::error::{CloudIoError, CloudIoErrorKind, Location, excerpt};
use super::non_finite::apply_policy;
use super::options::{CloudFile, ReadOptions};
use super::ply_header::{PlyElement, PlyFormat, PlyHeader, PlyKind, PlyProperty, parse_ply_header};
use super::text_lines::TextLines;
use crate::cloud::PointCloud;

/// Reads a PLY cloud from a stream (the whole stream is read; memory is bounded by its
/// length, never by the counts the header declares).
///
/// ```
/// use nbv_core::cloud::io::{read_ply, ReadOptions};
/// let text = "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n\
///             property float z\nproperty uchar red\nend_header\n1 2 3 255\n";
/// let file = read_ply(text.as_bytes(), &ReadOptions::default()).unwrap();
/// assert_eq!(file.cloud.points[0].z, 3.0);
/// assert_eq!(file.ignored_fields, ["red"]);
/// ```
pub fn read_ply(mut reader: impl Read, options: &ReadOptions) -> Result<CloudFile, CloudIoError> {
    let mut bytes = Vec::new();
    reader.read_to_end(&mut bytes).map_err(CloudIoError::io)?;
    parse_ply(&bytes, options)
}

/// Reads a PLY cloud from the bytes of a whole file.
pub(crate) fn parse_ply(bytes: &[u8], options: &ReadOptions) -> Result<CloudFile, CloudIoError> {
    let header = parse_ply_header(bytes)?;
    let Some(vertex) = header.elements.iter().position(|e| e.name == "vertex") else {
        return Err(CloudIoError::file(CloudIoErrorKind::Header(
            "no `vertex` element".into(),
        )));
    };
    let props = &header.elements[vertex].properties;
    let map = FieldMap::new(props.iter().map(|p| p.name.as_str())).map_err(CloudIoError::file)?;
    for (p, role) in props.iter().zip(&map.roles) {
        if role.is_some() && matches!(p.kind, PlyKind::List(..)) {
            return Err(CloudIoError::file(CloudIoErrorKind::Header(format!(
                "vertex property `{}` is a list; a scalar was expected",
                p.name
            ))));
        }
    }
    let cloud = match header.format {
        PlyFormat::Ascii => read_ascii(bytes, &header, vertex, &map)?,
        PlyFormat::BinaryLittleEndian => read_binary(bytes, &header, vertex, &map, false)?,
        PlyFormat::BinaryBigEndian => read_binary(bytes, &header, vertex, &map, true)?,
    };
    let mut file = CloudFile {
        width: cloud.len(),
        height: 1,
        cloud,
        viewpoint: None,
        dropped_non_finite: 0,
        ignored_fields: map.ignored,
    };
    apply_policy(&mut file, options.non_finite)?;
    Ok(file)
}

fn read_ascii(
    bytes: &[u8],
    header: &PlyHeader,
    vertex: usize,
    map: &FieldMap,
) -> Result<PointCloud, CloudIoError> {
    let mut lines = TextLines::new(bytes, header.body_offset, header.body_line);
    let mut builder = None;
    let mut tokens: Vec<&str> = Vec::new();
    for (ei, element) in header.elements.iter().enumerate() {
        if element.properties.is_empty() {
            continue;
        }
        let roles = (ei == vertex).then_some(&map.roles[..]);
        if roles.is_some() {
            // A record needs at least one character and one separator per value.
            let room =
                (bytes.len() - lines.pos().min(bytes.len())) / (2 * element.properties.len());
            let capacity = element.count.min(room as u64 + 1) as usize;
            builder = Some(CloudBuilder::new(map, capacity));
        }
        for found in 0..element.count {
            let Some(next) = lines.next_nonblank() else {
                return Err(CloudIoError::at(
                    Location::Line(lines.line()),
                    CloudIoErrorKind::MissingRecords {
                        element: element.name.clone(),
                        expected: element.count,
                        found,
                    },
                ));
            };
            let (n, text) = next?;
            tokens.clear();
            tokens.extend(text.split_ascii_whitespace());
            let mut rec = [0.0; ROLES];
            let at = |k| CloudIoError::at(Location::Line(n), k);
            decode_text_record(&element.properties, roles, &tokens, &mut rec).map_err(at)?;
            if let Some(b) = builder.as_mut().filter(|_| roles.is_some()) {
                b.push(&rec).map_err(at)?;
            }
        }
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
    Ok(builder.map_or_else(PointCloud::default, CloudBuilder::finish))
}

/// Decodes one ASCII record into `rec` (only the properties with a role are parsed; list
/// items are skipped).
fn decode_text_record(
    props: &[PlyProperty],
    roles: Option<&[Option<Role>]>,
    tokens: &[&str],
    rec: &mut Record,
) -> Result<(), CloudIoErrorKind> {
    let mut t = 0usize;
    for (k, p) in props.iter().enumerate() {
        let Some(tok) = tokens.get(t) else {
            return Err(text_value_count(props, tokens));
        };
        t += 1;
        match p.kind {
            PlyKind::Scalar(ty) => {
                if let Some(role) = roles.and_then(|r| r.get(k).copied().flatten()) {
                    rec[role.index()] =
                        ty.parse(tok).ok_or_else(|| CloudIoErrorKind::BadValue {
                            token: excerpt(tok),
                            expected: ty.describe(),
                        })?;
                }
            }
            PlyKind::List(len_ty, _) => {
                let len = len_ty
                    .parse_len(tok)
                    .ok_or_else(|| CloudIoErrorKind::BadValue {
                        token: excerpt(tok),
                        expected: "list length",
                    })?;
                t = usize::try_from(len)
                    .ok()
                    .and_then(|l| t.checked_add(l))
                    .filter(|&e| e <= tokens.len())
                    .ok_or_else(|| text_value_count(props, tokens))?;
            }
        }
    }
    if t != tokens.len() {
        return Err(text_value_count(props, tokens));
    }
    Ok(())
}

/// The value-count error for an ASCII record: how many values the properties (and the
/// list lengths present) call for, and how many there are.
fn text_value_count(props: &[PlyProperty], tokens: &[&str]) -> CloudIoErrorKind {
    let mut need = 0usize;
    for p in props {
        let tok = tokens.get(need).copied();
        need = need.saturating_add(1);
        if let PlyKind::List(len_ty, _) = p.kind {
            let len = tok.and_then(|t| len_ty.parse_len(t)).unwrap_or(0);
            need = need.saturating_add(usize::try_from(len).unwrap_or(usize::MAX));
        }
    }
    CloudIoErrorKind::ValueCount {
        expected: need,
        found: tokens.len(),
    }
}

fn truncated(
    offset: usize,
    record: u64,
    what: String,
    needed: u64,
    available: u64,
) -> CloudIoError {
    CloudIoError::at(
        Location::Byte {
            offset: offset as u64,
            record: Some(record),
        },
        CloudIoErrorKind::Truncated {
            what,
            needed,
            available,
        },
    )
}

fn read_binary(
    bytes: &[u8],
    header: &PlyHeader,
    vertex: usize,
    map: &FieldMap,
    big_endian: bool,
) -> Result<PointCloud, CloudIoError> {
    let mut pos = header.body_offset.min(bytes.len());
    let mut builder = None;
    for (ei, element) in header.elements.iter().enumerate() {
        let (min_size, fixed) = element.min_record_size();
        let available = (bytes.len() - pos) as u64;
        let needed = element.count.saturating_mul(min_size);
        if needed > available {
            let record = available / min_size.max(1);
            return Err(truncated(
                pos + (record * min_size) as usize,
                record,
                format!(
                    "{} `{}` records of {}{} bytes",
                    element.count,
                    element.name,
                    if fixed { "" } else { "at least " },
                    min_size
                ),
                needed,
                available,
            ));
        }
        // From here `count * min_size` fits in the remaining bytes (and in usize).
        let is_vertex = ei == vertex;
        if is_vertex {
            let mut b = CloudBuilder::new(map, element.count as usize);
            if fixed {
                read_fixed_records(bytes, pos, element, map, big_endian, &mut b)?;
                pos += needed as usize;
            } else {
                pos = walk_records(bytes, pos, element, Some((map, &mut b)), big_endian)?;
            }
            builder = Some(b);
        } else if fixed {
            pos += needed as usize;
        } else {
            pos = walk_records(bytes, pos, element, None, big_endian)?;
        }
    }
    if pos < bytes.len() {
        return Err(CloudIoError::at(
            Location::Byte {
                offset: pos as u64,
                record: None,
            },
            CloudIoErrorKind::TrailingData {
                detail: format!("{} bytes", bytes.len() - pos),
            },
        ));
    }
    Ok(builder.map_or_else(PointCloud::default, CloudBuilder::finish))
}

/// Decodes fixed-size vertex records whose total size was checked against the data.
fn read_fixed_records(
    bytes: &[u8],
    start: usize,
    element: &PlyElement,
    map: &FieldMap,
    big_endian: bool,
    builder: &mut CloudBuilder,
) -> Result<(), CloudIoError> {
    let mut fields = Vec::new();
    let mut offset = 0usize;
    for (p, role) in element.properties.iter().zip(&map.roles) {
        if let PlyKind::Scalar(ty) = p.kind {
            if let Some(role) = role {
                fields.push((offset, ty, role.index()));
            }
            offset += ty.size();
        }
    }
    let size = offset;
    let count = element.count as usize;
    let data = bytes.get(start..start + size * count).unwrap_or_default();
    let mut rec = [0.0; ROLES];
    for (i, chunk) in data.chunks_exact(size.max(1)).enumerate() {
        let at = |k| {
            CloudIoError::at(
                Location::Byte {
                    offset: (start + i * size) as u64,
                    record: Some(i as u64),
                },
                k,
            )
        };
        for &(off, ty, slot) in &fields {
            rec[slot] = chunk
                .get(off..)
                .and_then(|b| ty.decode(b, big_endian))
                .unwrap_or(f64::NAN);
        }
        builder.push(&rec).map_err(at)?;
    }
    Ok(())
}

/// Walks variable-size records (with list properties), bounds-checking every step; decodes
/// them into `target` if given. Returns the offset after the last record.
fn walk_records(
    bytes: &[u8],
    mut pos: usize,
    element: &PlyElement,
    mut target: Option<(&FieldMap, &mut CloudBuilder)>,
    big_endian: bool,
) -> Result<usize, CloudIoError> {
    let mut rec = [0.0; ROLES];
    for r in 0..element.count {
        let start = pos;
        let short = |pos: usize, what: &str, needed: u64| {
            truncated(
                start,
                r,
                format!("`{}` record {r} ({what})", element.name),
                needed,
                (bytes.len() - pos.min(bytes.len())) as u64,
            )
        };
        for (k, p) in element.properties.iter().enumerate() {
            match p.kind {
                PlyKind::Scalar(ty) => {
                    let v = bytes
                        .get(pos..)
                        .and_then(|b| ty.decode(b, big_endian))
                        .ok_or_else(|| short(pos, &p.name, ty.size() as u64))?;
                    if let Some(role) = target
                        .as_ref()
                        .and_then(|(m, _)| m.roles.get(k).copied().flatten())
                    {
                        rec[role.index()] = v;
                    }
                    pos += ty.size();
                }
                PlyKind::List(len_ty, item) => {
                    let raw = bytes.get(pos..).unwrap_or_default();
                    if raw.len() < len_ty.size() {
                        return Err(short(pos, &p.name, len_ty.size() as u64));
                    }
                    let len = len_ty.decode_len(raw, big_endian).ok_or_else(|| {
                        CloudIoError::at(
                            Location::Byte {
                                offset: pos as u64,
                                record: Some(r),
                            },
                            CloudIoErrorKind::BadValue {
                                token: format!(
                                    "{}",
                                    len_ty.decode(raw, big_endian).unwrap_or(f64::NAN)
                                ),
                                expected: "list length",
                            },
                        )
                    })?;
                    pos += len_ty.size();
                    let skip = len.saturating_mul(item.size() as u64);
                    if skip > (bytes.len() - pos) as u64 {
                        return Err(short(pos, &p.name, skip));
                    }
                    pos += skip as usize;
                }
            }
        }
        if let Some((_, b)) = target.as_mut() {
            b.push(&rec).map_err(|k| {
                CloudIoError::at(
                    Location::Byte {
                        offset: start as u64,
                        record: Some(r),
                    },
                    k,
                )
            })?;
        }
    }
    Ok(pos)
}
