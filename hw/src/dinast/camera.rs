//! [`DinastCamera`]: the IPA-1110 driver, a [`DepthCamera`] over any [`DinastTransport`].
//!
//! Opening reads the firmware version and starts streaming; dropping (or
//! [`DinastCamera::close`]) stops it. A capture discards whatever was buffered, bulk-reads
//! until a complete packet decodes (at most [`DinastConfig::max_reads_per_frame`] reads),
//! decodes the raw image with the vendor model and resamples it into the spec's pinhole
//! grid ([`PinholeResampler`]): the pipeline only knows the pinhole model, while the
//! vendor model is an equidistant (f-θ) lens.
//!
//! Frame time: host monotonic seconds since the camera was opened, taken when the packet's
//! last byte arrived, plus [`DinastConfig::clock_offset`] (which puts the camera on the
//! rig's clock and may absorb the unknown exposure-to-USB latency). Truth is `None`.

use super::frame::{DecoderStats, FrameDecoder, PACKET_LEN, RawFrame};
use super::protocol::{
    CONTROL_TIMEOUT, FIRMWARE_VERSION_LEN, firmware_version_setup, firmware_version_text,
    start_setup, stop_setup,
};
use super::resample::PinholeResampler;
use super::transport::{DinastTransport, TransportError};
use nbv_core::rig::{DepthCamera, DepthCameraSpec, DepthFrame, RigError};
use std::time::{Duration, Instant};

/// Settings of the driver.
#[derive(Debug, Clone, PartialEq)]
pub struct DinastConfig {
    /// The pinhole model the frames are resampled into.
    pub spec: DepthCameraSpec,
    /// Timeout of each bulk read.
    pub timeout: Duration,
    /// Timeout of each control transfer (start, stop, firmware version): the vendor
    /// driver's [`CONTROL_TIMEOUT`] for a device on USB; an emulated device answers when
    /// its thread gets to it, so it may need more.
    pub control_timeout: Duration,
    /// Bulk reads a capture may take before giving up with a timeout.
    pub max_reads_per_frame: usize,
    /// Added to the host time since opening to give the rig time of a frame, seconds.
    pub clock_offset: f64,
    /// Device name in errors.
    pub device: String,
}

impl DinastConfig {
    /// Defaults: 1 s per read, [`CONTROL_TIMEOUT`] per control transfer, 4 reads per
    /// frame, no clock offset, device `dinast`.
    ///
    /// ```
    /// use nbv_core::rig::DepthCameraSpec;
    /// let spec = DepthCameraSpec::ipa1110();
    /// let config = nbv_hw::dinast::DinastConfig::new(spec);
    /// assert_eq!(config.max_reads_per_frame, 4);
    /// ```
    pub fn new(spec: DepthCameraSpec) -> Self {
        Self {
            spec,
            timeout: Duration::from_secs(1),
            control_timeout: CONTROL_TIMEOUT,
            max_reads_per_frame: 4,
            clock_offset: 0.0,
            device: "dinast".into(),
        }
    }
}

/// The IPA-1110 driver (see the module documentation).
pub struct DinastCamera<T: DinastTransport> {
    transport: T,
    config: DinastConfig,
    resampler: PinholeResampler,
    decoder: FrameDecoder,
    read_buffer: Vec<u8>,
    firmware_version: String,
    opened: Instant,
    streaming: bool,
}

impl<T: DinastTransport> std::fmt::Debug for DinastCamera<T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("DinastCamera")
            .field("config", &self.config)
            .field("firmware_version", &self.firmware_version)
            .field("streaming", &self.streaming)
            .finish_non_exhaustive()
    }
}

impl<T: DinastTransport> DinastCamera<T> {
    /// Reads the firmware version and starts streaming.
    ///
    /// ```
    /// use nbv_core::rig::{DepthCamera, DepthCameraSpec, DepthFrame, RigError};
    /// use nbv_hw::dinast::{DinastCamera, DinastConfig, DinastEmulator, EmulatedTransport};
    ///
    /// /// A wall 0.4 m in front of the camera.
    /// struct Wall(DepthCameraSpec);
    /// impl DepthCamera for Wall {
    ///     fn spec(&self) -> &DepthCameraSpec { &self.0 }
    ///     fn capture(&mut self) -> Result<DepthFrame, RigError> {
    ///         let (width, height) = (self.0.width, self.0.height);
    ///         let depth = vec![0.4; width * height];
    ///         Ok(DepthFrame { time: 0.0, width, height, depth, truth: None })
    ///     }
    /// }
    ///
    /// let spec = DepthCameraSpec::ipa1110();
    /// let device = DinastEmulator::new("IPA-1110 v2");
    /// let transport = EmulatedTransport::new(device, Box::new(Wall(spec.clone())));
    /// let mut camera = DinastCamera::open(transport, DinastConfig::new(spec))?;
    /// assert_eq!(camera.firmware_version(), "IPA-1110 v2");
    /// let frame = camera.capture()?;
    /// let centre = frame.depth[120 * 320 + 160];
    /// assert!((centre - 0.4).abs() < 0.005);
    /// # Ok::<(), RigError>(())
    /// ```
    pub fn open(mut transport: T, config: DinastConfig) -> Result<Self, RigError> {
        let mut answer = [0u8; FIRMWARE_VERSION_LEN];
        let read = transport
            .control_in(
                firmware_version_setup(),
                &mut answer,
                config.control_timeout,
            )
            .map_err(|e| transport_error(&config.device, e, config.control_timeout))?;
        if read == 0 {
            return Err(protocol_error(&config.device, "empty firmware version"));
        }
        let firmware_version = firmware_version_text(answer.get(..read).unwrap_or_default());
        send_one_byte(&mut transport, &config, true)?;
        tracing::debug!(device = %config.device, %firmware_version, "Dinast camera streaming");
        Ok(Self {
            resampler: PinholeResampler::new(&config.spec),
            transport,
            config,
            decoder: FrameDecoder::new(),
            read_buffer: vec![0; PACKET_LEN],
            firmware_version,
            opened: Instant::now(),
            streaming: true,
        })
    }

