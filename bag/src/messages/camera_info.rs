//! `sensor_msgs`: [`CameraInfo`] (intrinsics, distortion, projection) and
//! [`RegionOfInterest`].

use super::{CdrStruct, Header, ros_message};
use crate::cdr::{CdrReader, CdrWriter};
use crate::error::CdrError;

/// `sensor_msgs/msg/RegionOfInterest`: a window of the image.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash)]
pub struct RegionOfInterest {
    /// Leftmost column.
    pub x_offset: u32,
    /// Topmost row.
    pub y_offset: u32,
    /// Rows (0: the full image).
    pub height: u32,
    /// Columns (0: the full image).
    pub width: u32,
    /// Whether the window is to be rectified.
    pub do_rectify: bool,
}

impl CdrStruct for RegionOfInterest {
    fn write_cdr(&self, w: &mut CdrWriter) {
        w.u32(self.x_offset);
        w.u32(self.y_offset);
        w.u32(self.height);
        w.u32(self.width);
        w.bool(self.do_rectify);
    }
    fn read_cdr(r: &mut CdrReader<'_>) -> Result<Self, CdrError> {
        Ok(Self {
            x_offset: r.u32()?,
            y_offset: r.u32()?,
            height: r.u32()?,
            width: r.u32()?,
            do_rectify: r.bool()?,
        })
    }
}

ros_message!(
    RegionOfInterest,
    "sensor_msgs/msg/RegionOfInterest",
    "RIHS01_ad16bcba5f9131dcdba6fbded19f726f5440e3c513b4fb586dd3027eeed8abb1",
    "uint32 x_offset\nuint32 y_offset\nuint32 height\nuint32 width\nbool do_rectify\n",
    []
);

/// `sensor_msgs/msg/CameraInfo`: a calibrated pinhole camera. `k`, `r` and `p` are
/// row-major 3×3, 3×3 and 3×4; zeros mean uncalibrated.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct CameraInfo {
    /// Stamp and the optical frame (+x right, +y down, +z forward).
    pub header: Header,
    /// Image rows.
    pub height: u32,
    /// Image columns.
    pub width: u32,
    /// `plumb_bob`, `rational_polynomial`, `equidistant`, ….
    pub distortion_model: String,
    /// Distortion coefficients.
    pub d: Vec<f64>,
    /// Intrinsics.
    pub k: [f64; 9],
    /// Rectification rotation.
    pub r: [f64; 9],
    /// Projection.
    pub p: [f64; 12],
    /// Horizontal binning.
    pub binning_x: u32,
    /// Vertical binning.
    pub binning_y: u32,
    /// Region of interest.
    pub roi: RegionOfInterest,
}

impl CdrStruct for CameraInfo {
    fn write_cdr(&self, w: &mut CdrWriter) {
        self.header.write_cdr(w);
        w.u32(self.height);
        w.u32(self.width);
        w.string(&self.distortion_model);
        w.f64_seq(&self.d);
        w.f64_array(&self.k);
        w.f64_array(&self.r);
        w.f64_array(&self.p);
        w.u32(self.binning_x);
        w.u32(self.binning_y);
        self.roi.write_cdr(w);
    }
    fn read_cdr(r: &mut CdrReader<'_>) -> Result<Self, CdrError> {
        Ok(Self {
            header: Header::read_cdr(r)?,
            height: r.u32()?,
            width: r.u32()?,
            distortion_model: r.string()?,
            d: r.f64_seq()?,
            k: r.f64_array()?,
            r: r.f64_array()?,
            p: r.f64_array()?,
            binning_x: r.u32()?,
            binning_y: r.u32()?,
            roi: RegionOfInterest::read_cdr(r)?,
        })
    }
}

ros_message!(
    CameraInfo,
    "sensor_msgs/msg/CameraInfo",
    "RIHS01_b3dfd68ff46c9d56c80fd3bd4ed22c7a4ddce8c8348f2f59c299e73118e7e275",
    "std_msgs/Header header\nuint32 height\nuint32 width\nstring distortion_model\n\
     float64[] d\nfloat64[9] k\nfloat64[9] r\nfloat64[12] p\nuint32 binning_x\n\
     uint32 binning_y\nsensor_msgs/RegionOfInterest roi\n",
    [Header, RegionOfInterest]
);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::messages::{RosMessage, Time};

    #[test]
    fn fixed_arrays_have_no_count() {
        let c = CameraInfo {
            header: Header {
                stamp: Time {
                    sec: 100,
                    nanosec: 500,
                },
                frame_id: "map".into(),
            },
            height: 480,
            width: 640,
            distortion_model: "plumb_bob".into(),
            d: vec![0.1, 0.2, 0.0, 0.0, 0.3],
            k: [500.0, 0.0, 320.0, 0.0, 500.0, 240.0, 0.0, 0.0, 1.0],
            ..Default::default()
        };
        let b = c.encode();
        // header 20, height 0x14, width 0x18, "plumb_bob" len at 0x1c, bytes to 0x2a,
        // d count at 0x2c, 4 pad, d[0] at 0x34, k[0] right after d[4] at 0x5c = 92.
        assert_eq!(&b[0x2c..0x30], &[5, 0, 0, 0]);
        assert_eq!(&b[0x34..0x3c], &0.1f64.to_le_bytes());
        assert_eq!(&b[92..100], &500.0f64.to_le_bytes());
        assert_eq!(b.len(), 92 + (9 + 9 + 12) * 8 + 8 + 17);
        assert_eq!(CameraInfo::decode(&b).unwrap(), c);
    }
}
