//! Kinematics of the six-axis arm: the serial chain read from URDF, forward kinematics to
//! every link, the links' collision and visual primitives as plain data, and closed-form
//! inverse kinematics for ortho-parallel arms with a spherical wrist (the Comau SMART SiX).
//!
//! The entry point is [`Robot`]. Joint vectors are [`Joints`] (radians, J1..J6); poses are
//! [`Pose`](crate::math::Pose)s in the URDF's root frame.
//!
//! # The Comau SMART SiX model ([`COMAU_URDF`])
//!
//! - Joint angles are Comau's native angles; J3 = -90° with the rest 0 is the calibration
//!   pose (forearm horizontal along +x, all link frames parallel to `base_link`, wrist
//!   centre at (0.79707, 0, 1.17)). Axes: J1 -z, J2 +y, J3 -y, J4 -x, J5 +y, J6 -x.
//! - `tool0`: flange frame, z out of the flange; x points down and y left in the
//!   calibration pose. `ee_bracket` coincides with `tool0`.
//! - Sensor frames (relative to `tool0`), both looking along `tool0` +z, optical
//!   convention (z forward, x right, y down in the calibration pose, i.e. x = `tool0` -y,
//!   y = `tool0` +x):
//!   `lms400` at (-0.080, 0, 0.140), its scan fan in its x-z plane, sweep along y;
//!   `dinast` at (0.045, 0, 0.150). Each origin is the centre of the sensor's front window.

mod comau_asset;
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

pub use comau_asset::{COMAU_URDF, comau_smart_six};
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
