//! [`Link`]: one TCP connection to the scanner. A reader thread drains the socket all the
//! time (so the kernel's receive buffer never fills during long streams), cuts frames and
//! hands replies and telegrams to the driver through a channel; the driver waits on that
//! channel at most its timeout.

use super::command::Command;
use super::frame::{FrameDecoder, encode_frame};
use super::reply::Reply;
use super::telegram::{MeasurementTelegram, TELEGRAM_MARKER};
use nbv_core::rig::RigError;
use std::io::{ErrorKind, Read, Write};
use std::net::{Shutdown, TcpStream, ToSocketAddrs};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{self, Receiver, RecvTimeoutError, Sender};
use std::thread::JoinHandle;
use std::time::Duration;

/// Device name in errors.
pub(crate) const DEVICE: &str = "LMS400";

/// How often the reader thread looks whether the link is being closed.
const READER_POLL: Duration = Duration::from_millis(50);

/// What the reader thread delivers.
#[derive(Debug)]
pub(crate) enum Inbound {
    /// A text reply.
    Reply(Reply),
    /// A measurement telegram.
    Telegram(MeasurementTelegram),
    /// A frame or payload that could not be decoded.
    Garbled(String),
    /// The connection ended (EOF or error); nothing follows.
    Closed(String),
}

/// A connection with its reader thread.
pub(crate) struct Link {
    stream: TcpStream,
    inbound: Receiver<Inbound>,
    closing: Arc<AtomicBool>,
    closed: Arc<AtomicBool>,
    reader: Option<JoinHandle<()>>,
    timeout: Duration,
}

impl Link {
    /// Connects to `address` (each resolved address tried with `timeout`).
    pub(crate) fn open(address: &str, timeout: Duration) -> Result<Self, RigError> {
        let disconnected = |detail: String| RigError::Disconnected {
            device: DEVICE.into(),
            detail,
        };
        let addresses = address
            .to_socket_addrs()
            .map_err(|e| disconnected(format!("cannot resolve {address}: {e}")))?;
        let mut last_error = format!("{address} resolves to no address");
        let mut connected = None;
        for candidate in addresses {
            match TcpStream::connect_timeout(&candidate, timeout) {
                Ok(stream) => {
                    connected = Some(stream);
                    break;
                }
                Err(e) if e.kind() == ErrorKind::TimedOut => return Err(timeout_error(timeout)),
                Err(e) => last_error = format!("cannot connect to {candidate}: {e}"),
            }
        }
        let stream = connected.ok_or_else(|| disconnected(last_error))?;
        let setup = |e: std::io::Error| disconnected(format!("socket setup: {e}"));
        stream.set_nodelay(true).map_err(setup)?;
        stream.set_write_timeout(Some(timeout)).map_err(setup)?;
        let reader_stream = stream.try_clone().map_err(setup)?;
        reader_stream
            .set_read_timeout(Some(READER_POLL))
            .map_err(setup)?;
        let (sender, inbound) = mpsc::channel();
        let closing = Arc::new(AtomicBool::new(false));
        let closed = Arc::new(AtomicBool::new(false));
        let reader = {
            let (closing, closed) = (closing.clone(), closed.clone());
            std::thread::Builder::new()
                .name("lms400-reader".into())
                .spawn(move || {
                    read_until_closed(reader_stream, &sender, &closing);
                    closed.store(true, Ordering::SeqCst);
                })
                .map_err(|e| disconnected(format!("cannot start the reader thread: {e}")))?
        };
        Ok(Self {
            stream,
            inbound,
            closing,
            closed,
            reader: Some(reader),
            timeout,
        })
    }

    /// Changes the timeout of later sends and receives.
    pub(crate) fn set_timeout(&mut self, timeout: Duration) {
        self.timeout = timeout;
        let _ = self.stream.set_write_timeout(Some(timeout));
    }

    /// Whether the reader has seen the connection end.
    pub(crate) fn is_closed(&self) -> bool {
        self.closed.load(Ordering::SeqCst)
    }

