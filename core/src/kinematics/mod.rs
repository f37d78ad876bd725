//! Kinematics of the six-axis arm: the serial chain read from URDF, forward kinematics to
//! every link, the links' collision and visual primitives as plain data, and closed-form
//! inverse kinematics for ortho-parallel arms with a spherical wrist (the Comau SMART SiX).
//!
//! The entry point is [`Robot`]. Joint vectors are [`Joints`] (radians, J1..J6); poses are
//! [`Pose`](crate::math::Pose)s in the URDF's root frame.

mod ik_error;
mod ik_solution;
mod joints;
mod link_geometry;
mod newton_refine;
mod ortho_parallel;
mod robot;
mod rotation_subproblems;
mod serial_chain;
mod urdf_error;
mod urdf_loader;

#[cfg(test)]
mod comau_tests;

pub use ik_error::{IkError, Unreachable};
pub use ik_solution::{
    Branch, Elbow, IkSolution, SINGULARITY_MARGIN, Shoulder, Singularity, Wrist,
};
pub use joints::{DOF, JointLimit, Joints};
pub use link_geometry::{LinkGeometry, Shape};
pub use ortho_parallel::{IkStructureError, OrthoParallelParams, STRUCTURE_TOLERANCE};
pub use robot::Robot;
pub use serial_chain::FrameError;
pub use urdf_error::UrdfError;
