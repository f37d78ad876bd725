//! The body shared by the PLY and PCD writers: one record per point with the fields of
//! [`out_fields`](super::columns::out_fields), as text lines or little-endian binary.

use std::io::{self, Write};

use super::columns::{OutField, value};
use super::options::Encoding;
use super::scalar::{ScalarType, push_float};
use crate::cloud::PointCloud;

/// Writes one record per point of `cloud`.
pub(crate) fn write_records(
    w: &mut impl Write,
    cloud: &PointCloud,
    fields: &[OutField],
    encoding: Encoding,
) -> io::Result<()> {
    match encoding {
        Encoding::Ascii => {
            let mut line = String::new();
            for i in 0..cloud.len() {
                line.clear();
                for (k, f) in fields.iter().enumerate() {
                    if k > 0 {
                        line.push(' ');
                    }
                    let v = value(cloud, f.role, i);
                    match f.ty {
                        ScalarType::F32 => push_float(&mut line, v, true),
                        ScalarType::F64 => push_float(&mut line, v, false),
                        // Labels and views: u32 held exactly in an f64.
                        _ => {
                            use std::fmt::Write as _;
                            let _ = write!(line, "{}", v as u64);
                        }
                    }
                }
                line.push('\n');
                w.write_all(line.as_bytes())?;
            }
        }
        Encoding::Binary | Encoding::BinaryCompressed => {
            let mut rec = Vec::new();
            for i in 0..cloud.len() {
                rec.clear();
                for f in fields {
                    let v = value(cloud, f.role, i);
                    match f.ty {
                        ScalarType::F32 => rec.extend_from_slice(&(v as f32).to_le_bytes()),
                        ScalarType::F64 => rec.extend_from_slice(&v.to_le_bytes()),
                        _ => rec.extend_from_slice(&(v as u32).to_le_bytes()),
                    }
                }
                w.write_all(&rec)?;
            }
        }
    }
    Ok(())
}
