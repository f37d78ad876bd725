//! [`LineStream`]: a TCP connection carrying `\n`-terminated ASCII lines, read with a
//! deadline and a bounded buffer (a peer that never sends a newline cannot make it grow
//! past [`MAX_LINE`](super::protocol::MAX_LINE)).

use super::protocol::MAX_LINE;
use nbv_core::rig::RigError;
use std::io::{ErrorKind, Read, Write};
use std::net::TcpStream;
use std::time::{Duration, Instant};

/// A line-oriented TCP connection of a named device.
#[derive(Debug)]
pub struct LineStream {
    stream: TcpStream,
    buffer: Vec<u8>,
    device: &'static str,
}

impl LineStream {
    /// Wraps a connected stream.
    pub fn new(stream: TcpStream, device: &'static str) -> Self {
        // Lines are small and latency matters more than throughput.
        let _ = stream.set_nodelay(true);
        Self {
            stream,
            buffer: Vec::with_capacity(MAX_LINE),
            device,
        }
    }

    fn disconnected(&self, detail: impl Into<String>) -> RigError {
        RigError::Disconnected {
            device: self.device.to_owned(),
            detail: detail.into(),
        }
    }

    /// Sends one line (the terminator is appended).
    pub fn send(&mut self, line: &str, timeout: Duration) -> Result<(), RigError> {
        let _ = self.stream.set_write_timeout(Some(timeout));
        let mut bytes = Vec::with_capacity(line.len() + 1);
        bytes.extend_from_slice(line.as_bytes());
        bytes.push(b'\n');
        self.stream.write_all(&bytes).map_err(|e| match e.kind() {
            ErrorKind::WouldBlock | ErrorKind::TimedOut => RigError::Timeout {
                device: self.device.to_owned(),
                seconds: timeout.as_secs_f64(),
            },
            _ => self.disconnected(format!("sending `{line}`: {e}")),
        })
    }

    /// The next line (without its terminator), waiting at most `timeout` for it.
    pub fn receive(&mut self, timeout: Duration) -> Result<String, RigError> {
        let deadline = Instant::now() + timeout;
        loop {
            if let Some(end) = self.buffer.iter().position(|&b| b == b'\n') {
                let line: Vec<u8> = self.buffer.drain(..=end).collect();
                let text = String::from_utf8_lossy(&line[..end]);
                return Ok(text.trim_end_matches('\r').to_owned());
            }
            if self.buffer.len() > MAX_LINE {
                return Err(RigError::Protocol {
                    device: self.device.to_owned(),
                    detail: format!("a line longer than {MAX_LINE} bytes"),
                });
            }
            let now = Instant::now();
            if now >= deadline {
                return Err(RigError::Timeout {
                    device: self.device.to_owned(),
                    seconds: timeout.as_secs_f64(),
                });
            }
            let _ = self.stream.set_read_timeout(Some(deadline - now));
            let mut chunk = [0u8; MAX_LINE];
            let room = (MAX_LINE + 1 - self.buffer.len()).min(chunk.len());
            match self.stream.read(&mut chunk[..room]) {
                Ok(0) => return Err(self.disconnected("connection closed by the peer")),
                Ok(n) => self.buffer.extend_from_slice(&chunk[..n]),
                Err(e) if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut) => {}
                Err(e) if e.kind() == ErrorKind::Interrupted => {}
                Err(e) => return Err(self.disconnected(e.to_string())),
            }
        }
    }
}
