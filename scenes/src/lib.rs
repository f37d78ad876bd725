//! # nbv-scenes
//!
//! Scene files (TOML): the workspace, the robot, the sensors, the objects and obstacles on
//! the table, the planner/NBV/registration parameters, the error model and the seed.

pub mod meshgen;
