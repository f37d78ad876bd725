//! Episode bags: `OUT/bag/`, a rosbag2 directory (MCAP storage, `bag/bag_0.mcap` and
//! `bag/metadata.yaml`) of everything the robot did, saw and decided, for RViz, Foxglove
//! and `ros2 bag play` (`nbv explore --bag`, `nbv sweep run --bag`; docs/bags.md).
//!
//! The recorder is an [`ExploreObserver`](nbv_core::pipeline::ExploreObserver) like the
//! Rerun recorder: it writes the pipeline's events as they come
//! ([`BagRecorder::observe`] puts it beside the progress bars), the models named after
//! the report at the end ([`BagRecorder::finish`]); the bag appears only when finished.
//!
//! Stamps are the rig's clock (the motion samples' and scan lines' times, seconds) in
//! nanoseconds plus [`STAMP_OFFSET_NS`] (one second), so rig time 0 is stamp 1 s and no
//! stamp is 0 (which tf2 reads as "the latest"). Header stamps equal the log times.
//!
//! ```text
//! /tf_static            tf2_msgs/TFMessage        world→<URDF root>, world→table, every
//!                                                 fixed URDF joint (the sensor mounts)
//! /tf                   tf2_msgs/TFMessage        every moving URDF joint, parent→child
//! /joint_states         sensor_msgs/JointState    the six joints, same samples as /tf
//! /robot_description    std_msgs/String           the URDF (latched)
//! /nbv/sweep/points     sensor_msgs/PointCloud2   the laser sweep cloud (world)
//! /nbv/camera/points    sensor_msgs/PointCloud2   a view's object points (camera optical frame)
//! /nbv/camera/depth     sensor_msgs/Image         a view's whole depth frame, 32FC1 metres
//! /nbv/camera/camera_info sensor_msgs/CameraInfo  the camera's pinhole intrinsics
//! /nbv/grid/occupied    visualization_msgs/MarkerArray  the reduced map's occupied voxels
//! /nbv/grid/unknown     visualization_msgs/MarkerArray  and its unknown voxels
//! /nbv/candidates       visualization_msgs/MarkerArray  candidate viewpoints, coloured by score
//! /nbv/models/<name>    sensor_msgs/PointCloud2   an object's registered model (world)
//! /nbv/events           std_msgs/String           one JSON object per pipeline event
//! ```

mod bag_recorder;
mod camera;
mod event_json;
mod markers;
mod robot_tf;
mod stamps;
pub mod topics;

pub use bag_recorder::{BagRecorder, BagTee, DIR_NAME};
pub use stamps::{STAMP_OFFSET_NS, stamp_ns};
