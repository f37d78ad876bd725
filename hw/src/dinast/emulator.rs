//! [`DinastEmulator`]: the device side of the IPA-1110's USB protocol, backed by any
//! [`DepthCamera`] (the twin's, or a fake), with fault injection ([`DinastFaults`]).
//!
//! It answers one USB request at a time ([`UsbRequest`] → [`UsbReply`]): the vendor control
//! requests like the device (anything else stalls), and, while started, bulk reads with
//! the device's byte stream: one packet per frame captured from the backing camera,
//! encoded with the vendor model ([`RawEncoder`]). A bulk read while stopped gets no answer
//! (the transfer times out), as on a device that is not streaming. Transports carry the
//! requests to it: [`super::ChannelTransport`] across threads, [`super::EmulatedTransport`]
//! in the same thread.

use super::frame::{HEADER_LEN, IMAGE_LEN, PACKET_LEN};
use super::protocol::{FIRMWARE_VERSION_LEN, firmware_version_setup, start_setup, stop_setup};
use super::resample::RawEncoder;
use super::transport::{ControlSetup, TransportError};
use nbv_core::rig::DepthCamera;

/// One USB transfer as the device sees it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum UsbRequest {
    /// Control transfer host → device.
    ControlOut {
        /// Setup stage.
        setup: ControlSetup,
        /// Data stage.
        data: Vec<u8>,
    },
    /// Control transfer device → host.
    ControlIn {
        /// Setup stage.
        setup: ControlSetup,
        /// `wLength`.
        length: usize,
    },
    /// Bulk read of at most `length` bytes.
    BulkIn {
        /// Host buffer size.
        length: usize,
    },
}

/// The device's answer to a [`UsbRequest`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum UsbReply {
    /// Bytes accepted (control out).
    Written(usize),
    /// Bytes sent (control in, bulk in).
    Data(Vec<u8>),
    /// The transfer failed.
    Failed(TransportError),
    /// No answer: the host's transfer times out.
    Silent,
}

impl UsbReply {
    /// The host's result for an out transfer.
    pub fn into_written(self) -> Result<usize, TransportError> {
        match self {
            Self::Written(count) => Ok(count),
            Self::Data(_) => Err(TransportError::Io("data answer to an out transfer".into())),
            Self::Failed(error) => Err(error),
            Self::Silent => Err(TransportError::Timeout),
        }
    }

    /// The host's result for an in transfer: copies the data into `buf` (cut to its size).
    pub fn copy_into(self, buf: &mut [u8]) -> Result<usize, TransportError> {
        match self {
            Self::Data(data) => {
                let count = data.len().min(buf.len());
                if let (Some(to), Some(from)) = (buf.get_mut(..count), data.get(..count)) {
                    to.copy_from_slice(from);
                }
                Ok(count)
            }
            Self::Written(_) => Err(TransportError::Io("no data in an in transfer".into())),
            Self::Failed(error) => Err(error),
            Self::Silent => Err(TransportError::Timeout),
        }
    }
}

/// Faults the emulator injects.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct DinastFaults {
    /// After this many answered bulk reads, the device is unplugged: every later request
    /// fails with [`TransportError::NoDevice`].
    pub unplug_after_reads: Option<usize>,
    /// After this many answered bulk reads, the device stops answering anything.
    pub silent_after_reads: Option<usize>,
    /// Bytes of garbage (never containing the sync marker) sent before every packet.
    pub garbage_before_sync: usize,
    /// The first packet after each start is cut after its header and half of its first
    /// image; the next packet follows at once.
    pub truncate_packet: bool,
}

/// The emulated IPA-1110.
#[derive(Debug)]
pub struct DinastEmulator {
    firmware: String,
    faults: DinastFaults,
    started: bool,
    unplugged: bool,
    /// Bytes of the stream not yet read by the host.
    stream: Vec<u8>,
    packets_since_start: usize,
    bulk_reads: usize,
    encoder: Option<RawEncoder>,
}

impl DinastEmulator {
    /// A stopped device that reports `firmware` (cut to 21 bytes) as its version.
    pub fn new(firmware: impl Into<String>) -> Self {
        Self {
            firmware: firmware.into(),
            faults: DinastFaults::default(),
            started: false,
            unplugged: false,
            stream: Vec::new(),
            packets_since_start: 0,
            bulk_reads: 0,
            encoder: None,
        }
    }

