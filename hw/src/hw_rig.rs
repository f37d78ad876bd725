//! [`HwRig`]: the three real drivers of a rig file — the C4G arm, the LMS400 and the
//! Dinast — connected and configured for the sensors a scene describes. It is the real
//! counterpart of the twin's `SimRig`: the pipeline takes its three parts unchanged.

use crate::comau::C4gArm;
use crate::dinast::{
    CONTROL_TIMEOUT, ChannelTransport, ControlSetup, DinastCamera, DinastConfig, DinastTransport,
    TransportError, UsbTransport,
};
use crate::lms400::{Lms400Config, Lms400Scanner};
use crate::rig_file::RigFile;
use nbv_core::kinematics::Robot;
use nbv_core::math::Pose;
use nbv_core::rig::{DepthCameraSpec, LineScannerSpec, Rig, RigError};
use std::time::Duration;

/// How the camera driver reaches its device: libusb, or an emulated device in this process.
#[derive(Debug)]
pub enum CameraTransport {
    /// The IPA-1110 on the USB bus.
    Usb(UsbTransport),
    /// An emulated IPA-1110 (see [`crate::emulated_rig`]).
    Emulated(ChannelTransport),
}

impl DinastTransport for CameraTransport {
    fn control_out(
        &mut self,
        setup: ControlSetup,
        data: &[u8],
        timeout: Duration,
    ) -> Result<usize, TransportError> {
        match self {
            Self::Usb(t) => t.control_out(setup, data, timeout),
            Self::Emulated(t) => t.control_out(setup, data, timeout),
        }
    }

    fn control_in(
        &mut self,
        setup: ControlSetup,
        buf: &mut [u8],
        timeout: Duration,
    ) -> Result<usize, TransportError> {
        match self {
            Self::Usb(t) => t.control_in(setup, buf, timeout),
            Self::Emulated(t) => t.control_in(setup, buf, timeout),
        }
    }

    fn bulk_read(&mut self, buf: &mut [u8], timeout: Duration) -> Result<usize, TransportError> {
        match self {
            Self::Usb(t) => t.bulk_read(buf, timeout),
            Self::Emulated(t) => t.bulk_read(buf, timeout),
        }
    }
}

/// The real rig's three devices.
#[derive(Debug)]
pub struct HwRig {
    /// The Comau arm.
    pub arm: C4gArm,
    /// The mid-range scanner.
    pub scanner: Lms400Scanner,
    /// The short-range camera.
    pub camera: DinastCamera<CameraTransport>,
}

impl HwRig {
    /// The rig as the pipeline takes it: `robot` (the model with this rig's sensor mounts,
    /// [`RigFile::robot`]) with its base at `base`, and the three devices, borrowed.
    pub fn rig(&mut self, robot: Robot, base: Pose) -> Rig<'_> {
        Rig {
            robot,
            base,
            arm: &mut self.arm,
            scanner: &mut self.scanner,
            camera: &mut self.camera,
        }
    }

    /// Connects to the devices `rig` names, the scanner configured for `laser` and the
    /// camera resampled to `camera`; `camera_transport` is `None` to open the USB device the
    /// rig file selects.
    ///
    /// ```no_run
    /// use nbv_core::rig::DepthCameraSpec;
    /// use nbv_hw::{hw_rig::HwRig, lms400::Lms400Config, rig_file::RigFile};
    /// let rig = RigFile::load("examples/rigs/lab.toml")?;
    /// let laser = Lms400Config::default().spec; // the paper's LMS400 set-up
    /// let camera = DepthCameraSpec::ipa1110();
    /// let hw = HwRig::connect(&rig, laser, camera, None)?;
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn connect(
        rig: &RigFile,
        laser: LineScannerSpec,
        camera: DepthCameraSpec,
        camera_transport: Option<CameraTransport>,
    ) -> Result<Self, RigError> {
        let arm = C4gArm::connect(rig.arm.clone())?;
        let scanner = Lms400Scanner::connect(Lms400Config {
            address: rig.laser.address.clone(),
            spec: laser,
            timeout: Duration::from_secs_f64(rig.laser.timeout_s),
            clock_offset_s: rig.laser.clock_offset_s,
            reconnect_attempts: rig.laser.connect_attempts,
        })?;
        let transport = match camera_transport {
            Some(t) => t,
            None => CameraTransport::Usb(UsbTransport::open(rig.camera.usb).map_err(|e| {
                RigError::Disconnected {
                    device: "dinast".into(),
                    detail: e.to_string(),
                }
            })?),
        };
        let timeout = Duration::from_secs_f64(rig.camera.timeout_s);
        // A device on USB answers a control transfer within the vendor's timeout; the
        // emulated one when the emulator thread gets to it: the frame timeout, if longer.
        let control_timeout = match &transport {
            CameraTransport::Usb(_) => CONTROL_TIMEOUT,
            CameraTransport::Emulated(_) => CONTROL_TIMEOUT.max(timeout),
        };
        let config = DinastConfig {
            timeout,
            control_timeout,
            clock_offset: rig.camera.clock_offset_s,
            ..DinastConfig::new(camera)
        };
        let camera = DinastCamera::open(transport, config)?;
        Ok(Self {
            arm,
            scanner,
            camera,
        })
    }
}
