//! [`IkSolution`]: one inverse-kinematics configuration with its arm/elbow/wrist branch and
//! the singularities it sits at.

use super::joints::Joints;
use serde::{Deserialize, Serialize};

/// Distance (m or rad, see [`Singularity`]) under which a solution is flagged singular.
pub const SINGULARITY_MARGIN: f64 = 1e-6;

/// One joint configuration that places the requested frame at the requested pose.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct IkSolution {
    /// The joint angles (within the joint limits).
    pub joints: Joints,
    /// Which of the up to eight closed-form branches it is.
    pub branch: Branch,
    /// Singular configurations it is at (or within [`SINGULARITY_MARGIN`] of).
    pub singularity: Singularity,
}

/// The closed-form branch of a solution. Ordered shoulder, then elbow, then wrist.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
pub struct Branch {
    /// Side of the J1 axis the wrist centre is reached from.
    pub shoulder: Shoulder,
    /// Side of the shoulder–wrist line the elbow is on.
    pub elbow: Elbow,
    /// Side of the wrist singularity J5 is on.
    pub wrist: Wrist,
}

/// Shoulder branch.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
pub enum Shoulder {
    /// The wrist centre lies on the side of the J1 axis towards which the shoulder offset
    /// points (the arm reaches forward).
    Front,
    /// J1 turned by about half a turn: the arm leans back over the J1 axis.
    Back,
}

/// Elbow branch.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
pub enum Elbow {
    /// The elbow is on the side of the shoulder–wrist line it takes when the arm reaches
    /// forward with the elbow raised (the Comau's calibration pose is elbow-up).
    Up,
    /// The other side.
    Down,
}

/// Wrist branch.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
pub enum Wrist {
    /// J5 on the positive side of the configuration where J4 and J6 align (for the Comau:
    /// J5 ≥ 0).
    Positive,
    /// J5 on the negative side.
    Negative,
}

/// Singular configurations a solution is at. At an exact singularity the free angle is
/// taken from the reference configuration (see `Robot::ik` and `Robot::ik_nearest`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct Singularity {
    /// The wrist centre is on the J1 axis (for arms with a lateral offset: on the cylinder of
    /// that radius around it), within [`SINGULARITY_MARGIN`] metres: J1 is free.
    pub shoulder: bool,
    /// The arm is fully stretched or folded: the elbow angle is within
    /// [`SINGULARITY_MARGIN`] radians of 0 or π (boundary of the workspace).
    pub elbow: bool,
    /// J4 and J6 are aligned (for the Comau: J5 within [`SINGULARITY_MARGIN`] radians of
    /// 0): only J4 + J6 is determined.
    pub wrist: bool,
}

impl Singularity {
    /// Whether any flag is set.
    pub fn any(&self) -> bool {
        self.shoulder || self.elbow || self.wrist
    }
}
