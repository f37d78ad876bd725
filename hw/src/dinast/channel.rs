//! [`ChannelTransport`]: a [`DinastTransport`] that is `Send` and forwards every transfer
//! over a std channel to a [`DeviceEnd`], which the (single, non-`Send`) emulator thread
//! polls.
//!
//! Each call carries its own reply channel and deadline. The transport waits for the
//! answer until the call's timeout (capped by the channel's); no answer in time is
//! [`TransportError::Timeout`], a dropped [`DeviceEnd`] is [`TransportError::NoDevice`]
//! ("unplugged"). The device end skips calls whose deadline has passed. A call the device
//! leaves unanswered (a silent device) keeps its reply channel open for as long as the
//! device end lives, so its host sees a timeout and never an unplug, however late it looks.

use super::emulator::{DinastEmulator, UsbReply, UsbRequest};
use super::transport::{ControlSetup, DinastTransport, TransportError};
use nbv_core::rig::DepthCamera;
use std::collections::VecDeque;
use std::sync::mpsc::{self, Receiver, RecvTimeoutError, Sender, SyncSender, TryRecvError};
use std::time::{Duration, Instant};

/// Reply channels of unanswered calls kept open (the newest ones): a host waits for one
/// call at a time, so older ones have long been given up.
const MAX_SILENT: usize = 16;

#[derive(Debug)]
struct Call {
    request: UsbRequest,
    deadline: Instant,
    reply: SyncSender<UsbReply>,
}

/// The host side of the channel (see the module documentation).
#[derive(Debug)]
pub struct ChannelTransport {
    calls: Sender<Call>,
    max_wait: Duration,
}

/// The device side of the channel: hands pending calls to the emulator.
#[derive(Debug)]
pub struct DeviceEnd {
    calls: Receiver<Call>,
    /// Reply channels of calls the device left unanswered, newest last.
    silent: VecDeque<SyncSender<UsbReply>>,
}

/// A connected pair; the transport never waits longer than `max_wait` for an answer.
///
/// ```
/// use nbv_hw::dinast::{channel_transport, ControlSetup, DinastTransport, TransportError};
/// use std::time::Duration;
/// let (mut transport, device) = channel_transport(Duration::from_millis(50));
/// drop(device); // unplugged
/// let setup = nbv_hw::dinast::start_setup();
/// let sent = transport.control_out(setup, &[1], Duration::from_secs(1));
/// assert_eq!(sent, Err(TransportError::NoDevice));
/// ```
pub fn channel_transport(max_wait: Duration) -> (ChannelTransport, DeviceEnd) {
    let (calls, receiver) = mpsc::channel();
    (
        ChannelTransport { calls, max_wait },
        DeviceEnd {
            calls: receiver,
            silent: VecDeque::new(),
        },
    )
}

impl ChannelTransport {
    fn call(&self, request: UsbRequest, timeout: Duration) -> Result<UsbReply, TransportError> {
        let wait = timeout.min(self.max_wait);
        let (reply, answer) = mpsc::sync_channel(1);
        let deadline = Instant::now() + wait;
        self.calls
            .send(Call {
                request,
                deadline,
                reply,
            })
            .map_err(|_| TransportError::NoDevice)?;
        match answer.recv_timeout(wait) {
            Ok(reply) => Ok(reply),
            Err(RecvTimeoutError::Timeout) => Err(TransportError::Timeout),
            Err(RecvTimeoutError::Disconnected) => Err(TransportError::NoDevice),
        }
    }
}

impl DinastTransport for ChannelTransport {
    fn control_out(
        &mut self,
        setup: ControlSetup,
        data: &[u8],
        timeout: Duration,
    ) -> Result<usize, TransportError> {
        let data = data.to_vec();
        self.call(UsbRequest::ControlOut { setup, data }, timeout)?
            .into_written()
    }

    fn control_in(
        &mut self,
        setup: ControlSetup,
        buf: &mut [u8],
        timeout: Duration,
    ) -> Result<usize, TransportError> {
        let length = buf.len();
        self.call(UsbRequest::ControlIn { setup, length }, timeout)?
            .copy_into(buf)
    }

    fn bulk_read(&mut self, buf: &mut [u8], timeout: Duration) -> Result<usize, TransportError> {
        let length = buf.len();
        self.call(UsbRequest::BulkIn { length }, timeout)?
            .copy_into(buf)
    }
}

impl DeviceEnd {
    /// Answers every pending call with `emulator` (backed by `camera`) without blocking;
    /// returns whether there was any.
    pub fn poll(&mut self, emulator: &mut DinastEmulator, camera: &mut dyn DepthCamera) -> bool {
        let mut worked = false;
        loop {
            let call = match self.calls.try_recv() {
                Ok(call) => call,
                Err(TryRecvError::Empty | TryRecvError::Disconnected) => return worked,
            };
            worked = true;
            if call.deadline <= Instant::now() {
                continue; // the host has given up
            }
            match emulator.handle(call.request, camera) {
                UsbReply::Silent => {
                    if self.silent.len() == MAX_SILENT {
                        self.silent.pop_front();
                    }
                    self.silent.push_back(call.reply);
                }
                reply => {
                    // The host may have just timed out; then nobody listens.
                    let _ = call.reply.send(reply);
                }
            }
        }
    }
}
