//! The subcommands of `nbv`, one module each.

pub mod scene;
