//! The PCD writer (version 0.7, as PCL writes it): fields `x y z`, then PCL's
//! `normal_x normal_y normal_z` and `vp_x vp_y vp_z`, `label`, `view`, `tx ty tz`; identity
//! `VIEWPOINT`; `DATA ascii`, `binary` or `binary_compressed`.

use std::io::{BufWriter, Write};

use super::columns::{ColumnNames, check_writable, out_fields};
use super::error::CloudIoError;
use super::lzf::lzf_compress;
use super::options::{Encoding, WriteOptions};
use super::record_writer::write_records;
use crate::cloud::PointCloud;

const PCD_NAMES: ColumnNames = ColumnNames {
    normals: ["normal_x", "normal_y", "normal_z"],
    origins: ["vp_x", "vp_y", "vp_z"],
};

/// Writes `cloud` as PCD to a stream (an unorganised cloud: `HEIGHT 1`). The output
/// depends only on the cloud and the options.
///
/// ```
/// use nbv_core::cloud::{PointCloud, io::{write_pcd, read_pcd, Encoding, ReadOptions, WriteOptions}};
/// use nalgebra::Point3;
/// let c = PointCloud::from_points(vec![Point3::new(0.25, -1.0, 2.0); 100]);
/// let mut out = Vec::new();
/// write_pcd(&mut out, &c, &WriteOptions { encoding: Encoding::BinaryCompressed, ..Default::default() }).unwrap();
/// assert!(out.len() < 100 * 12);
/// assert_eq!(read_pcd(&out[..], &ReadOptions::default()).unwrap().cloud, c);
/// ```
pub fn write_pcd(
    writer: impl Write,
    cloud: &PointCloud,
    options: &WriteOptions,
) -> Result<(), CloudIoError> {
    let fields = out_fields(cloud, options.float, &PCD_NAMES);
    check_writable(cloud, &fields)?;
    let join = |f: &dyn Fn(&super::columns::OutField) -> String| {
        fields.iter().map(f).collect::<Vec<_>>().join(" ")
    };
    let n = cloud.len();
    let header = format!(
        "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS {}\nSIZE {}\nTYPE {}\nCOUNT {}\n\
         WIDTH {n}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {n}\nDATA {}\n",
        join(&|f| f.name.to_owned()),
        join(&|f| f.ty.size().to_string()),
        join(&|f| f.ty.pcd_letter().to_string()),
        join(&|_| "1".to_owned()),
        match options.encoding {
            Encoding::Ascii => "ascii",
            Encoding::Binary => "binary",
            Encoding::BinaryCompressed => "binary_compressed",
        }
    );
    let io = CloudIoError::io;
    let mut w = BufWriter::new(writer);
    w.write_all(header.as_bytes()).map_err(io)?;
    match options.encoding {
        Encoding::Ascii | Encoding::Binary => {
            write_records(&mut w, cloud, &fields, options.encoding).map_err(io)?;
        }
        Encoding::BinaryCompressed => {
            let mut records = Vec::new();
            write_records(&mut records, cloud, &fields, Encoding::Binary).map_err(io)?;
            // Field-major layout, as PCL compresses it.
            let record: usize = fields.iter().map(|f| f.ty.size()).sum();
            let mut columns = Vec::with_capacity(records.len());
            let mut offset = 0;
            for f in &fields {
                let s = f.ty.size();
                for r in records.chunks_exact(record) {
                    columns.extend_from_slice(&r[offset..offset + s]);
                }
                offset += s;
            }
            let packed = if columns.is_empty() {
                Vec::new()
            } else {
                lzf_compress(&columns)
            };
            let size = |v: usize| {
                u32::try_from(v).map_err(|_| {
                    CloudIoError::io(std::io::Error::new(
                        std::io::ErrorKind::InvalidInput,
                        "binary_compressed PCD holds at most 4 GiB of point data",
                    ))
                })
            };
            w.write_all(&size(packed.len())?.to_le_bytes())
                .map_err(io)?;
            w.write_all(&size(columns.len())?.to_le_bytes())
                .map_err(io)?;
            w.write_all(&packed).map_err(io)?;
        }
    }
    w.flush().map_err(io)
}
