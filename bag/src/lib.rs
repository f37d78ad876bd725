//! # nbv-bag: rosbag2 bags (MCAP storage) in and out, without a ROS install
//!
//! - [`BagWriter`] writes a rosbag2 directory: `dir/<dirname>_0.mcap` (profile `ros2`,
//!   zstd chunks, indexes and summary) and a v8 `metadata.yaml` that Humble and Jazzy both
//!   read; latched topics (`/tf_static`, `/robot_description`) get transient-local QoS.
//! - [`BagReader`] opens a rosbag2 directory or a bare `.mcap`, lists topics, yields a
//!   topic's messages in log-time order, and builds a [`TfBuffer`] and xyz clouds.
//! - [`messages`]: the ROS 2 types as plain structs with `encode`/`decode` (CDR, [`cdr`])
//!   and their `ros2msg` schema texts, byte-identical to rosbags'.
//! - [`point_cloud`]: `PointCloud2` ⇄ points, for any FLOAT32/FLOAT64 xyz layout.
//! - [`TfBuffer`]: an offline tf2 buffer (interpolation, no extrapolation, static frames,
//!   full history).
//!
//! Write a bag with one cloud and its sensor's pose, read it back, and put the cloud in
//! the world frame:
//!
//! ```
//! use nbv_bag::messages::{Header, TFMessage, Time, Transform, TransformStamped, Vector3};
//! use nbv_bag::point_cloud::cloud_from_points;
//! use nbv_bag::{BagReader, BagWriter};
//!
//! let tmp = tempfile::tempdir().unwrap();
//! let stamp = Time { sec: 100, nanosec: 0 };
//! let t_ns = stamp.to_nanos();
//! let mut bag = BagWriter::create(tmp.path().join("scan")).unwrap();
//! let tf = TransformStamped {
//!     header: Header { stamp, frame_id: "world".into() },
//!     child_frame_id: "sensor".into(),
//!     transform: Transform { translation: Vector3 { x: 1.0, y: 0.0, z: 0.5 }, ..Default::default() },
//! };
//! bag.write("/tf_static", t_ns as u64, &TFMessage { transforms: vec![tf] }).unwrap();
//! let header = Header { stamp, frame_id: "sensor".into() };
//! bag.write("/points", t_ns as u64, &cloud_from_points(header, &[[0.0, 0.0, 2.0]])).unwrap();
//! let dir = bag.finish().unwrap();
//!
//! let bag = BagReader::open(&dir).unwrap();
//! assert_eq!(bag.topic("/points").unwrap().type_name, "sensor_msgs/msg/PointCloud2");
//! let tf = bag.tf_buffer().unwrap();
//! let cloud = &bag.point_clouds("/points").unwrap()[0];
//! let pose = tf.lookup("world", &cloud.header.frame_id, cloud.header.stamp.to_nanos()).unwrap();
//! let p = pose * cloud.points[0];
//! assert_eq!((p.x, p.y, p.z), (1.0, 0.0, 2.5));
//! ```

pub mod cdr;
pub mod error;
mod mcap_scan;
pub mod messages;
pub mod metadata;
pub mod point_cloud;
pub mod reader;
pub mod tf_buffer;
pub mod writer;

pub use error::{BagError, CdrError, CloudError, DecodeError, TfError};
pub use reader::{BagMessage, BagReader, StampedCloud, TopicInfo};
pub use tf_buffer::TfBuffer;
pub use writer::BagWriter;
