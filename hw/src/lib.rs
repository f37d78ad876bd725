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
//! `Send` ([`emulated_rig`]).
//!
//! With `hw`: a [`rig_file`] says where the devices are and how the sensors are mounted,
//! [`hw_rig::HwRig`] connects the three drivers, and [`emulated_rig::EmulatedRig`] serves
//! them from any backing rig. `nbv explore --backend hw --rig FILE [--emulate]` uses these.
//!
//! What each wire protocol is, and the decisions where public sources disagree, is in the
//! module docs: [`lms400`] (CoLa framing, telegram layout and trailer), [`comau`] (the line
//! protocol of `hw/pdl2/nbv_server.pdl`), [`dinast`] (USB requests, packet sync, the vendor
//! raw-to-distance model and the resampling onto the pinhole grid).

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
