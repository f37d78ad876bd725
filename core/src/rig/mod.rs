//! The boundary between the pipeline and a rig: what the pipeline asks of an arm, a line
//! scanner (mid range) and a depth camera (short range).
//!
//! The twin (`nbv-sim`) and the real drivers (`nbv-hw`) implement these traits and lend
//! them, with the robot model and base, as one [`Rig`]; the pipeline never knows which
//! one it drives.
//!
//! Time is the rig's own clock in seconds (simulated time in the twin, the host's
//! monotonic clock on hardware); a scan line and the arm's joint samples share it, so the
//! pipeline can stamp each line with the sensor pose at its time.

mod arm;
mod depth_camera;
mod frame_average;
mod frame_smoothing;
mod line_scanner;
mod no_return;
mod rig_error;
mod robot_rig;
mod sensor_cloud;
mod sweep;
mod truth;

pub use arm::{Arm, JointPath, Motion, TimedJoints};
pub use depth_camera::{DepthCamera, DepthCameraSpec, DepthFrame};
pub use frame_average::average_frames;
pub use frame_smoothing::{GATE_SIGMAS, MIN_NEIGHBOURS, smooth_frame};
pub use line_scanner::{LineScanner, LineScannerSpec, ScanLine};
pub use no_return::no_return_pixels;
pub use rig_error::RigError;
pub use robot_rig::Rig;
pub use sensor_cloud::{SensorCloudError, depth_frame_to_cloud, lines_to_cloud, sensor_pose};
pub use sweep::{SweepData, acquire_sweep};
pub use truth::{LabelCounts, TruthHit, TruthLabel};
