//! [`IkError`] and [`Unreachable`]: why an inverse-kinematics query has no answer.

use super::ortho_parallel::IkStructureError;
use super::serial_chain::FrameError;

/// Why `Robot::ik` returned no solution.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum IkError {
    /// The frame is not a link of the robot.
    #[error(transparent)]
    Frame(#[from] FrameError),
    /// The frame does not move rigidly with the tip link, so a pose of it does not fix the
    /// joint angles.
    #[error("frame `{frame}` is not rigidly attached to the tip link `{tip}`")]
    NotOnTip {
        /// The frame asked for.
        frame: String,
        /// The tip link.
        tip: String,
    },
    /// The closed-form solver does not apply to this robot's geometry.
    #[error("closed-form IK does not apply to this robot: {0}")]
    Unsupported(#[from] IkStructureError),
    /// The target pose or the reference configuration contains NaN or infinity.
    #[error("the {0} is not finite")]
    NonFinite(&'static str),
    /// Closed-form solutions within the limits exist but miss the pose on the exact chain
    /// and numerical polishing did not fix them (a chain far from the ortho-parallel class).
    #[error(
        "{solutions} closed-form solutions within the limits miss the pose and could not be polished"
    )]
    NotConverged {
        /// How many.
        solutions: usize,
    },
    /// The pose cannot be reached.
    #[error("unreachable: {0}")]
    Unreachable(#[from] Unreachable),
}

/// Why a pose cannot be reached. Positions are in the robot's root frame, distances in m.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Unreachable {
    /// The wrist centre is farther from the shoulder than the stretched arm reaches.
    #[error("wrist centre {wrist_centre:?} is {by:.4} m beyond the stretched arm")]
    TooFar {
        /// Required wrist centre.
        wrist_centre: [f64; 3],
        /// Shortfall of the arm.
        by: f64,
    },
    /// The wrist centre is closer to the shoulder than the folded arm allows.
    #[error("wrist centre {wrist_centre:?} is {by:.4} m too close to the shoulder")]
    TooClose {
        /// Required wrist centre.
        wrist_centre: [f64; 3],
        /// How much closer than the folded arm.
        by: f64,
    },
    /// The wrist centre is nearer the J1 axis than the arm's lateral offset.
    #[error(
        "wrist centre {wrist_centre:?} is {by:.4} m inside the lateral-offset cylinder around J1"
    )]
    InsideOffset {
        /// Required wrist centre.
        wrist_centre: [f64; 3],
        /// Depth inside the cylinder.
        by: f64,
    },
    /// The pose is reachable by the geometry, but every solution breaks a joint limit.
    #[error("all {solutions} geometric solutions violate the joint limits")]
    JointLimits {
        /// Number of geometric solutions found (before the limits).
        solutions: usize,
    },
}