    /// The same device with `faults` injected.
    pub fn with_faults(mut self, faults: DinastFaults) -> Self {
        self.faults = faults;
        self
    }

    /// Whether the host started streaming (and did not stop it).
    pub fn is_started(&self) -> bool {
        self.started
    }

    /// Bulk reads answered so far.
    pub fn bulk_reads(&self) -> usize {
        self.bulk_reads
    }

    /// Answers one request; bulk reads capture frames from `camera` as needed.
    pub fn handle(&mut self, request: UsbRequest, camera: &mut dyn DepthCamera) -> UsbReply {
        if self.unplugged {
            return UsbReply::Failed(TransportError::NoDevice);
        }
        let reached = |limit: Option<usize>| limit.is_some_and(|n| self.bulk_reads >= n);
        if reached(self.faults.silent_after_reads) {
            return UsbReply::Silent;
        }
        match request {
            UsbRequest::ControlOut { setup, data } => self.control_out(setup, &data),
            UsbRequest::ControlIn { setup, length } => self.control_in(setup, length),
            UsbRequest::BulkIn { length } => {
                if reached(self.faults.unplug_after_reads) {
                    self.unplugged = true;
                    return UsbReply::Failed(TransportError::NoDevice);
                }
                self.bulk_in(length, camera)
            }
        }
    }

    fn control_out(&mut self, setup: ControlSetup, data: &[u8]) -> UsbReply {
        if data.len() != 1 {
            return UsbReply::Failed(TransportError::Stall);
        }
        if setup == start_setup() {
            self.started = true;
        } else if setup == stop_setup() {
            self.started = false;
        } else {
            return UsbReply::Failed(TransportError::Stall);
        }
        self.stream.clear();
        self.packets_since_start = 0;
        UsbReply::Written(1)
    }

    fn control_in(&self, setup: ControlSetup, length: usize) -> UsbReply {
        if setup != firmware_version_setup() {
            return UsbReply::Failed(TransportError::Stall);
        }
        let mut answer: Vec<u8> = self.firmware.bytes().take(FIRMWARE_VERSION_LEN).collect();
        answer.resize(FIRMWARE_VERSION_LEN, 0);
        answer.truncate(length);
        UsbReply::Data(answer)
    }

    fn bulk_in(&mut self, length: usize, camera: &mut dyn DepthCamera) -> UsbReply {
        if !self.started {
            return UsbReply::Silent;
        }
        // The device sends at most one packet's worth per transfer.
        let length = length.min(PACKET_LEN);
        while self.stream.len() < length {
            if let Err(error) = self.append_packet(camera) {
                return UsbReply::Failed(error);
            }
        }
        self.bulk_reads += 1;
        UsbReply::Data(self.stream.drain(..length).collect())
    }

