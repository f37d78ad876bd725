//! [`UsbTransport`]: the [`DinastTransport`] over libusb (rusb): finds the IPA-1110 by
//! VID/PID ([`UsbSelection`] picks one of several), claims interface 0 and reads from the
//! first bulk-in endpoint.

use super::transport::{ControlSetup, DinastTransport, TransportError};
use nbv_core::rig::RigError;
use rusb::{Context, Device, DeviceHandle, Direction, TransferType, UsbContext};
use std::fmt;
use std::str::FromStr;
use std::time::Duration;
use thiserror::Error;

/// USB vendor id of the IPA-1110.
pub const VENDOR_ID: u16 = 0x18d1;
/// USB product id of the IPA-1110.
pub const PRODUCT_ID: u16 = 0x1402;
/// The interface the driver claims.
pub const INTERFACE: u8 = 0;

/// Which IPA-1110 to open when several are plugged in.
///
/// Parsed from `"N"` (the N-th one, 0-based, in libusb's enumeration order) or
/// `"BUS:ADDRESS"` (decimal, as `lsusb` prints them, e.g. `"001:005"`).
///
/// ```
/// use nbv_hw::dinast::UsbSelection;
/// assert_eq!("2".parse(), Ok(UsbSelection::Nth(2)));
/// assert_eq!("001:005".parse(), Ok(UsbSelection::BusAddress { bus: 1, address: 5 }));
/// assert_eq!(UsbSelection::default(), UsbSelection::Nth(0));
/// ```
///
/// In a rig file it is the same text (`usb = "001:005"`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Deserialize)]
#[serde(try_from = "String")]
pub enum UsbSelection {
    /// The n-th matching device (0-based).
    Nth(usize),
    /// The matching device at this bus number and address.
    BusAddress {
        /// Bus number.
        bus: u8,
        /// Device address on the bus.
        address: u8,
    },
}

impl Default for UsbSelection {
    fn default() -> Self {
        Self::Nth(0)
    }
}

impl fmt::Display for UsbSelection {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Nth(n) => write!(f, "{n}"),
            Self::BusAddress { bus, address } => write!(f, "{bus:03}:{address:03}"),
        }
    }
}

/// A [`UsbSelection`] that does not parse.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
#[error("USB selection {0:?} is neither N nor BUS:ADDRESS")]
pub struct UsbSelectionParseError(pub String);

impl TryFrom<String> for UsbSelection {
    type Error = UsbSelectionParseError;

    fn try_from(text: String) -> Result<Self, Self::Error> {
        text.parse()
    }
}

impl FromStr for UsbSelection {
    type Err = UsbSelectionParseError;

    fn from_str(text: &str) -> Result<Self, Self::Err> {
        let text = text.trim();
        let error = || UsbSelectionParseError(text.to_string());
        match text.split_once(':') {
            Some((bus, address)) => Ok(Self::BusAddress {
                bus: bus.trim().parse().map_err(|_| error())?,
                address: address.trim().parse().map_err(|_| error())?,
            }),
            None => text.parse().map(Self::Nth).map_err(|_| error()),
        }
    }
}

/// Why the camera could not be opened.
#[derive(Debug, Error)]
pub enum UsbOpenError {
    /// No matching device (or fewer than the selection needs).
    #[error(
        "no Dinast IPA-1110 ({VENDOR_ID:04x}:{PRODUCT_ID:04x}) matches selection {selection} ({found} found)"
    )]
    NotFound {
        /// What was asked for.
        selection: UsbSelection,
        /// How many IPA-1110 were found.
        found: usize,
    },
    /// libusb failed (no USB access, permissions, device busy...).
    #[error("USB error while {step}: {source}")]
    Usb {
        /// What the driver was doing.
        step: &'static str,
        /// libusb's error.
        source: rusb::Error,
    },
    /// Interface 0 has no bulk-in endpoint.
    #[error("interface {INTERFACE} has no bulk-in endpoint")]
    NoBulkInEndpoint,
}

impl From<UsbOpenError> for RigError {
    fn from(error: UsbOpenError) -> Self {
        RigError::Disconnected {
            device: "dinast".into(),
            detail: error.to_string(),
        }
    }
}

impl From<rusb::Error> for TransportError {
    fn from(error: rusb::Error) -> Self {
        match error {
            rusb::Error::NoDevice => Self::NoDevice,
            rusb::Error::Timeout => Self::Timeout,
            rusb::Error::Pipe => Self::Stall,
            other => Self::Io(other.to_string()),
        }
    }
}

/// The camera over libusb, interface 0 claimed.
pub struct UsbTransport {
    handle: DeviceHandle<Context>,
    bulk_in: u8,
}

impl fmt::Debug for UsbTransport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("UsbTransport")
            .field("bulk_in", &self.bulk_in)
            .finish_non_exhaustive()
    }
}

fn usb(step: &'static str) -> impl FnOnce(rusb::Error) -> UsbOpenError {
    move |source| UsbOpenError::Usb { step, source }
}

fn is_ipa1110(device: &Device<Context>) -> bool {
    device
        .device_descriptor()
        .is_ok_and(|d| d.vendor_id() == VENDOR_ID && d.product_id() == PRODUCT_ID)
}

