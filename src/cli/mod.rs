//! The subcommands of `nbv`, one module each.

pub mod map;
pub mod render;
pub mod register;
pub mod scene;