    /// Captures one frame and appends its packet (with the injected faults) to the stream.
    fn append_packet(&mut self, camera: &mut dyn DepthCamera) -> Result<(), TransportError> {
        let frame = camera
            .capture()
            .map_err(|e| TransportError::Io(format!("backing camera: {e}")))?;
        let spec = camera.spec();
        let encoder = match self.encoder.take() {
            Some(encoder) if encoder.spec() == spec => encoder,
            _ => RawEncoder::new(spec),
        };
        let raw = encoder.encode(&frame);
        self.encoder = Some(encoder);
        let mut packet = raw
            .map_err(|e| TransportError::Io(format!("backing camera: {e}")))?
            .to_packet();
        if self.faults.truncate_packet && self.packets_since_start == 0 {
            packet.truncate(HEADER_LEN + IMAGE_LEN / 2);
        }
        // Garbage: a byte pattern without 0xAA, so it can never hold the marker.
        self.stream.extend(
            (0..self.faults.garbage_before_sync).map(|i| (i as u8).wrapping_mul(37) & 0x7F),
        );
        self.stream.extend(packet);
        self.packets_since_start += 1;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dinast::frame::{FrameDecoder, PACKET_LEN};
    use nbv_core::rig::{DepthCameraSpec, DepthFrame, RigError};

    /// A wall at 0.5 m.
    struct Wall(DepthCameraSpec);

    impl DepthCamera for Wall {
        fn spec(&self) -> &DepthCameraSpec {
            &self.0
        }
        fn capture(&mut self) -> Result<DepthFrame, RigError> {
            let (width, height) = (self.0.width, self.0.height);
            Ok(DepthFrame {
                time: 0.0,
                width,
                height,
                depth: vec![0.5; width * height],
                truth: None,
            })
        }
    }

    fn wall() -> Wall {
        Wall(DepthCameraSpec {
            width: 64,
            height: 48,
            ..DepthCameraSpec::ipa1110()
        })
    }

    fn out(setup: ControlSetup) -> UsbRequest {
        UsbRequest::ControlOut {
            setup,
            data: vec![1],
        }
    }

    #[test]
    fn answers_the_firmware_version_padded_to_21_bytes() {
        let mut device = DinastEmulator::new("v1.0");
        let setup = firmware_version_setup();
        let reply = device.handle(UsbRequest::ControlIn { setup, length: 64 }, &mut wall());
        let mut expected = b"v1.0".to_vec();
        expected.resize(FIRMWARE_VERSION_LEN, 0);
        assert_eq!(reply, UsbReply::Data(expected));
    }

    #[test]
    fn wrong_requests_stall() {
        let mut device = DinastEmulator::new("v1.0");
        let stall = UsbReply::Failed(TransportError::Stall);
        let wrong_type = ControlSetup {
            request_type: 0xC0,
            ..start_setup()
        };
        let wrong_value = ControlSetup {
            value: 3,
            ..firmware_version_setup()
        };
        let wrong_request = ControlSetup {
            request: 0xC9,
            ..start_setup()
        };
        assert_eq!(device.handle(out(wrong_type), &mut wall()), stall);
        assert_eq!(device.handle(out(wrong_request), &mut wall()), stall);
        let reply = device.handle(
            UsbRequest::ControlIn {
                setup: wrong_value,
                length: 21,
            },
            &mut wall(),
        );
        assert_eq!(reply, stall);
        let two_bytes = UsbRequest::ControlOut {
            setup: start_setup(),
            data: vec![1, 1],
        };
        assert_eq!(device.handle(two_bytes, &mut wall()), stall);
        assert!(!device.is_started());
    }

    #[test]
    fn streams_packets_only_while_started() {
        let mut device = DinastEmulator::new("v1.0");
        let mut camera = wall();
        let read = UsbRequest::BulkIn { length: PACKET_LEN };
        assert_eq!(device.handle(read.clone(), &mut camera), UsbReply::Silent);
        assert_eq!(
            device.handle(out(start_setup()), &mut camera),
            UsbReply::Written(1)
        );
        let UsbReply::Data(bytes) = device.handle(read.clone(), &mut camera) else {
            panic!("no data while started");
        };
        let mut decoder = FrameDecoder::new();
        decoder.push(&bytes);
        let frame = decoder.pop_frame().unwrap();
        // The wall fills the middle of the raw image, not its 64°-off-axis border.
        assert_ne!(frame.depth_code_at(160, 120), Some(0));
        assert_eq!(frame.depth_code_at(0, 120), Some(0));
        assert_eq!(
            device.handle(out(stop_setup()), &mut camera),
            UsbReply::Written(1)
        );
        assert_eq!(device.handle(read, &mut camera), UsbReply::Silent);
    }

    #[test]
    fn unplugged_device_fails_every_request() {
        let faults = DinastFaults {
            unplug_after_reads: Some(1),
            ..DinastFaults::default()
        };
        let mut device = DinastEmulator::new("v1.0").with_faults(faults);
        let mut camera = wall();
        let read = UsbRequest::BulkIn { length: PACKET_LEN };
        device.handle(out(start_setup()), &mut camera);
        assert!(matches!(
            device.handle(read.clone(), &mut camera),
            UsbReply::Data(_)
        ));
        let gone = UsbReply::Failed(TransportError::NoDevice);
        assert_eq!(device.handle(read, &mut camera), gone);
        assert_eq!(device.handle(out(stop_setup()), &mut camera), gone);
    }
}
