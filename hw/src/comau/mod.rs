//! Comau C4G through a PDL2 server program (`hw/pdl2/nbv_server.pdl`): the line protocol,
//! the client ([`C4gArm`], an [`nbv_core::rig::Arm`]) and the emulator ([`C4gEmulator`]).

mod client;
mod emulator;
mod line_stream;
pub mod protocol;

pub use client::{C4gArm, C4gConfig};
pub use emulator::{C4gEmulator, C4gEmulatorStats, C4gFaults};
pub use line_stream::LineStream;
