//! [`SerialChain`]: six revolute joints from the root link to the tip link, every link as a
//! named frame rigidly attached to one chain link, and forward kinematics over them.

use super::joints::{DOF, JointLimit, Joints};
use super::link_geometry::LinkGeometry;
use crate::math::Pose;
use nalgebra::{Unit, UnitQuaternion, Vector3};
use std::collections::HashMap;

/// A link name that is not part of the robot.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown frame `{name}` (known frames: {})", known.join(", "))]
pub struct FrameError {
    /// The name asked for.
    pub name: String,
    /// The frames the robot has.
    pub known: Vec<String>,
}

/// One revolute joint of the chain.
#[derive(Debug, Clone)]
pub(crate) struct ChainJoint {
    /// Joint name from the URDF.
    pub name: String,
    /// Pose of the joint frame (at q = 0) in the previous chain link's frame (the root for
    /// J1); fixed joints between the two are folded in.
    pub origin: Pose,
    /// Rotation axis in the joint frame (unit).
    pub axis: Unit<Vector3<f64>>,
    /// Limits.
    pub limit: JointLimit,
}

/// A link seen as a frame: the chain link it is rigidly attached to and the fixed offset.
#[derive(Debug, Clone)]
pub(crate) struct ChainFrame {
    /// Link name.
    pub name: String,
    /// 0 = the root link, k = the child link of joint k (1-based).
    pub attach: usize,
    /// `T_chainlink_frame`.
    pub offset: Pose,
}

/// The kinematic model read from a URDF.
#[derive(Debug, Clone)]
pub(crate) struct SerialChain {
    /// The `<robot name>`.
    pub name: String,
    /// Revolute joints, base to tip.
    pub joints: [ChainJoint; DOF],
    /// Their limits (copy of `joints[i].limit`, for borrowing as a slice).
    pub limits: [JointLimit; DOF],
    /// Every link, in URDF document order.
    pub frames: Vec<ChainFrame>,
    /// Link names in the same order.
    pub frame_names: Vec<String>,
    /// Name -> index into `frames`.
    pub frame_index: HashMap<String, usize>,
    /// Collision primitives of all links.
    pub collisions: Vec<LinkGeometry>,
    /// Visual primitives of all links.
    pub visuals: Vec<LinkGeometry>,
    /// Index of the root link's frame.
    pub root: usize,
    /// Index of the tip link's frame (child of the last joint).
    pub tip: usize,
}

impl SerialChain {
    /// Index of a frame by name.
    pub fn find(&self, name: &str) -> Result<usize, FrameError> {
        self.frame_index
            .get(name)
            .copied()
            .ok_or_else(|| FrameError {
                name: name.to_owned(),
                known: self.frame_names.clone(),
            })
    }

    /// Poses of the chain links in the root frame: entry 0 is the root (identity), entry k
    /// the child link of joint k.
    pub fn link_chain_poses(&self, q: &Joints) -> [Pose; DOF + 1] {
        let mut out = [Pose::identity(); DOF + 1];
        for (k, joint) in self.joints.iter().enumerate() {
            let rot = UnitQuaternion::from_axis_angle(&joint.axis, q[k]);
            out[k + 1] = out[k] * joint.origin * Pose::from_parts(Default::default(), rot);
        }
        out
    }

    /// Poses of the joint frames in the root frame before each joint's own rotation is
    /// applied (so axis k passes through `frames[k].translation` along
    /// `frames[k].rotation * joints[k].axis`).
    pub fn joint_frames(&self, q: &Joints) -> [Pose; DOF] {
        let links = self.link_chain_poses(q);
        std::array::from_fn(|k| links[k] * self.joints[k].origin)
    }

    /// World axes (unit) and points on them for every joint at `q`.
    pub fn joint_axes(&self, q: &Joints) -> [(Vector3<f64>, Vector3<f64>); DOF] {
        let frames = self.joint_frames(q);
        std::array::from_fn(|k| {
            (
                frames[k].rotation * self.joints[k].axis.into_inner(),
                frames[k].translation.vector,
            )
        })
    }

    /// Pose of frame `index` in the root frame.
    pub fn frame_pose(&self, q: &Joints, index: usize) -> Option<Pose> {
        let frame = self.frames.get(index)?;
        let links = self.link_chain_poses(q);
        Some(links[frame.attach] * frame.offset)
    }

    /// Pose of the tip link in the root frame.
    pub fn tip_pose(&self, q: &Joints) -> Pose {
        let links = self.link_chain_poses(q);
        links[DOF]
    }

    /// Poses of all frames, in `frame_names` order.
    pub fn all_frame_poses(&self, q: &Joints) -> Vec<Pose> {
        let links = self.link_chain_poses(q);
        self.frames
            .iter()
            .map(|f| links[f.attach] * f.offset)
            .collect()
    }
}
