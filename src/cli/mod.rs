//! The subcommands of `nbv`, one module each.

pub mod bag_views;
pub mod explore;
pub mod explore_summary;
pub mod fuse;
#[cfg(feature = "hw")]
pub mod hw_backend;
pub mod map;
pub mod oracle;
pub mod progress;
pub mod register;
pub mod render;
pub mod scan;
pub mod scene;
pub mod sweep;
pub mod tune;
pub mod views;