    /// Sends a command.
    pub(crate) fn send(&mut self, command: &Command) -> Result<(), RigError> {
        let frame = encode_frame(&command.to_payload()).map_err(|e| RigError::Protocol {
            device: DEVICE.into(),
            detail: e.to_string(),
        })?;
        tracing::debug!(target: "lms400", "→ {command}");
        self.stream
            .write_all(&frame)
            .and_then(|()| self.stream.flush())
            .map_err(|e| match e.kind() {
                ErrorKind::WouldBlock | ErrorKind::TimedOut => timeout_error(self.timeout),
                _ => RigError::Disconnected {
                    device: DEVICE.into(),
                    detail: format!("sending `{command}`: {e}"),
                },
            })
    }

    /// The next reply or telegram, waiting at most the timeout.
    pub(crate) fn receive(&mut self) -> Result<Inbound, RigError> {
        match self.inbound.recv_timeout(self.timeout) {
            Ok(Inbound::Closed(detail)) => Err(RigError::Disconnected {
                device: DEVICE.into(),
                detail,
            }),
            Ok(inbound) => Ok(inbound),
            Err(RecvTimeoutError::Timeout) => Err(timeout_error(self.timeout)),
            Err(RecvTimeoutError::Disconnected) => Err(RigError::Disconnected {
                device: DEVICE.into(),
                detail: "connection closed".into(),
            }),
        }
    }
}

impl Drop for Link {
    fn drop(&mut self) {
        self.closing.store(true, Ordering::SeqCst);
        let _ = self.stream.shutdown(Shutdown::Both);
        if let Some(reader) = self.reader.take() {
            let _ = reader.join();
        }
    }
}

pub(crate) fn timeout_error(timeout: Duration) -> RigError {
    RigError::Timeout {
        device: DEVICE.into(),
        seconds: timeout.as_secs_f64(),
    }
}

/// The reader thread: reads, decodes and forwards until EOF, an error or `closing`.
fn read_until_closed(mut stream: TcpStream, sender: &Sender<Inbound>, closing: &AtomicBool) {
    let mut decoder = FrameDecoder::new();
    let mut buffer = vec![0u8; 64 * 1024];
    let closed = loop {
        if closing.load(Ordering::SeqCst) {
            break "link closed by the driver".to_owned();
        }
        let received = match stream.read(&mut buffer) {
            Ok(0) => break "connection closed by the scanner".to_owned(),
            Ok(n) => buffer.get(..n).unwrap_or_default(),
            Err(e)
                if matches!(
                    e.kind(),
                    ErrorKind::WouldBlock | ErrorKind::TimedOut | ErrorKind::Interrupted
                ) =>
            {
                continue;
            }
            Err(e) => break format!("connection lost: {e}"),
        };
        let skipped_before = decoder.skipped_bytes();
        decoder.push(received);
        loop {
            let inbound = match decoder.next_frame() {
                Ok(None) => break,
                Ok(Some(payload)) => classify(&payload),
                Err(e) => Inbound::Garbled(format!("bad frame: {e}")),
            };
            if sender.send(inbound).is_err() {
                return;
            }
        }
        let skipped = decoder.skipped_bytes() - skipped_before;
        if skipped > 0 {
            tracing::warn!(target: "lms400", "skipped {skipped} bytes of garbage between frames");
        }
    };
    let _ = sender.send(Inbound::Closed(closed));
}

fn classify(payload: &[u8]) -> Inbound {
    if payload.starts_with(TELEGRAM_MARKER) {
        match MeasurementTelegram::parse(payload) {
            Ok(telegram) => Inbound::Telegram(telegram),
            Err(e) => Inbound::Garbled(format!("bad telegram: {e}")),
        }
    } else {
        match Reply::parse(payload) {
            Ok(reply) => {
                tracing::debug!(target: "lms400", "← {reply}");
                Inbound::Reply(reply)
            }
            Err(e) => Inbound::Garbled(e.to_string()),
        }
    }
}
