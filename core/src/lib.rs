//! # nbv-core
//!
//! The exploration pipeline of nbv-twin, after Aleotti et al., *Global registration of
//! mid-range 3D observations and short range next best views* (IROS 2014).
//!
//! This crate knows nothing of Rapier or of any device driver: the pipeline is generic over
//! the rig traits, which the twin (`nbv-sim`) and the real drivers (`nbv-hw`) implement.
//!
//! Conventions used throughout:
//! - lengths in metres, angles in radians, poses as [`math::Pose`] (`Isometry3<f64>`);
//! - the world frame is the robot base frame: x forward, y left, z up, floor at z = 0;
//! - a pose `T_a_b` maps coordinates in frame `b` to frame `a`.

pub mod atomic_file;
pub mod calibration;
pub mod cloud;
pub mod evaluation;
pub mod kinematics;
pub mod math;
pub mod mesh;
pub mod nbv;
pub mod occupancy;
pub mod perception;
pub mod pipeline;
pub mod planning;
pub mod registration;
pub mod rig;
pub mod surface;
