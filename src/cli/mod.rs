//! The subcommands of `nbv`, one module each.

pub mod map;
pub mod register;
pub mod render;
pub mod scan;
pub mod scene;
