//! [`PlanningError`]: why a motion could not be planned.

use super::Collision;
use crate::kinematics::IkError;

/// A planning failure. The failures a caller acts on by trying the next viewpoint are
/// [`StartInCollision`](Self::StartInCollision),
/// [`NoGoalCollisionFree`](Self::NoGoalCollisionFree) and
/// [`BudgetExhausted`](Self::BudgetExhausted); the others report bad input.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PlanningError {
    /// A planner parameter is out of its range.
    #[error("invalid planner parameter `{name}` = {value}: {reason}")]
    InvalidConfig {
        /// Parameter name.
        name: &'static str,
        /// The value given.
        value: f64,
        /// What is required.
        reason: &'static str,
    },
    /// A configuration contains NaN or infinity.
    #[error("the {0} is not finite")]
    NonFinite(&'static str),
    /// The start configuration breaks a joint limit.
    #[error("start configuration: joint {joint} = {value:.6} rad is outside its limits")]
    StartOutOfLimits {
        /// Joint index (0-based).
        joint: usize,
        /// Its value (rad).
        value: f64,
    },
    /// The start configuration is in collision. If only map voxels are involved (unknown
    /// space enveloping the arm), the caller may clear them with
    /// [`CollisionWorld::ignore_voxels`](super::CollisionWorld::ignore_voxels) and retry.
    #[error("start configuration is in collision: {0}")]
    StartInCollision(Collision),
    /// No goal configuration was given.
    #[error("no goal configuration given")]
    NoGoal,
    /// Every goal is outside the joint limits or in collision.
    #[error(
        "none of {goals} goal configurations is usable ({out_of_limits} outside the limits, {in_collision} in collision{})",
        first.as_ref().map(|c| format!("; first: {c}")).unwrap_or_default()
    )]
    NoGoalCollisionFree {
        /// Goals given.
        goals: usize,
        /// Goals outside the joint limits.
        out_of_limits: usize,
        /// Goals in collision.
        in_collision: usize,
        /// The collision of the first goal in collision.
        first: Option<Collision>,
    },
    /// The iteration budget ran out before the trees connected.
    #[error(
        "no path found within {iterations} iterations ({nodes} nodes, {start_nodes} of them from the start)"
    )]
    BudgetExhausted {
        /// Iterations run.
        iterations: usize,
        /// Nodes in both trees.
        nodes: usize,
        /// Nodes in the start's tree.
        start_nodes: usize,
    },
    /// The goal pose has no IK solution (see [`MotionPlanner::plan_to_pose`](super::MotionPlanner::plan_to_pose)).
    #[error("goal pose: {0}")]
    Ik(#[from] IkError),
    /// A robot collision shape the planner cannot use (URDF meshes are not loaded).
    #[error("link `{link}`: unsupported collision shape ({shape})")]
    UnsupportedLinkShape {
        /// The link.
        link: String,
        /// What it is.
        shape: &'static str,
    },
    /// An obstacle with bad geometry.
    #[error("obstacle `{name}`: {reason}")]
    InvalidObstacle {
        /// Its name.
        name: String,
        /// What is wrong.
        reason: String,
    },
}
