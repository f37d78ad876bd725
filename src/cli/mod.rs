//! The subcommands of `nbv`, one module each.

pub mod scan;
pub mod map;
pub mod render;
pub mod scene;
