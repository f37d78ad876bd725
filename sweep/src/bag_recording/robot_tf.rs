//! [`RobotTf`]: the robot as tf2 sees it — the URDF's joint tree, each joint a transform
//! from its parent link to its child link as robot_state_publisher publishes them (fixed
//! joints once on `/tf_static`, the moving ones on `/tf` per joint sample), the world→root
//! and world→table frames, and `/joint_states`.
//!
//! The transforms come from the kinematic model the pipeline uses
//! ([`Robot::link_poses`]: `T_parent_child = T_root_parent⁻¹ · T_root_child`), so looking up
//! the camera's link in `world` at a joint sample gives the pipeline's sensor pose
//! (`base · FK(q, camera)`).

use super::stamps::header;
use super::topics::{TABLE, WORLD};
use crate::error::{Context, Result};
use nbv_bag::messages::{JointState, TFMessage, Transform, TransformStamped};
use nbv_core::kinematics::{Joints, Robot};
use nbv_core::math::Pose;
use nbv_scenes::Scene;

/// One URDF joint between two links the kinematic model knows.
#[derive(Debug, Clone)]
struct Edge {
    parent: String,
    child: String,
    parent_index: usize,
    child_index: usize,
}

/// The robot's frames for tf2.
#[derive(Debug, Clone)]
pub struct RobotTf {
    robot: Robot,
    base: Pose,
    table: Pose,
    fixed: Vec<Edge>,
    moving: Vec<Edge>,
    joint_names: Vec<String>,
}

impl RobotTf {
    /// The joint tree of `urdf` (the text of `scene.robot.urdf`) over `robot` (its model),
    /// mounted at the scene's base pose.
    pub fn new(scene: &Scene, urdf: &str, robot: Robot) -> Result<Self> {
        let parsed = urdf_rs::read_from_string(urdf)
            .with_context(|| format!("reading {}", scene.robot.urdf.display()))?;
        let mut fixed = Vec::new();
        let mut moving = Vec::new();
        for joint in &parsed.joints {
            let (Some(parent_index), Some(child_index)) = (
                robot.frame_index(&joint.parent.link),
                robot.frame_index(&joint.child.link),
            ) else {
                continue;
            };
            let edge = Edge {
                parent: joint.parent.link.clone(),
                child: joint.child.link.clone(),
                parent_index,
                child_index,
            };
            if joint.joint_type == urdf_rs::JointType::Fixed {
                fixed.push(edge);
            } else {
                moving.push(edge);
            }
        }
        let t = &scene.table;
        let table = Pose::translation(
            0.5 * (t.min[0] + t.max[0]),
            0.5 * (t.min[1] + t.max[1]),
            t.top(),
        );
        let joint_names = robot.joint_names().map(str::to_owned).to_vec();
        Ok(Self {
            robot,
            base: scene.robot.base.to_pose(),
            table,
            fixed,
            moving,
            joint_names,
        })
    }

    /// The kinematic model.
    pub fn robot(&self) -> &Robot {
        &self.robot
    }

    /// `/tf_static` at stamp `ns`: world→root link (the base pose), world→table, and every
    /// fixed joint (the flange, the bracket, the laser's and the camera's mounts).
    pub fn static_transforms(&self, ns: u64) -> TFMessage {
        let poses = self.robot.link_poses(&Joints::zeros());
        let mut transforms = vec![
            stamped(WORLD, self.robot.base_frame(), &self.base, ns),
            stamped(WORLD, TABLE, &self.table, ns),
        ];
        transforms.extend(self.fixed.iter().map(|e| edge(e, &poses, ns)));
        TFMessage { transforms }
    }

    /// `/tf` at stamp `ns`: every moving joint at `q`, parent link → child link.
    pub fn moving_transforms(&self, q: &Joints, ns: u64) -> TFMessage {
        let poses = self.robot.link_poses(q);
        TFMessage {
            transforms: self.moving.iter().map(|e| edge(e, &poses, ns)).collect(),
        }
    }

    /// `/joint_states` at stamp `ns`: the six joints' names (URDF) and positions (rad).
    pub fn joint_state(&self, q: &Joints, ns: u64) -> JointState {
        JointState {
            header: header("", ns),
            name: self.joint_names.clone(),
            position: q.iter().copied().collect(),
            velocity: Vec::new(),
            effort: Vec::new(),
        }
    }
}

/// A URDF joint's transform at the link poses `poses` (root frame).
fn edge(e: &Edge, poses: &[Pose], ns: u64) -> TransformStamped {
    let pose = poses[e.parent_index].inverse() * poses[e.child_index];
    stamped(&e.parent, &e.child, &pose, ns)
}

/// `child`'s pose in `parent` at stamp `ns`.
pub fn stamped(parent: &str, child: &str, pose: &Pose, ns: u64) -> TransformStamped {
    TransformStamped {
        header: header(parent, ns),
        child_frame_id: child.to_owned(),
        transform: Transform::from_isometry(pose),
    }
}
