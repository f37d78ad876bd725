//! [`EmulatedTransport`]: a [`DinastTransport`] that owns a [`DinastEmulator`] and its
//! backing camera and answers every transfer in the calling thread (tests, single-threaded
//! tools). A silent device is reported as [`TransportError::Timeout`] at once.

use super::emulator::{DinastEmulator, UsbRequest};
use super::transport::{ControlSetup, DinastTransport, TransportError};
use nbv_core::rig::DepthCamera;
use std::time::Duration;

/// The emulated device and its backing camera, owned together.
pub struct EmulatedTransport {
    /// The device.
    pub emulator: DinastEmulator,
    /// What the device sees.
    pub camera: Box<dyn DepthCamera>,
}

impl EmulatedTransport {
    /// `emulator` backed by `camera`.
    pub fn new(emulator: DinastEmulator, camera: Box<dyn DepthCamera>) -> Self {
        Self { emulator, camera }
    }
}

impl DinastTransport for EmulatedTransport {
    fn control_out(
        &mut self,
        setup: ControlSetup,
        data: &[u8],
        _timeout: Duration,
    ) -> Result<usize, TransportError> {
        let request = UsbRequest::ControlOut {
            setup,
            data: data.to_vec(),
        };
        self.emulator
            .handle(request, self.camera.as_mut())
            .into_written()
    }

    fn control_in(
        &mut self,
        setup: ControlSetup,
        buf: &mut [u8],
        _timeout: Duration,
    ) -> Result<usize, TransportError> {
        let request = UsbRequest::ControlIn {
            setup,
            length: buf.len(),
        };
        self.emulator
            .handle(request, self.camera.as_mut())
            .copy_into(buf)
    }

    fn bulk_read(&mut self, buf: &mut [u8], _timeout: Duration) -> Result<usize, TransportError> {
        let request = UsbRequest::BulkIn { length: buf.len() };
        self.emulator
            .handle(request, self.camera.as_mut())
            .copy_into(buf)
    }
}