    /// The firmware version the camera reported.
    pub fn firmware_version(&self) -> &str {
        &self.firmware_version
    }

    /// The driver's settings.
    pub fn config(&self) -> &DinastConfig {
        &self.config
    }

    /// Changes the timeouts of each bulk read and of each control transfer from now on
    /// (e.g. generous ones while the device is opened, short ones once the stream runs).
    pub fn set_timeouts(&mut self, bulk: Duration, control: Duration) {
        self.config.timeout = bulk;
        self.config.control_timeout = control;
    }

    /// What the packet decoder has seen since opening.
    pub fn decoder_stats(&self) -> DecoderStats {
        self.decoder.stats()
    }

    /// Reads one complete raw frame; returns it with its rig time.
    pub fn capture_raw(&mut self) -> Result<(f64, RawFrame), RigError> {
        if !self.streaming {
            return Err(RigError::State {
                device: self.config.device.clone(),
                detail: "capture after close".into(),
            });
        }
        self.decoder.reset();
        for _ in 0..self.config.max_reads_per_frame {
            let read = self
                .transport
                .bulk_read(&mut self.read_buffer, self.config.timeout)
                .map_err(|e| transport_error(&self.config.device, e, self.config.timeout))?;
            let time = self.opened.elapsed().as_secs_f64() + self.config.clock_offset;
            self.decoder
                .push(self.read_buffer.get(..read).unwrap_or_default());
            if let Some(raw) = self.decoder.pop_frame() {
                return Ok((time, raw));
            }
        }
        let stats = self.decoder.stats();
        tracing::warn!(device = %self.config.device, ?stats, "no complete Dinast packet");
        Err(RigError::Timeout {
            device: self.config.device.clone(),
            seconds: self.config.timeout.as_secs_f64() * self.config.max_reads_per_frame as f64,
        })
    }

    /// Stops streaming and releases the transport.
    pub fn close(mut self) -> Result<(), RigError> {
        self.stop()
    }

    fn stop(&mut self) -> Result<(), RigError> {
        if !self.streaming {
            return Ok(());
        }
        self.streaming = false;
        send_one_byte(&mut self.transport, &self.config, false)
    }
}

impl<T: DinastTransport> DepthCamera for DinastCamera<T> {
    fn spec(&self) -> &DepthCameraSpec {
        &self.config.spec
    }

    fn capture(&mut self) -> Result<DepthFrame, RigError> {
        let (time, raw) = self.capture_raw()?;
        let spec = self.resampler.spec();
        Ok(DepthFrame {
            time,
            width: spec.width,
            height: spec.height,
            depth: self.resampler.depth(&raw),
            truth: None,
        })
    }
}

impl<T: DinastTransport> Drop for DinastCamera<T> {
    fn drop(&mut self) {
        if let Err(error) = self.stop() {
            tracing::debug!(%error, "Dinast stop on drop failed");
        }
    }
}

/// Sends start (`true`) or stop (`false`).
fn send_one_byte<T: DinastTransport>(
    transport: &mut T,
    config: &DinastConfig,
    start: bool,
) -> Result<(), RigError> {
    let device = config.device.as_str();
    let setup = if start { start_setup() } else { stop_setup() };
    let written = transport
        .control_out(setup, &[0x01], config.control_timeout)
        .map_err(|e| transport_error(device, e, config.control_timeout))?;
    if written != 1 {
        return Err(protocol_error(
            device,
            &format!("{written} bytes accepted of a 1-byte request"),
        ));
    }
    Ok(())
}

fn protocol_error(device: &str, detail: &str) -> RigError {
    RigError::Protocol {
        device: device.into(),
        detail: detail.into(),
    }
}

/// The rig-level meaning of a transport failure.
fn transport_error(device: &str, error: TransportError, timeout: Duration) -> RigError {
    match error {
        TransportError::Timeout => RigError::Timeout {
            device: device.into(),
            seconds: timeout.as_secs_f64(),
        },
        TransportError::NoDevice => RigError::Disconnected {
            device: device.into(),
            detail: "device unplugged".into(),
        },
        TransportError::Stall => protocol_error(device, "request stalled by the device"),
        TransportError::Io(detail) => RigError::Disconnected {
            device: device.into(),
            detail: format!("USB I/O error: {detail}"),
        },
    }
}
