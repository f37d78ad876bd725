//! `sensor_msgs`: [`PointCloud2`] and [`PointField`], the raw message. Reading and
//! building xyz clouds is [`point_cloud`](crate::point_cloud).

use super::{CdrStruct, Header, read_seq, ros_message, write_seq};
use crate::cdr::{CdrReader, CdrWriter};
use crate::error::CdrError;

/// `sensor_msgs/msg/PointField`: one field of a point's record.
#[derive(Debug, Clone, Default, PartialEq, Eq, Hash)]
pub struct PointField {
    /// Its name (`x`, `y`, `z`, `intensity`, `rgb`, …).
    pub name: String,
    /// Byte offset in the point's record.
    pub offset: u32,
    /// One of the `PointField::INT8..FLOAT64` codes.
    pub datatype: u8,
    /// Consecutive values of the type.
    pub count: u32,
}

impl PointField {
    /// `int8`.
    pub const INT8: u8 = 1;
    /// `uint8`.
    pub const UINT8: u8 = 2;
    /// `int16`.
    pub const INT16: u8 = 3;
    /// `uint16`.
    pub const UINT16: u8 = 4;
    /// `int32`.
    pub const INT32: u8 = 5;
    /// `uint32`.
    pub const UINT32: u8 = 6;
    /// `float32`.
    pub const FLOAT32: u8 = 7;
    /// `float64`.
    pub const FLOAT64: u8 = 8;
}

impl CdrStruct for PointField {
    fn write_cdr(&self, w: &mut CdrWriter) {
        w.string(&self.name);
        w.u32(self.offset);
        w.u8(self.datatype);
        w.u32(self.count);
    }
    fn read_cdr(r: &mut CdrReader<'_>) -> Result<Self, CdrError> {
        Ok(Self {
            name: r.string()?,
            offset: r.u32()?,
            datatype: r.u8()?,
            count: r.u32()?,
        })
    }
}

ros_message!(
    PointField,
    "sensor_msgs/msg/PointField",
    "RIHS01_5c6a4750728c2bcfbbf7037225b20b02d4429634732146b742dee1726637ef01",
    "uint8 INT8=1\nuint8 UINT8=2\nuint8 INT16=3\nuint8 UINT16=4\nuint8 INT32=5\nuint8 UINT32=6\n\
     uint8 FLOAT32=7\nuint8 FLOAT64=8\nstring name\nuint32 offset\nuint8 datatype\nuint32 count\n",
    []
);

/// `sensor_msgs/msg/PointCloud2`: points as records of `point_step` bytes, `width` per
/// row, `height` rows (1 for an unordered cloud).
#[derive(Debug, Clone, Default, PartialEq, Eq, Hash)]
pub struct PointCloud2 {
    /// Stamp and the sensor frame the points are in.
    pub header: Header,
    /// Rows.
    pub height: u32,
    /// Points per row.
    pub width: u32,
    /// The record's layout.
    pub fields: Vec<PointField>,
    /// Byte order of `data`.
    pub is_bigendian: bool,
    /// Bytes per point.
    pub point_step: u32,
    /// Bytes per row.
    pub row_step: u32,
    /// `row_step·height` bytes.
    pub data: Vec<u8>,
    /// True when no point is invalid (NaN/Inf).
    pub is_dense: bool,
}

impl CdrStruct for PointCloud2 {
    fn write_cdr(&self, w: &mut CdrWriter) {
        self.header.write_cdr(w);
        w.u32(self.height);
        w.u32(self.width);
        write_seq(w, &self.fields);
        w.bool(self.is_bigendian);
        w.u32(self.point_step);
        w.u32(self.row_step);
        w.bytes(&self.data);
        w.bool(self.is_dense);
    }
    fn read_cdr(r: &mut CdrReader<'_>) -> Result<Self, CdrError> {
        Ok(Self {
            header: Header::read_cdr(r)?,
            height: r.u32()?,
            width: r.u32()?,
            fields: read_seq(r, 5 + 4 + 1 + 4)?,
            is_bigendian: r.bool()?,
            point_step: r.u32()?,
            row_step: r.u32()?,
            data: r.bytes()?,
            is_dense: r.bool()?,
        })
    }
}

ros_message!(
    PointCloud2,
    "sensor_msgs/msg/PointCloud2",
    "RIHS01_9198cabf7da3796ae6fe19c4cb3bdd3525492988c70522628af5daa124bae2b5",
    "std_msgs/Header header\nuint32 height\nuint32 width\nsensor_msgs/PointField[] fields\n\
     bool is_bigendian\nuint32 point_step\nuint32 row_step\nuint8[] data\nbool is_dense\n",
    [Header, PointField]
);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::messages::{RosMessage, Time};

    #[test]
    fn one_point_is_121_bytes() {
        let field = |name: &str, offset| PointField {
            name: name.into(),
            offset,
            datatype: PointField::FLOAT32,
            count: 1,
        };
        let data: Vec<u8> = [1.0f32, 2.0, 3.0]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        let c = PointCloud2 {
            header: Header {
                stamp: Time {
                    sec: 100,
                    nanosec: 500,
                },
                frame_id: "map".into(),
            },
            height: 1,
            width: 1,
            fields: vec![field("x", 0), field("y", 4), field("z", 8)],
            is_bigendian: false,
            point_step: 12,
            row_step: 12,
            data,
            is_dense: true,
        };
        let b = c.encode();
        assert_eq!(b.len(), 121);
        let u32_at = |o: usize| u32::from_le_bytes([b[o], b[o + 1], b[o + 2], b[o + 3]]);
        assert_eq!(&b[0..4], &[0, 1, 0, 0]);
        assert_eq!((u32_at(0x04), u32_at(0x08)), (100, 500));
        assert_eq!(&b[0x0c..0x14], &[4, 0, 0, 0, b'm', b'a', b'p', 0]);
        assert_eq!((u32_at(0x14), u32_at(0x18), u32_at(0x1c)), (1, 1, 3));
        assert_eq!(&b[0x20..0x28], &[2, 0, 0, 0, b'x', 0, 0, 0]);
        assert_eq!(u32_at(0x28), 0);
        assert_eq!(&b[0x2c..0x30], &[7, 0, 0, 0]);
        assert_eq!(u32_at(0x30), 1);
        assert_eq!(&b[0x34..0x3a], &[2, 0, 0, 0, b'y', 0]);
        assert_eq!(u32_at(0x58), 1);
        assert_eq!(&b[0x5c..0x60], &[0, 0, 0, 0]);
        assert_eq!((u32_at(0x60), u32_at(0x64), u32_at(0x68)), (12, 12, 12));
        assert_eq!(
            &b[0x6c..0x78],
            &[0, 0, 0x80, 0x3f, 0, 0, 0, 0x40, 0, 0, 0x40, 0x40]
        );
        assert_eq!(b[0x78], 1);
        assert_eq!(PointCloud2::decode(&b).unwrap(), c);
        assert_eq!(PointCloud2::schema_text().len(), 724);
    }
}
