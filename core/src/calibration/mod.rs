//! The rig's calibration while it explores: what is known of its sensors' noise and
//! poses ([`PoseUncertainty`]: the registration's weights and priors), what the table
//! tells about each camera view's pose ([`TableEvidence`]), and the self-calibration that
//! estimates the depth camera's hand-eye correction and the joint offsets from every
//! object's registration ([`estimate_hand_eye`]). The pipeline registers each object
//! again from the calibrated poses.

mod hand_eye;
mod pose_uncertainty;
mod table_evidence;

pub use hand_eye::{HandEyeEstimate, estimate_hand_eye, identifiable_mount};
pub use pose_uncertainty::PoseUncertainty;
pub use table_evidence::TableEvidence;

pub(crate) use hand_eye::correction_pose;
