//! The subcommands of `nbv`, one module each.

pub mod explore;
pub mod explore_pictures;
pub mod explore_report;
#[cfg(feature = "hw")]
pub mod hw_backend;
pub mod map;
pub mod progress;
pub mod register;
pub mod render;
pub mod scan;
pub mod scene;
pub mod sweep;
pub mod sweep_gate;
pub mod sweep_grid;
pub mod sweep_plots;
pub mod sweep_results;
pub mod views;
