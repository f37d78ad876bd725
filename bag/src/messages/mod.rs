//! ROS 2 message types as plain structs: [`CdrStruct`] (their CDR layout) and
//! [`RosMessage`] (a type that can be a topic's type: its name, its `ros2msg` schema text
//! and `encode`/`decode`). One file per message family.
//!
//! Schema texts are the comment-free ones rosbags 0.11.9 writes: the type's own fields
//! (constants first), then each dependency once, depth-first, each after a line of 80 `=`
//! and `MSG: pkg/Type`. The tests compare them byte for byte with rosbags' output.

mod builtin;
mod camera_info;
mod geometry;
mod image;
mod joint_state;
mod marker;
mod point_cloud2;
mod std_msgs;
mod tf2;

pub use builtin::{Duration, Time};
pub use camera_info::{CameraInfo, RegionOfInterest};
pub use geometry::{
    Point, Pose, PoseWithCovariance, PoseWithCovarianceStamped, Quaternion, Transform,
    TransformStamped, Vector3,
};
pub use image::{CompressedImage, Image};
pub use joint_state::JointState;
pub use marker::{Marker, MarkerArray, MeshFile, UVCoordinate};
pub use point_cloud2::{PointCloud2, PointField};
pub use std_msgs::{ColorRGBA, Header, RosString};
pub use tf2::TFMessage;

use crate::cdr::{CdrReader, CdrWriter};
use crate::error::CdrError;

/// A type with a CDR layout: its fields written and read in wire order (nested structs add
/// no alignment of their own, so this is all a field of this type needs).
pub trait CdrStruct: Sized {
    /// Appends the fields.
    fn write_cdr(&self, w: &mut CdrWriter);
    /// Reads the fields.
    ///
    /// # Errors
    /// Whatever [`CdrReader`] refuses.
    fn read_cdr(r: &mut CdrReader<'_>) -> Result<Self, CdrError>;
}

/// The line between the sections of a `ros2msg` schema text.
pub const SCHEMA_SEPARATOR: &str =
    "================================================================================";

/// A ROS 2 message type: what a bag needs to register a topic of it, and its CDR bytes.
///
/// ```
/// use nbv_bag::messages::{Header, RosMessage, Time};
/// let h = Header { stamp: Time { sec: 100, nanosec: 500 }, frame_id: "map".into() };
/// let bytes = h.encode();
/// assert_eq!(bytes.len(), 20);
/// assert_eq!(Header::decode(&bytes).unwrap(), h);
/// assert_eq!(Header::TYPE_NAME, "std_msgs/msg/Header");
/// ```
pub trait RosMessage: CdrStruct {
    /// The package resource name, `pkg/msg/Type` (the MCAP schema name and the
    /// metadata.yaml `type`).
    const TYPE_NAME: &'static str;
    /// The `RIHS01_…` type description hash as rosbags computes it (for metadata.yaml's
    /// `type_description_hash`; unverified against a ROS install).
    const TYPE_HASH: &'static str;
    /// The type's own `.msg` text (constants, then fields), comment-free, ending in `\n`.
    const DEFINITION: &'static str;

    /// Appends the dependencies not yet in `out`, depth-first, as `(pkg/Type, definition)`.
    fn dependencies(out: &mut Vec<(String, &'static str)>) {
        let _ = out;
    }

    /// The full `ros2msg` schema text: the definition, then every dependency once.
    fn schema_text() -> String {
        let mut deps = Vec::new();
        Self::dependencies(&mut deps);
        let mut s = String::from(Self::DEFINITION);
        for (name, def) in deps {
            s.push_str(SCHEMA_SEPARATOR);
            s.push_str("\nMSG: ");
            s.push_str(&name);
            s.push('\n');
            s.push_str(def);
        }
        s
    }

    /// The CDR little-endian bytes, encapsulation header included.
    fn encode(&self) -> Vec<u8> {
        let mut w = CdrWriter::new();
        self.write_cdr(&mut w);
        w.finish()
    }

    /// Decodes CDR bytes (up to 3 trailing padding bytes allowed).
    ///
    /// # Errors
    /// [`CdrError`] for a truncated buffer, a bad header, bad strings or trailing bytes.
    fn decode(bytes: &[u8]) -> Result<Self, CdrError> {
        let mut r = CdrReader::new(bytes)?;
        let v = Self::read_cdr(&mut r)?;
        r.finish()?;
        Ok(v)
    }
}

/// Adds `T` (as `pkg/Type`) and its dependencies to `out` unless already there.
pub(crate) fn push_dep<T: RosMessage>(out: &mut Vec<(String, &'static str)>) {
    let name = T::TYPE_NAME.replacen("/msg/", "/", 1);
    if out.iter().any(|(n, _)| *n == name) {
        return;
    }
    out.push((name, T::DEFINITION));
    T::dependencies(out);
}

/// Writes a sequence of structs: the count, then each.
pub(crate) fn write_seq<T: CdrStruct>(w: &mut CdrWriter, v: &[T]) {
    w.seq_len(v.len());
    for x in v {
        x.write_cdr(w);
    }
}

/// Reads a sequence of structs, each at least `min_bytes` long on the wire.
pub(crate) fn read_seq<T: CdrStruct>(
    r: &mut CdrReader<'_>,
    min_bytes: usize,
) -> Result<Vec<T>, CdrError> {
    let n = r.seq_len(min_bytes)?;
    (0..n).map(|_| T::read_cdr(r)).collect()
}

/// Implements [`RosMessage`] for a type: name, hash, definition and direct dependencies
/// in field order.
macro_rules! ros_message {
    ($t:ty, $name:literal, $hash:literal, $def:expr, [$($dep:ty),* $(,)?]) => {
        impl $crate::messages::RosMessage for $t {
            const TYPE_NAME: &'static str = $name;
            const TYPE_HASH: &'static str = $hash;
            const DEFINITION: &'static str = $def;
            fn dependencies(out: &mut Vec<(String, &'static str)>) {
                let _ = &out;
                $($crate::messages::push_dep::<$dep>(out);)*
            }
        }
    };
}
pub(crate) use ros_message;
