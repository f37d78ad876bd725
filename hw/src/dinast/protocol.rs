//! The IPA-1110's vendor control requests (start, stop, firmware version), shared by the
//! driver and the emulator.

use super::transport::{ControlSetup, VENDOR_IN, VENDOR_OUT};
use std::time::Duration;

/// `bRequest` that starts streaming.
pub const REQUEST_START: u8 = 0xC7;
/// `bRequest` that stops streaming.
pub const REQUEST_STOP: u8 = 0xC8;
/// `bRequest` that reads the firmware version.
pub const REQUEST_FIRMWARE_VERSION: u8 = 0xDC;
/// Bytes of the firmware version answer (a NUL-padded string).
pub const FIRMWARE_VERSION_LEN: usize = 21;
/// Timeout of the control transfers (vendor driver).
pub const CONTROL_TIMEOUT: Duration = Duration::from_millis(1000);

/// Setup of the start request (host → device, one data byte).
pub fn start_setup() -> ControlSetup {
    ControlSetup {
        request_type: VENDOR_OUT,
        request: REQUEST_START,
        value: 0x01,
        index: 0,
    }
}

/// Setup of the stop request (host → device, one data byte).
pub fn stop_setup() -> ControlSetup {
    ControlSetup {
        request: REQUEST_STOP,
        ..start_setup()
    }
}

/// Setup of the firmware version request (device → host, [`FIRMWARE_VERSION_LEN`] bytes).
pub fn firmware_version_setup() -> ControlSetup {
    ControlSetup {
        request_type: VENDOR_IN,
        request: REQUEST_FIRMWARE_VERSION,
        value: 0x02,
        index: 0x08,
    }
}

/// The text of a firmware version answer: up to the first NUL, lossy UTF-8, trimmed.
///
/// ```
/// assert_eq!(nbv_hw::dinast::firmware_version_text(b"V1.2 \0\0\0"), "V1.2");
/// ```
pub fn firmware_version_text(answer: &[u8]) -> String {
    let end = answer.iter().position(|&b| b == 0).unwrap_or(answer.len());
    let text = answer.get(..end).unwrap_or_default();
    String::from_utf8_lossy(text).trim().to_string()
}
