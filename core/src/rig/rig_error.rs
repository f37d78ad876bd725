//! [`RigError`]: how a rig reports that it could not do what the pipeline asked.

use thiserror::Error;

/// A failure of the arm or of a sensor.
#[derive(Debug, Error)]
pub enum RigError {
    /// The motion would hit something (the twin checks the true world); the arm stopped.
    #[error("collision of {link} with {with} at t = {time:.3} s")]
    Collision {
        /// Robot link in contact.
        link: String,
        /// What it touched.
        with: String,
        /// Rig time of the first contact, seconds.
        time: f64,
    },
    /// A commanded configuration is outside the joint limits.
    #[error("joint {joint} at {value_deg:.2}° is outside its limits")]
    JointLimit {
        /// Joint index (0-based).
        joint: usize,
        /// Commanded value, degrees.
        value_deg: f64,
    },
    /// The path is malformed (no waypoint, bad speed fraction, NaN).
    #[error("invalid path: {0}")]
    InvalidPath(String),
    /// A device did not answer in time.
    #[error("{device}: no answer within {seconds:.1} s")]
    Timeout {
        /// Device name.
        device: String,
        /// Timeout, seconds.
        seconds: f64,
    },
    /// A device connection was lost or refused.
    #[error("{device}: disconnected: {detail}")]
    Disconnected {
        /// Device name.
        device: String,
        /// What happened.
        detail: String,
    },
    /// A device answered something the driver does not understand.
    #[error("{device}: protocol error: {detail}")]
    Protocol {
        /// Device name.
        device: String,
        /// What was wrong.
        detail: String,
    },
    /// The call is not valid in the device's current state (e.g. stop without start).
    #[error("{device}: {detail}")]
    State {
        /// Device name.
        device: String,
        /// What was wrong.
        detail: String,
    },
}
