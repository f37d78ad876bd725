//! [`EmulatedRig`]: the three device emulators served from one thread, backed by any rig
//! (the CLI plugs in the twin), at the addresses a rig file names — so the real drivers run
//! the whole pipeline byte for byte without hardware.
//!
//! The backing devices are built *inside* the emulator thread by a factory (the twin's
//! devices share state and are not `Send`); the thread polls the C4G and LMS400 emulators
//! and the Dinast device end in turn and sleeps briefly when none had work. Port 0 in a
//! rig-file address picks a free port; [`EmulatedRig::rig_file`] gives the file with the
//! ports actually bound, and [`EmulatedRig::camera_transport`] the camera's in-process USB
//! transport.

use crate::comau::{C4gEmulator, C4gEmulatorStats};
use crate::dinast::{ChannelTransport, DinastEmulator, channel_transport};
use crate::hw_rig::CameraTransport;
use crate::lms400::Lms400Emulator;
use crate::rig_file::RigFile;
use nbv_core::kinematics::Robot;
use nbv_core::rig::{Arm, DepthCamera, LineScanner};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;
use std::thread::JoinHandle;
use std::time::Duration;

/// The devices behind the emulators.
pub struct BackingRig {
    /// Answers the C4G's motions.
    pub arm: Box<dyn Arm>,
    /// Answers the LMS400's streams.
    pub scanner: Box<dyn LineScanner>,
    /// Answers the Dinast's frames.
    pub camera: Box<dyn DepthCamera>,
    /// The controller's own kinematic model, for `POS` (the flange frame `tool0`).
    pub controller_model: Option<Robot>,
}

/// Builds the backing devices inside the emulator thread.
pub type BackingFactory = Box<dyn FnOnce() -> Result<BackingRig, String> + Send>;

/// Why the emulators could not run.
#[derive(Debug, thiserror::Error)]
pub enum EmulatedRigError {
    /// An emulator could not listen on its address.
    #[error("emulating {device}: cannot listen on {address}: {detail}")]
    Bind {
        /// Device.
        device: &'static str,
        /// Address from the rig file.
        address: String,
        /// The I/O error.
        detail: String,
    },
    /// The backing rig could not be built.
    #[error("emulating the rig: {0}")]
    Backing(String),
    /// The emulators could not start serving.
    #[error("emulating the rig: {0}")]
    Serve(String),
    /// The emulator thread panicked.
    #[error("the emulator thread panicked")]
    Panicked,
}

/// What the emulators saw, when they stop.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct EmulatedRigStats {
    /// The C4G emulator's counts.
    pub arm: C4gEmulatorStats,
    /// Connections the LMS400 emulator accepted.
    pub laser_connections: usize,
    /// Bulk reads the Dinast emulator answered.
    pub camera_reads: usize,
}

/// Running emulators of a rig.
pub struct EmulatedRig {
    rig_file: RigFile,
    camera: Option<ChannelTransport>,
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<Result<EmulatedRigStats, EmulatedRigError>>>,
}

impl EmulatedRig {
    /// Starts the emulators at `rig`'s addresses, backed by what `factory` builds.
    pub fn start(rig: &RigFile, factory: BackingFactory) -> Result<Self, EmulatedRigError> {
        let (ready_tx, ready_rx) = mpsc::channel();
        let (camera, mut device_end) =
            channel_transport(Duration::from_secs_f64(rig.camera.timeout_s));
        let stop = Arc::new(AtomicBool::new(false));
        let flag = stop.clone();
        let arm_address = rig.arm.address.clone();
        let laser_address = rig.laser.address.clone();
        let thread = std::thread::spawn(move || {
            let bind = |device, address: &str, e: std::io::Error| EmulatedRigError::Bind {
                device,
                address: address.to_owned(),
                detail: e.to_string(),
            };
            let setup = (|| -> Result<_, EmulatedRigError> {
                let mut arm = C4gEmulator::bind(arm_address.as_str())
                    .map_err(|e| bind("the C4G", &arm_address, e))?;
                let laser = Lms400Emulator::bind(&laser_address)
                    .map_err(|e| bind("the LMS400", &laser_address, e))?;
                let mut backing = factory().map_err(EmulatedRigError::Backing)?;
                if let Some(robot) = backing.controller_model.take() {
                    arm = arm.with_kinematics(robot, "tool0");
                }
                let addresses = (
                    arm.local_addr()
                        .map_err(|e| bind("the C4G", &arm_address, e))?,
                    laser
                        .local_addr()
                        .map_err(|e| bind("the LMS400", &laser_address, e))?,
                );
                Ok((arm, laser, backing, addresses))
            })();
            let (mut arm, mut laser, mut backing, addresses) = match setup {
                Ok(s) => s,
                Err(e) => {
                    let message = e.to_string();
                    let _ = ready_tx.send(Err(e));
                    return Err(EmulatedRigError::Serve(message));
                }
            };
            let _ = ready_tx.send(Ok(addresses));
            let mut camera = DinastEmulator::new("IPA-1110 emulated by nbv-twin");
            while !flag.load(Ordering::Relaxed) {
                let mut busy = arm.poll(backing.arm.as_mut());
                // The client already got the device's error reply; keep serving.
                busy |= laser.poll(backing.scanner.as_mut()).unwrap_or_else(|e| {
                    tracing::warn!("emulated LMS400: {e}");
                    true
                });
                busy |= device_end.poll(&mut camera, backing.camera.as_mut());
                if !busy {
                    std::thread::sleep(Duration::from_micros(200));
                }
            }
            Ok(EmulatedRigStats {
                arm: arm.stats().clone(),
                laser_connections: laser.connections(),
                camera_reads: camera.bulk_reads(),
            })
        });
        let (arm_addr, laser_addr) = match ready_rx.recv() {
            Ok(Ok(addresses)) => addresses,
            Ok(Err(e)) => {
                let _ = thread.join();
                return Err(e);
            }
            Err(_) => {
                return Err(match thread.join() {
                    Ok(Err(e)) => e,
                    _ => EmulatedRigError::Panicked,
                });
            }
        };
        let mut rig_file = rig.clone();
        rig_file.arm.address = arm_addr.to_string();
        rig_file.laser.address = laser_addr.to_string();
        Ok(Self {
            rig_file,
            camera: Some(camera),
            stop,
            thread: Some(thread),
        })
    }

    /// The rig file with the addresses the emulators listen on.
    pub fn rig_file(&self) -> &RigFile {
        &self.rig_file
    }

    /// The camera's transport to the emulated device (once; `None` afterwards).
    pub fn camera_transport(&mut self) -> Option<CameraTransport> {
        self.camera.take().map(CameraTransport::Emulated)
    }

    /// Stops the emulators and returns what they saw.
    pub fn finish(mut self) -> Result<EmulatedRigStats, EmulatedRigError> {
        self.shutdown()
    }

    fn shutdown(&mut self) -> Result<EmulatedRigStats, EmulatedRigError> {
        self.stop.store(true, Ordering::Relaxed);
        match self.thread.take() {
            Some(t) => t.join().map_err(|_| EmulatedRigError::Panicked)?,
            None => Ok(EmulatedRigStats::default()),
        }
    }
}

impl Drop for EmulatedRig {
    fn drop(&mut self) {
        let _ = self.shutdown();
    }
}
