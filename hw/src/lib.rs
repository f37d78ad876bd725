//! # nbv-hw
//!
//! Drivers for the real rig, one cargo feature per device (`lms400`, `comau`, `dinast`;
//! `hw` enables all three). Each driver implements nbv-core's rig traits
//! ([`nbv_core::rig::Arm`], [`nbv_core::rig::LineScanner`], [`nbv_core::rig::DepthCamera`]),
//! so the pipeline runs unchanged on the twin or on the real devices.
//!
//! Every device also has a wire-level emulator that speaks its protocol and is backed by any
//! implementation of the same trait (the CLI and the tests plug in the twin), so the drivers
//! are exercised byte for byte without hardware. The emulators are poll-driven and
//! single-threaded: one thread can serve all three devices from a twin whose parts are not
//! `Send`.

#[cfg(feature = "comau")]
pub mod comau;
#[cfg(feature = "dinast")]
pub mod dinast;
#[cfg(feature = "lms400")]
pub mod lms400;

mod config_error;
pub use config_error::ConfigError;

#[cfg(feature = "hw")]
pub mod emulated_rig;
#[cfg(feature = "hw")]
pub mod hw_rig;
#[cfg(feature = "hw")]
pub mod rig_file;
