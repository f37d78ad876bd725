//! # nbv-sim
//!
//! The twin: a Rapier world built from a scene, in which the simulated arm moves and the
//! simulated sensors cast their rays.

mod convert;
pub mod render;
pub mod world;
