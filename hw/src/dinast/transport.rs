//! [`DinastTransport`]: the three USB operations the Dinast driver needs (vendor control
//! out, vendor control in, bulk in), and [`TransportError`], how they fail.
//!
//! The driver only talks to this trait, so it runs unchanged over libusb
//! ([`super::UsbTransport`]) or over the emulated device ([`super::ChannelTransport`],
//! [`super::EmulatedTransport`]).

use std::time::Duration;
use thiserror::Error;

/// `bmRequestType` of a vendor request to the device, host to device.
pub const VENDOR_OUT: u8 = 0x40;
/// `bmRequestType` of a vendor request to the device, device to host.
pub const VENDOR_IN: u8 = 0xC0;

/// The setup stage of a control transfer (everything but the data).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ControlSetup {
    /// `bmRequestType` ([`VENDOR_OUT`] or [`VENDOR_IN`] for this camera).
    pub request_type: u8,
    /// `bRequest`.
    pub request: u8,
    /// `wValue`.
    pub value: u16,
    /// `wIndex`.
    pub index: u16,
}

/// Why a USB transfer failed.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum TransportError {
    /// The device did not complete the transfer in time.
    #[error("USB transfer timed out")]
    Timeout,
    /// The device is gone (unplugged, or the emulated device was dropped).
    #[error("device unplugged")]
    NoDevice,
    /// The device rejected the request (a USB STALL).
    #[error("request stalled by the device")]
    Stall,
    /// Any other USB failure.
    #[error("USB I/O error: {0}")]
    Io(String),
}

/// The USB operations of the Dinast driver. Every call has a timeout and never blocks
/// longer than it (plus scheduling slack).
pub trait DinastTransport {
    /// Control transfer host → device with `data`; returns the bytes written.
    fn control_out(
        &mut self,
        setup: ControlSetup,
        data: &[u8],
        timeout: Duration,
    ) -> Result<usize, TransportError>;

    /// Control transfer device → host into `buf`; returns the bytes read.
    fn control_in(
        &mut self,
        setup: ControlSetup,
        buf: &mut [u8],
        timeout: Duration,
    ) -> Result<usize, TransportError>;

    /// Bulk transfer from the first bulk-in endpoint into `buf`; returns the bytes read
    /// (possibly fewer than `buf.len()`).
    fn bulk_read(&mut self, buf: &mut [u8], timeout: Duration) -> Result<usize, TransportError>;
}

/// A borrowed transport is a transport (the caller keeps the transport, e.g. to inspect
/// an emulator after the driver is dropped).
impl<T: DinastTransport + ?Sized> DinastTransport for &mut T {
    fn control_out(
        &mut self,
        setup: ControlSetup,
        data: &[u8],
        timeout: Duration,
    ) -> Result<usize, TransportError> {
        (**self).control_out(setup, data, timeout)
    }

    fn control_in(
        &mut self,
        setup: ControlSetup,
        buf: &mut [u8],
        timeout: Duration,
    ) -> Result<usize, TransportError> {
        (**self).control_in(setup, buf, timeout)
    }

    fn bulk_read(&mut self, buf: &mut [u8], timeout: Duration) -> Result<usize, TransportError> {
        (**self).bulk_read(buf, timeout)
    }
}
