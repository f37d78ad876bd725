//! Motion planning in joint space for the arm (the paper's PlanAndExecute, Algorithm 1
//! lines 13–16): a collision model of the robot among the reduced map's voxels, the known
//! obstacles and itself, and a bidirectional RRT with multiple goals.
//!
//! - [`CollisionWorld`]: robot primitives (from the URDF) at `link_poses(q)` against
//!   [`Obstacle`]s (cuboids, triangle meshes), the occupied and unknown voxels of a
//!   [`ReducedMap`](crate::occupancy::ReducedMap) (bitset broad phase over the lattice,
//!   exact bounds from each link's core, parry's GJK where they leave a voxel open) and
//!   non-adjacent links;
//! - [`MotionBound`]: per-joint lever arms, so edges are checked finely enough that no
//!   point of the robot moves more than a given distance between checks;
//! - [`MotionPlanner`]: RRT-Connect from the start to every IK solution of the viewpoint,
//!   shortcutting, typed failures ([`PlanningError`]) after which the caller tries the next
//!   viewpoint; the result is a [`JointPath`](crate::rig::JointPath) and [`PlanStats`].
//!
//! parry3d works in f32 with glam types; the project stays in nalgebra f64 and converts in
//! one module at the boundary (`parry_bridge`; `shape_core` reads the dimensions of parry's
//! primitives for its bounds).
//!
//! # Start configurations in collision
//!
//! Unknown space may envelop the arm (e.g. voxels behind the sensor that no ray cleared).
//! The planner does not hide this: it returns [`PlanningError::StartInCollision`] with the
//! contact. When the contact is with map voxels only ([`Collision::is_voxel`]), the caller
//! may collect them with [`CollisionWorld::colliding_voxels`], drop them with
//! [`CollisionWorld::ignore_voxels`] and plan again.

mod collision_world;
mod motion_bound;
mod motion_planner;
mod obstacle;
mod parry_bridge;
mod path_shortcut;
mod planner_config;
mod planning_error;
mod robot_shapes;
mod shape_core;
mod voxel_obstacles;

pub use collision_world::{Collision, CollisionTarget, CollisionWorld};
pub use motion_bound::MotionBound;
pub use motion_planner::{MotionPlanner, PlanStats, PlannedPath};
pub use obstacle::{Obstacle, ObstacleShape};
pub use path_shortcut::path_length;
pub use planner_config::PlannerConfig;
pub use planning_error::PlanningError;
