//! `std_msgs`: [`Header`], [`RosString`] (`std_msgs/String`) and [`ColorRGBA`].

use super::{CdrStruct, Time, ros_message};
use crate::cdr::{CdrReader, CdrWriter};
use crate::error::CdrError;

/// `std_msgs/msg/Header`: a stamp and the frame the data is in.
#[derive(Debug, Clone, Default, PartialEq, Eq, Hash)]
pub struct Header {
    /// When the data was taken.
    pub stamp: Time,
    /// The data's frame (for a transform: the parent).
    pub frame_id: String,
}

impl CdrStruct for Header {
    fn write_cdr(&self, w: &mut CdrWriter) {
        self.stamp.write_cdr(w);
        w.string(&self.frame_id);
    }
    fn read_cdr(r: &mut CdrReader<'_>) -> Result<Self, CdrError> {
        Ok(Self {
            stamp: Time::read_cdr(r)?,
            frame_id: r.string()?,
        })
    }
}

ros_message!(
    Header,
    "std_msgs/msg/Header",
    "RIHS01_f49fb3ae2cf070f793645ff749683ac6b06203e41c891e17701b1cb597ce6a01",
    "builtin_interfaces/Time stamp\nstring frame_id\n",
    [Time]
);

/// `std_msgs/msg/String` (named so as not to shadow Rust's `String`).
#[derive(Debug, Clone, Default, PartialEq, Eq, Hash)]
pub struct RosString {
    /// The text.
    pub data: String,
}

impl CdrStruct for RosString {
    fn write_cdr(&self, w: &mut CdrWriter) {
        w.string(&self.data);
    }
    fn read_cdr(r: &mut CdrReader<'_>) -> Result<Self, CdrError> {
        Ok(Self { data: r.string()? })
    }
}

ros_message!(
    RosString,
    "std_msgs/msg/String",
    "RIHS01_df668c740482bbd48fb39d76a70dfd4bd59db1288021743503259e948f6b1a18",
    "string data\n",
    []
);

/// `std_msgs/msg/ColorRGBA`: a colour, components in `0..=1`.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ColorRGBA {
    /// Red.
    pub r: f32,
    /// Green.
    pub g: f32,
    /// Blue.
    pub b: f32,
    /// Alpha (0 is invisible).
    pub a: f32,
}

impl CdrStruct for ColorRGBA {
    fn write_cdr(&self, w: &mut CdrWriter) {
        w.f32(self.r);
        w.f32(self.g);
        w.f32(self.b);
        w.f32(self.a);
    }
    fn read_cdr(r: &mut CdrReader<'_>) -> Result<Self, CdrError> {
        Ok(Self {
            r: r.f32()?,
            g: r.f32()?,
            b: r.f32()?,
            a: r.f32()?,
        })
    }
}

ros_message!(
    ColorRGBA,
    "std_msgs/msg/ColorRGBA",
    "RIHS01_77a7a5b9ae477306097665106e0413ba74440245b1f3d0c6d6405fe5c7813fe8",
    "float32 r\nfloat32 g\nfloat32 b\nfloat32 a\n",
    []
);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::messages::RosMessage;

    #[test]
    fn header_hexdump() {
        let h = Header {
            stamp: Time {
                sec: 100,
                nanosec: 500,
            },
            frame_id: "map".into(),
        };
        let b = h.encode();
        assert_eq!(
            b,
            [
                0x00, 0x01, 0x00, 0x00, 0x64, 0x00, 0x00, 0x00, 0xf4, 0x01, 0x00, 0x00, 0x04, 0x00,
                0x00, 0x00, 0x6d, 0x61, 0x70, 0x00
            ]
        );
        assert_eq!(Header::decode(&b).unwrap(), h);
    }

    #[test]
    fn string_schema_and_bytes() {
        assert_eq!(RosString::schema_text(), "string data\n");
        let s = RosString { data: "hi".into() };
        assert_eq!(s.encode(), [0, 1, 0, 0, 3, 0, 0, 0, b'h', b'i', 0]);
    }
}
