//! `tf2_msgs`: [`TFMessage`], what `/tf` and `/tf_static` carry.

use super::{CdrStruct, TransformStamped, read_seq, ros_message, write_seq};
use crate::cdr::{CdrReader, CdrWriter};
use crate::error::CdrError;

/// `tf2_msgs/msg/TFMessage`: a batch of transforms.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TFMessage {
    /// The transforms.
    pub transforms: Vec<TransformStamped>,
}

impl CdrStruct for TFMessage {
    fn write_cdr(&self, w: &mut CdrWriter) {
        write_seq(w, &self.transforms);
    }
    fn read_cdr(r: &mut CdrReader<'_>) -> Result<Self, CdrError> {
        // header 8 + 2 strings of at least 5 + 7 f64.
        Ok(Self {
            transforms: read_seq(r, 8 + 5 + 5 + 56)?,
        })
    }
}

ros_message!(
    TFMessage,
    "tf2_msgs/msg/TFMessage",
    "RIHS01_e369d0f05a23ae52508854b66f6aa0437f3449d652e8cbf22d5abe85d020f087",
    "geometry_msgs/TransformStamped[] transforms\n",
    [TransformStamped]
);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::messages::{Header, RosMessage, Time, Transform, Vector3};

    #[test]
    fn one_transform_is_92_bytes_with_x_at_0x24() {
        let m = TFMessage {
            transforms: vec![TransformStamped {
                header: Header {
                    stamp: Time {
                        sec: 100,
                        nanosec: 500,
                    },
                    frame_id: "map".into(),
                },
                child_frame_id: "base".into(),
                transform: Transform {
                    translation: Vector3 {
                        x: 1.5,
                        y: -2.0,
                        z: 0.25,
                    },
                    ..Default::default()
                },
            }],
        };
        let b = m.encode();
        assert_eq!(b.len(), 92);
        assert_eq!(&b[0x1c..0x21], b"base\0");
        assert_eq!(&b[0x21..0x24], &[0, 0, 0]);
        assert_eq!(&b[0x24..0x2c], &1.5f64.to_le_bytes());
        assert_eq!(&b[84..92], &1.0f64.to_le_bytes()); // w last
        assert_eq!(TFMessage::decode(&b).unwrap(), m);
        assert_eq!(TFMessage::schema_text().len(), 990);
    }
}
