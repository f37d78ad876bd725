//! # nbv-sweep
//!
//! Episodes of nbv-twin measured against the twin's truth, and sweeps of them — the
//! library behind `nbv explore` and `nbv sweep`; the binary parses arguments and prints.
//!
//! - [`episode`]: one exploration in the twin and its outputs (report, models, map).
//! - [`report`]: [`report::ExploreReport`], an exploration measured against the scene's
//!   truth (quality, coverage, registration and alignment errors); [`matching`]: which
//!   scene object a cluster is.
//! - [`pictures`]: the episode's PNG pictures (headless renderer).
//! - [`grid`]: a sweep's grid file and its episodes; [`shard`]: `I/N`; [`slurm`]: the grid as a Slurm job array and its merge (`nbv sweep submit`).
//! - [`engine`]: run, resume and merge a sweep; [`layout`]: the sweep directory.
//! - [`results`]: rows, CSV, aggregates, best settings, registration and robustness
//!   tables; [`objectives`]: the view-objective comparison; [`gate`]: `--require` gates;
//!   [`plots`]: SVG plots.
//! - [`map_stats`]: `stats.json` of `nbv map` (phase 1 on a cloud file).
//! - [`views`]: what `nbv views` lists — each object's next-best-view candidates,
//!   planned and checked in the twin.
//! - [`recording`] (feature `rerun`): `episode.rrd`, an episode for the Rerun viewer.
//! - [`bag_recording`]: `bag/`, an episode as a ROS 2 bag (rosbag2, MCAP) for RViz,
//!   Foxglove and `ros2 bag play`.
//! - [`tune`]: `nbv tune` — scene parameters tuned by Bayesian optimisation over
//!   training episodes, a Pareto front of two objectives, checked on unseen seeds.
//! - [`error`]: the error type, [`SweepError`].

pub mod bag_recording;
pub mod engine;
pub mod episode;
pub mod error;
pub mod gate;
pub mod grid;
pub mod layout;
pub mod map_stats;
pub mod matching;
pub mod objectives;
pub mod oracle;
pub mod pictures;
pub mod plots;
#[cfg(feature = "rerun")]
pub mod recording;
pub mod report;
pub mod rows;
pub mod shard;
pub mod slurm;
pub mod tune;
pub mod views;

pub use error::{Result, SweepError};
