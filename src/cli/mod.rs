//! The subcommands of `nbv`, one module each.

pub mod register;
pub mod scene;
