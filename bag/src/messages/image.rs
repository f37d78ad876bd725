//! `sensor_msgs`: [`Image`] (raw pixels, e.g. a `32FC1` depth image in metres) and
//! [`CompressedImage`] (what a marker's texture is).

use super::{CdrStruct, Header, ros_message};
use crate::cdr::{CdrReader, CdrWriter};
use crate::error::CdrError;

/// `sensor_msgs/msg/Image`: `height` rows of `step` bytes.
#[derive(Debug, Clone, Default, PartialEq, Eq, Hash)]
pub struct Image {
    /// Stamp and the camera's optical frame.
    pub header: Header,
    /// Rows.
    pub height: u32,
    /// Columns.
    pub width: u32,
    /// Pixel encoding (`32FC1`, `16UC1`, `rgb8`, …).
    pub encoding: String,
    /// Byte order of multi-byte pixels (0 little, 1 big).
    pub is_bigendian: u8,
    /// Bytes per row.
    pub step: u32,
    /// `step·height` bytes.
    pub data: Vec<u8>,
}

impl CdrStruct for Image {
    fn write_cdr(&self, w: &mut CdrWriter) {
        self.header.write_cdr(w);
        w.u32(self.height);
        w.u32(self.width);
        w.string(&self.encoding);
        w.u8(self.is_bigendian);
        w.u32(self.step);
        w.bytes(&self.data);
    }
    fn read_cdr(r: &mut CdrReader<'_>) -> Result<Self, CdrError> {
        Ok(Self {
            header: Header::read_cdr(r)?,
            height: r.u32()?,
            width: r.u32()?,
            encoding: r.string()?,
            is_bigendian: r.u8()?,
            step: r.u32()?,
            data: r.bytes()?,
        })
    }
}

ros_message!(
    Image,
    "sensor_msgs/msg/Image",
    "RIHS01_d31d41a9a4c4bc8eae9be757b0beed306564f7526c88ea6a4588fb9582527d47",
    "std_msgs/Header header\nuint32 height\nuint32 width\nstring encoding\nuint8 is_bigendian\n\
     uint32 step\nuint8[] data\n",
    [Header]
);

/// `sensor_msgs/msg/CompressedImage`: an encoded image (`format` e.g. `png`, `jpeg`).
#[derive(Debug, Clone, Default, PartialEq, Eq, Hash)]
pub struct CompressedImage {
    /// Stamp and frame.
    pub header: Header,
    /// The encoding.
    pub format: String,
    /// The encoded bytes.
    pub data: Vec<u8>,
}

impl CdrStruct for CompressedImage {
    fn write_cdr(&self, w: &mut CdrWriter) {
        self.header.write_cdr(w);
        w.string(&self.format);
        w.bytes(&self.data);
    }
    fn read_cdr(r: &mut CdrReader<'_>) -> Result<Self, CdrError> {
        Ok(Self {
            header: Header::read_cdr(r)?,
            format: r.string()?,
            data: r.bytes()?,
        })
    }
}

ros_message!(
    CompressedImage,
    "sensor_msgs/msg/CompressedImage",
    "RIHS01_15640771531571185e2efc8a100baf923961a4d15d5569652e6cb6691e8e371a",
    "std_msgs/Header header\nstring format\nuint8[] data\n",
    [Header]
);
