//! The subcommands of `nbv`, one module each.

pub mod scan;
pub mod scene;
