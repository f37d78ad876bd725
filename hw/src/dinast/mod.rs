//! Dinast IPA-1110 over USB: the transport, the frame decoder, the driver and its emulator.
//!
//! - [`DinastTransport`]: the USB operations the driver needs; [`UsbTransport`] over
//!   libusb, [`ChannelTransport`] and [`EmulatedTransport`] to the emulator.
//! - [`raw_model`]: the vendor's raw-to-distance model and its inverse.
//! - [`FrameDecoder`]: packets out of the bulk stream.
//! - [`DinastCamera`]: the [`nbv_core::rig::DepthCamera`] driver, resampling the vendor's
//!   f-θ image into the spec's pinhole grid.
//! - [`DinastEmulator`]: the device side, backed by any depth camera.

mod camera;
mod channel;
mod emulated_transport;
mod emulator;
mod frame;
mod protocol;
pub mod raw_model;
mod resample;
mod transport;
mod usb;

pub use camera::{DinastCamera, DinastConfig};
pub use channel::{ChannelTransport, DeviceEnd, channel_transport};
pub use emulated_transport::EmulatedTransport;
pub use emulator::{DinastEmulator, DinastFaults, UsbReply, UsbRequest};
pub use frame::{
    DecoderStats, FrameDecoder, HEADER_LEN, IMAGE_LEN, MAX_QUEUED_FRAMES, PACKET_LEN, RawFrame,
    SYNC_MARKER,
};
pub use protocol::{
    CONTROL_TIMEOUT, FIRMWARE_VERSION_LEN, REQUEST_FIRMWARE_VERSION, REQUEST_START, REQUEST_STOP,
    firmware_version_setup, firmware_version_text, start_setup, stop_setup,
};
pub use raw_model::{
    point_from_raw, range_from_raw, range_quantisation_bound, raw_direction, raw_from_range,
    raw_position,
};
pub use resample::{EDGE_MARGIN_PX, FrameSizeError, PinholeResampler, RawEncoder};
pub use transport::{ControlSetup, DinastTransport, TransportError, VENDOR_IN, VENDOR_OUT};
pub use usb::{
    INTERFACE, PRODUCT_ID, UsbOpenError, UsbSelection, UsbSelectionParseError, UsbTransport,
    VENDOR_ID,
};
