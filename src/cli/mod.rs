//! The subcommands of `nbv`, one module each.

pub mod explore;
pub mod explore_pictures;
pub mod explore_report;
pub mod map;
pub mod progress;
pub mod register;
pub mod render;
pub mod scan;
pub mod scene;
pub mod views;
