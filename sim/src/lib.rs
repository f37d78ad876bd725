//! # nbv-sim
//!
//! The twin: a Rapier world built from a scene ([`world`]), in which the simulated arm
//! moves and the simulated sensors cast their rays ([`sensors`]), assembled into a rig
//! that implements nbv-core's traits ([`rig`]), and a headless renderer ([`render`]).
//!
//! Everything random is seeded from the scene seed through counter-based streams (one per
//! scan line, depth-frame row and view), so the same scene and seed give the same data
//! whatever the rayon thread count.

mod convert;
pub mod render;
pub mod rig;
mod seeds;
pub mod sensors;
pub mod world;
