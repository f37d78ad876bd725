//! The simulated rig: nbv-core's [`Arm`](nbv_core::rig::Arm),
//! [`LineScanner`](nbv_core::rig::LineScanner) and
//! [`DepthCamera`](nbv_core::rig::DepthCamera) over the twin world ([`SimRig`]), with the
//! scene's error model between the true and the reported poses ([`PoseErrors`]).

mod joint_reach;
mod pose_errors;
mod sim_rig;
mod timed_path;
mod twin_state;

pub use pose_errors::PoseErrors;
pub use sim_rig::{SimArm, SimDepthCamera, SimLineScanner, SimRig, SimRigError};
pub use twin_state::{
    AcquisitionTruth, CHECK_STEP, MOTION_SAMPLE_RATE_HZ, RigConfig, START_TOLERANCE, SensorKind,
    TwinState, UnknownSensorFrame,
};
