//! The PLY header: format line, elements and their scalar or list properties, comments,
//! and where the body starts.

use super::error::{CloudIoError, CloudIoErrorKind, Location, excerpt};
use super::scalar::ScalarType;
use super::text_lines::TextLines;

/// Body encoding of a PLY file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum PlyFormat {
    Ascii,
    BinaryLittleEndian,
    BinaryBigEndian,
}

/// The type of a PLY property.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum PlyKind {
    /// One value.
    Scalar(ScalarType),
    /// A length of the first type, then that many values of the second.
    List(ScalarType, ScalarType),
}

/// A property of an element.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct PlyProperty {
    pub(crate) name: String,
    pub(crate) kind: PlyKind,
}

/// An element: a name, a declared record count and the properties of each record.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct PlyElement {
    pub(crate) name: String,
    pub(crate) count: u64,
    pub(crate) properties: Vec<PlyProperty>,
}

impl PlyElement {
    /// Smallest size of a binary record (lists empty), and whether all records have that
    /// size (no list property).
    pub(crate) fn min_record_size(&self) -> (u64, bool) {
        let mut size = 0u64;
        let mut fixed = true;
        for p in &self.properties {
            size += match p.kind {
                PlyKind::Scalar(t) => t.size() as u64,
                PlyKind::List(len, _) => {
                    fixed = false;
                    len.size() as u64
                }
            };
        }
        (size, fixed)
    }
}

/// A parsed header.
#[derive(Debug, Clone)]
pub(crate) struct PlyHeader {
    pub(crate) format: PlyFormat,
    pub(crate) elements: Vec<PlyElement>,
    /// Byte offset of the body.
    pub(crate) body_offset: usize,
    /// Line number of the first body line (ASCII).
    pub(crate) body_line: usize,
}

fn header_error(line: usize, msg: String) -> CloudIoError {
    CloudIoError::at(Location::Line(line), CloudIoErrorKind::Header(msg))
}

fn parse_type(line: usize, name: &str) -> Result<ScalarType, CloudIoError> {
    ScalarType::from_ply(name)
        .ok_or_else(|| header_error(line, format!("unknown property type `{}`", excerpt(name))))
}