fn first_bulk_in(device: &Device<Context>) -> Result<u8, UsbOpenError> {
    let config = device
        .active_config_descriptor()
        .map_err(usb("reading the configuration descriptor"))?;
    config
        .interfaces()
        .filter(|interface| interface.number() == INTERFACE)
        .flat_map(|interface| interface.descriptors())
        .flat_map(|descriptor| descriptor.endpoint_descriptors().collect::<Vec<_>>())
        .find(|e| e.direction() == Direction::In && e.transfer_type() == TransferType::Bulk)
        .map(|e| e.address())
        .ok_or(UsbOpenError::NoBulkInEndpoint)
}

impl UsbTransport {
    /// Opens the selected IPA-1110, claims interface 0 and finds its bulk-in endpoint.
    /// Fails cleanly (never panics) when libusb is unavailable or no device matches.
    ///
    /// ```no_run
    /// use nbv_hw::dinast::{UsbSelection, UsbTransport};
    /// let transport = UsbTransport::open(UsbSelection::default())?;
    /// # Ok::<(), nbv_hw::dinast::UsbOpenError>(())
    /// ```
    pub fn open(selection: UsbSelection) -> Result<Self, UsbOpenError> {
        // A context of its own: rusb's global one panics where libusb cannot start (a
        // machine or container without USB), where this is an error to report.
        let context = Context::new().map_err(usb("starting libusb"))?;
        let list = context.devices().map_err(usb("listing USB devices"))?;
        let cameras: Vec<_> = list.iter().filter(is_ipa1110).collect();
        let chosen = match selection {
            UsbSelection::Nth(n) => cameras.get(n),
            UsbSelection::BusAddress { bus, address } => cameras
                .iter()
                .find(|d| d.bus_number() == bus && d.address() == address),
        };
        let device = chosen.ok_or(UsbOpenError::NotFound {
            selection,
            found: cameras.len(),
        })?;
        let bulk_in = first_bulk_in(device)?;
        let handle = device.open().map_err(usb("opening the device"))?;
        // Not supported on every platform; claiming tells if a kernel driver is in the way.
        let _ = handle.set_auto_detach_kernel_driver(true);
        handle
            .claim_interface(INTERFACE)
            .map_err(usb("claiming interface 0"))?;
        tracing::debug!(%selection, bulk_in, "Dinast IPA-1110 opened");
        Ok(Self { handle, bulk_in })
    }

    /// Address of the bulk-in endpoint in use.
    pub fn bulk_in_endpoint(&self) -> u8 {
        self.bulk_in
    }
}

impl DinastTransport for UsbTransport {
    fn control_out(
        &mut self,
        setup: ControlSetup,
        data: &[u8],
        timeout: Duration,
    ) -> Result<usize, TransportError> {
        let ControlSetup {
            request_type,
            request,
            value,
            index,
        } = setup;
        Ok(self
            .handle
            .write_control(request_type, request, value, index, data, timeout)?)
    }

    fn control_in(
        &mut self,
        setup: ControlSetup,
        buf: &mut [u8],
        timeout: Duration,
    ) -> Result<usize, TransportError> {
        let ControlSetup {
            request_type,
            request,
            value,
            index,
        } = setup;
        Ok(self
            .handle
            .read_control(request_type, request, value, index, buf, timeout)?)
    }

    fn bulk_read(&mut self, buf: &mut [u8], timeout: Duration) -> Result<usize, TransportError> {
        Ok(self.handle.read_bulk(self.bulk_in, buf, timeout)?)
    }
}

impl Drop for UsbTransport {
    fn drop(&mut self) {
        let _ = self.handle.release_interface(INTERFACE);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn selection_round_trips_through_text() {
        for selection in [
            UsbSelection::Nth(0),
            UsbSelection::Nth(7),
            UsbSelection::BusAddress {
                bus: 3,
                address: 42,
            },
        ] {
            assert_eq!(selection.to_string().parse(), Ok(selection));
        }
    }

    #[test]
    fn bad_selections_do_not_parse() {
        for text in ["", "x", "-1", "1:", ":2", "1:2:3", "300:1"] {
            assert!(text.parse::<UsbSelection>().is_err(), "{text:?}");
        }
    }

    #[test]
    fn rusb_errors_map_to_transport_errors() {
        assert_eq!(
            TransportError::from(rusb::Error::NoDevice),
            TransportError::NoDevice
        );
        assert_eq!(
            TransportError::from(rusb::Error::Timeout),
            TransportError::Timeout
        );
        assert_eq!(
            TransportError::from(rusb::Error::Pipe),
            TransportError::Stall
        );
        assert!(matches!(
            TransportError::from(rusb::Error::Busy),
            TransportError::Io(_)
        ));
    }

    #[test]
    fn opening_without_a_camera_fails_cleanly() {
        // This machine has no IPA-1110: either libusb is unavailable or nothing matches.
        let opened = UsbTransport::open(UsbSelection::default());
        if let Err(error) = &opened {
            eprintln!("open without a camera: {error}");
        }
        match opened {
            Ok(transport) => panic!("unexpected IPA-1110 found: {transport:?}"),
            Err(UsbOpenError::NotFound { found, .. }) => assert_eq!(found, 0),
            Err(UsbOpenError::Usb { .. } | UsbOpenError::NoBulkInEndpoint) => {}
        }
        let far = UsbSelection::BusAddress {
            bus: 255,
            address: 255,
        };
        assert!(UsbTransport::open(far).is_err());
    }
}