/// Parses the header at the start of `bytes`.
pub(crate) fn parse_ply_header(bytes: &[u8]) -> Result<PlyHeader, CloudIoError> {
    let mut lines = TextLines::new(bytes, 0, 1);
    let magic = lines.next_raw().map(|(_, l)| l);
    if magic.map(|l| l.trim_ascii_end()) != Some(b"ply") {
        let found = magic.map_or_else(String::new, |l| {
            excerpt(&String::from_utf8_lossy(&l[..l.len().min(40)]))
        });
        return Err(CloudIoError::at(
            Location::Line(1),
            CloudIoErrorKind::BadMagic {
                format: "PLY",
                detail: format!("the first line must be `ply`, found `{found}`"),
            },
        ));
    }
    let mut format = None;
    let mut elements: Vec<PlyElement> = Vec::new();
    loop {
        let Some(next) = lines.next_text() else {
            return Err(CloudIoError::at(
                Location::Line(lines.line()),
                CloudIoErrorKind::MissingHeaderEnd {
                    format: "PLY",
                    expected: "end_header",
                },
            ));
        };
        let (n, text) = next?;
        let mut tokens = text.split_ascii_whitespace();
        let Some(keyword) = tokens.next() else {
            continue;
        };
        let args: Vec<&str> = tokens.collect();
        match keyword {
            "comment" | "obj_info" => {}
            "format" => {
                if format.is_some() {
                    return Err(header_error(n, "second `format` line".into()));
                }
                let f = match args.first().copied() {
                    Some("ascii") => PlyFormat::Ascii,
                    Some("binary_little_endian") => PlyFormat::BinaryLittleEndian,
                    Some("binary_big_endian") => PlyFormat::BinaryBigEndian,
                    other => {
                        return Err(header_error(
                            n,
                            format!(
                                "unknown format `{}`: expected ascii, binary_little_endian or binary_big_endian",
                                excerpt(other.unwrap_or(""))
                            ),
                        ));
                    }
                };
                match args.get(1) {
                    Some(v) if v.parse::<f64>().is_ok_and(|v| (1.0..2.0).contains(&v)) => {}
                    _ => return Err(header_error(n, "format version must be 1.0".into())),
                }
                format = Some(f);
            }
            "element" => {
                let [name, count] = args[..] else {
                    return Err(header_error(n, "expected `element <name> <count>`".into()));
                };
                let count = count.parse::<u64>().map_err(|_| {
                    header_error(
                        n,
                        format!(
                            "element count `{}` is not a non-negative integer",
                            excerpt(count)
                        ),
                    )
                })?;
                if elements.iter().any(|e| e.name == name) {
                    return Err(header_error(
                        n,
                        format!("second element `{}`", excerpt(name)),
                    ));
                }
                elements.push(PlyElement {
                    name: name.to_owned(),
                    count,
                    properties: Vec::new(),
                });
            }
            "property" => {
                let Some(element) = elements.last_mut() else {
                    return Err(header_error(n, "`property` before any `element`".into()));
                };
                let (name, kind) = match args[..] {
                    ["list", len, item, name] => {
                        let len = parse_type(n, len)?;
                        if len.is_float() {
                            return Err(header_error(
                                n,
                                "a list length must have an integer type".into(),
                            ));
                        }
                        (name, PlyKind::List(len, parse_type(n, item)?))
                    }
                    [ty, name] if ty != "list" => (name, PlyKind::Scalar(parse_type(n, ty)?)),
                    _ => {
                        return Err(header_error(
                            n,
                            "expected `property <type> <name>` or `property list <type> <type> <name>`".into(),
                        ));
                    }
                };
                if element.properties.iter().any(|p| p.name == name) {
                    return Err(header_error(
                        n,
                        format!("second property `{}`", excerpt(name)),
                    ));
                }
                element.properties.push(PlyProperty {
                    name: name.to_owned(),
                    kind,
                });
            }
            "end_header" => {
                let Some(format) = format else {
                    return Err(header_error(
                        n,
                        "no `format` line before `end_header`".into(),
                    ));
                };
                return Ok(PlyHeader {
                    format,
                    elements,
                    body_offset: lines.pos(),
                    body_line: lines.line(),
                });
            }
            other => {
                return Err(header_error(
                    n,
                    format!("unknown header keyword `{}`", excerpt(other)),
                ));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_elements_lists_and_comments() {
        let h = b"ply\r\nformat binary_big_endian 1.0\r\ncomment x\r\nobj_info y\r\n\
element vertex 3\r\nproperty float32 x\r\nproperty list uchar int vertex_indices\r\n\
element face 0\r\nend_header\r\n\x01";
        let hdr = parse_ply_header(h).unwrap();
        assert_eq!(hdr.format, PlyFormat::BinaryBigEndian);
        assert_eq!(hdr.elements.len(), 2);
        assert_eq!(hdr.elements[0].count, 3);
        assert_eq!(
            hdr.elements[0].properties[1].kind,
            PlyKind::List(ScalarType::U8, ScalarType::I32)
        );
        assert_eq!(hdr.elements[0].min_record_size(), (5, false));
        assert_eq!(&h[hdr.body_offset..], b"\x01");
        assert_eq!(hdr.body_line, 10);
    }

    #[test]
    fn rejects_bad_headers_with_line_numbers() {
        let cases: [(&[u8], usize); 6] = [
            (b"plx\n", 1),
            (b"ply\nformat ascii 1.0\nelement vertex -1\n", 3),
            (b"ply\nformat ascii 1.0\nproperty float x\n", 3),
            (
                b"ply\nformat ascii 1.0\nelement vertex 1\nproperty half x\n",
                4,
            ),
            (
                b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n",
                5,
            ),
            (b"ply\nelement vertex 1\nend_header\n", 3),
        ];
        for (text, line) in cases {
            let e = parse_ply_header(text).unwrap_err();
            assert_eq!(e.location, Location::Line(line), "{e}");
        }
    }
}
