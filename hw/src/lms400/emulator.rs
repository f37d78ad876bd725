//! [`Lms400Emulator`]: a poll-driven LMS400 on a TCP port, backed by any [`LineScanner`].
//!
//! It serves one client at a time (a new connection replaces the old one), answers the
//! commands of [`super::Command`] with the replies listed in [`super::Reply`]'s module,
//! and on `mLRstopdata` sends every line the backing scanner returns as a measurement
//! telegram, then the stop answer.
//!
//! Like the device: `mSCsetscanconfig` and the filter writes need the service login
//! (`sFA 1` / `sFA A` otherwise); a wrong password is answered `sAN SetAccessMode 0`;
//! `Run` returns to user level. The scan configuration is checked against the device's
//! documented limits (resolution 0.1–1°, angles 55–125°, frequency 200–500 Hz), except
//! that frequencies down to **190 Hz** are accepted with a warning: the paper ran its
//! LMS400 at 190 Hz, below the documented range, so the real device evidently accepts it.
//! Only mode 20 (distance and remission) is streamed; the mean filter is accepted but not
//! emulated; the range filter is.

use super::command::{
    Command, CommandError, DataMode, FILTER_RANGE, SERVICE_LEVEL, SERVICE_PASSWORD,
};
use super::faults::Lms400Faults;
use super::frame::{FrameDecoder, FrameError, encode_frame};
use super::line_mapping::{LineMappingError, TelegramSettings, line_to_telegram};
use super::reply::{Reply, SopasError};
use super::scan_config::{ScanConfig, ScanConfigAnswer};
use super::telegram::TelegramError;
use nbv_core::rig::{LineScanner, RigError};
use std::collections::VecDeque;
use std::io::{self, ErrorKind, Read, Write};
use std::net::{Shutdown, SocketAddr, TcpListener, TcpStream};
use std::time::Instant;
use thiserror::Error;

/// Lowest scan frequency accepted (1/100 Hz): the paper's 190 Hz.
const MIN_FREQUENCY: u32 = 19_000;
/// Lowest documented scan frequency (1/100 Hz).
const MIN_DOCUMENTED_FREQUENCY: u32 = 20_000;
/// Highest scan frequency (1/100 Hz).
const MAX_FREQUENCY: u32 = 50_000;
/// Resolution limits (1/10000°).
const RESOLUTION_RANGE: std::ops::RangeInclusive<u32> = 1_000..=10_000;
/// Scan area (1/10000°).
const SCAN_AREA: std::ops::RangeInclusive<i64> = 550_000..=1_250_000;

/// Garbage sent before each telegram under [`Lms400Faults::garbage_before_telegrams`]:
/// noise, then a partial frame marker that runs into the real one.
const GARBAGE: &[u8] = b"\xFF\x00noise\x13\x02\x02\x02";

/// What went wrong while emulating.
#[derive(Debug, Error)]
pub enum EmulatorError {
    /// The listening socket failed.
    #[error("emulator socket: {0}")]
    Io(#[from] io::Error),
    /// The backing scanner failed (the client got an `sFA 4`).
    #[error("backing scanner: {0}")]
    Scanner(#[from] RigError),
    /// A backing line has no telegram (the client got an `sFA 5`).
    #[error("line cannot be sent: {0}")]
    Line(#[from] LineMappingError),
    /// A telegram could not be encoded (the client got an `sFA 5`).
    #[error("telegram cannot be encoded: {0}")]
    Telegram(#[from] TelegramError),
    /// A payload could not be framed.
    #[error("frame cannot be encoded: {0}")]
    Frame(#[from] FrameError),
}

/// Bytes waiting to be sent.
struct Outgoing {
    due: Instant,
    bytes: Vec<u8>,
    sent: usize,
    /// Part of a stop's output (counted by `disconnect_after_bytes`).
    stream: bool,
}

/// The connected client.
struct Session {
    stream: TcpStream,
    decoder: FrameDecoder,
    access_level: u8,
    streaming: bool,
    outbox: VecDeque<Outgoing>,
    stream_bytes_sent: usize,
}

/// An emulated LMS400 (see the module documentation).
///
/// ```no_run
/// use nbv_core::rig::{LineScanner, LineScannerSpec, RigError, ScanLine};
/// use nbv_hw::lms400::Lms400Emulator;
/// // Any LineScanner can back it (the CLI plugs in the twin's); this one sees nothing.
/// struct Blind(LineScannerSpec);
/// impl LineScanner for Blind {
///     fn spec(&self) -> &LineScannerSpec { &self.0 }
///     fn start(&mut self) -> Result<(), RigError> { Ok(()) }
///     fn stop(&mut self) -> Result<Vec<ScanLine>, RigError> { Ok(Vec::new()) }
/// }
/// let mut emulator = Lms400Emulator::bind("127.0.0.1:2111")?;
/// let mut scanner = Blind(LineScannerSpec::lms400());
/// loop {
///     if !emulator.poll(&mut scanner)? {
///         std::thread::sleep(std::time::Duration::from_millis(1));
///     }
/// }
/// # Ok::<(), nbv_hw::lms400::EmulatorError>(())
/// ```
pub struct Lms400Emulator {
    listener: TcpListener,
    session: Option<Session>,
    faults: Lms400Faults,
    scan_config: ScanConfig,
    filter_mask: u8,
    range_filter_mm: (u16, u16),
    telegram_counter: u16,
    logins: usize,
    connections: usize,
    drop_requested: bool,
}

impl Lms400Emulator {
    /// Listens on `addr` (e.g. `127.0.0.1:0` for any free port).
    pub fn bind(addr: &str) -> io::Result<Self> {
        let listener = TcpListener::bind(addr)?;
        listener.set_nonblocking(true)?;
        Ok(Self {
            listener,
            session: None,
            faults: Lms400Faults::default(),
            scan_config: ScanConfig {
                frequency: 36_000,
                resolution: 2_500,
                start_angle: 550_000,
                span: 700_000,
            },
            filter_mask: 0,
            range_filter_mm: (700, 3000),
            telegram_counter: 0,
            logins: 0,
            connections: 0,
            drop_requested: false,
        })
    }

    /// The address it listens on.
    pub fn local_addr(&self) -> io::Result<SocketAddr> {
        self.listener.local_addr()
    }

    /// The faults in force.
    pub fn faults(&self) -> &Lms400Faults {
        &self.faults
    }

    /// Replaces the faults in force.
    pub fn set_faults(&mut self, faults: Lms400Faults) {
        self.faults = faults;
    }

    /// The scan configuration last applied.
    pub fn scan_config(&self) -> ScanConfig {
        self.scan_config
    }

    /// The range filter (mm) and whether it is on.
    pub fn range_filter_mm(&self) -> Option<(u16, u16)> {
        (self.filter_mask & FILTER_RANGE != 0).then_some(self.range_filter_mm)
    }

    /// Successful logins so far.
    pub fn logins(&self) -> usize {
        self.logins
    }

    /// Connections accepted so far.
    pub fn connections(&self) -> usize {
        self.connections
    }

    /// Whether a client is connected.
    pub fn has_client(&self) -> bool {
        self.session.is_some()
    }

    /// Drops the client's connection at the next [`poll`](Self::poll).
    pub fn disconnect_client(&mut self) {
        self.drop_requested = true;
    }

    /// Does whatever is pending without blocking: accepts a client, answers its commands,
    /// sends due replies. Returns whether anything happened.
    pub fn poll(&mut self, scanner: &mut dyn LineScanner) -> Result<bool, EmulatorError> {
        let mut active = false;
        if std::mem::take(&mut self.drop_requested) && self.session.is_some() {
            self.close_session(scanner, "disconnect requested");
            active = true;
        }
        active |= self.accept(scanner)?;
        let commands = self.read_commands(scanner);
        active |= !commands.is_empty();
        let mut first_error = None;
        for payload in commands {
            if let Err(e) = self.handle(&payload, scanner) {
                tracing::warn!(target: "lms400-emulator", "{e}");
                first_error.get_or_insert(e);
            }
        }
        active |= self.flush(scanner);
        match first_error {
            Some(e) => Err(e),
            None => Ok(active),
        }
    }

    fn accept(&mut self, scanner: &mut dyn LineScanner) -> Result<bool, EmulatorError> {
        let (stream, peer) = match self.listener.accept() {
            Ok(accepted) => accepted,
            Err(e) if e.kind() == ErrorKind::WouldBlock => return Ok(false),
            Err(e) => return Err(e.into()),
        };
        if self.session.is_some() {
            self.close_session(scanner, "replaced by a new connection");
        }
        stream.set_nonblocking(true)?;
        stream.set_nodelay(true)?;
        tracing::info!(target: "lms400-emulator", "client {peer} connected");
        self.connections += 1;
        self.session = Some(Session {
            stream,
            decoder: FrameDecoder::new(),
            access_level: 0,
            streaming: false,
            outbox: VecDeque::new(),
            stream_bytes_sent: 0,
        });
        Ok(true)
    }

    /// Reads what the client sent; returns the complete command payloads.
    fn read_commands(&mut self, scanner: &mut dyn LineScanner) -> Vec<Vec<u8>> {
        let Some(session) = self.session.as_mut() else {
            return Vec::new();
        };
        let mut buffer = [0u8; 4096];
        let lost = loop {
            match session.stream.read(&mut buffer) {
                Ok(0) => break Some("client closed the connection".to_owned()),
                Ok(n) => session.decoder.push(buffer.get(..n).unwrap_or_default()),
                Err(e) if e.kind() == ErrorKind::WouldBlock => break None,
                Err(e) if e.kind() == ErrorKind::Interrupted => {}
                Err(e) => break Some(format!("connection lost: {e}")),
            }
        };
        let mut payloads = Vec::new();
        loop {
            match session.decoder.next_frame() {
                Ok(Some(payload)) => payloads.push(payload),
                Ok(None) => break,
                Err(e) => {
                    tracing::warn!(target: "lms400-emulator", "bad frame from the client: {e}");
                    queue_reply(
                        session,
                        &self.faults,
                        &Reply::Error(SopasError::INVALID_DATA),
                    );
                }
            }
        }
        if let Some(reason) = lost {
            self.close_session(scanner, &reason);
        }
        payloads
    }

    fn handle(
        &mut self,
        payload: &[u8],
        scanner: &mut dyn LineScanner,
    ) -> Result<(), EmulatorError> {
        let Some(session) = self.session.as_mut() else {
            return Ok(());
        };
        let command = match Command::parse(payload) {
            Ok(command) => command,
            Err(e) => {
                tracing::warn!(target: "lms400-emulator", "refused command: {e}");
                let code = match e {
                    CommandError::UnknownMethod(_) => SopasError::UNKNOWN_METHOD,
                    CommandError::UnknownVariable(_) => SopasError::UNKNOWN_VARIABLE,
                    CommandError::BadArguments { .. } => SopasError::INVALID_DATA,
                    CommandError::NotText | CommandError::UnknownType(_) => {
                        SopasError::UNKNOWN_COMMAND
                    }
                };
                queue_reply(session, &self.faults, &Reply::Error(code));
                return Ok(());
            }
        };
        let logged_in = session.access_level >= SERVICE_LEVEL;
        let needs_login = matches!(command, Command::SetScanConfig(_)) || command.is_write();
        if needs_login && !logged_in {
            let code = if command.is_write() {
                SopasError::WRITE_ACCESS_DENIED
            } else {
                SopasError::METHOD_ACCESS_DENIED
            };
            queue_reply(session, &self.faults, &Reply::Error(code));
            return Ok(());
        }
        let write_ack = Reply::WriteAck {
            name: command.name().to_owned(),
        };
        let reply = match command {
            Command::SetAccessMode { level, password } => {
                let accepted = level == SERVICE_LEVEL && password == SERVICE_PASSWORD;
                if accepted {
                    session.access_level = level;
                    self.logins += 1;
                }
                Reply::answer("SetAccessMode", &[if accepted { "1" } else { "0" }])
            }
            Command::SetScanConfig(requested) => {
                let status = check_scan_config(&requested);
                if status == ScanConfigAnswer::OK {
                    if requested.frequency < MIN_DOCUMENTED_FREQUENCY {
                        tracing::warn!(
                            target: "lms400-emulator",
                            "scan frequency {:.2} Hz is below the documented 200 Hz; accepted as the paper's device did",
                            requested.frequency_hz()
                        );
                    }
                    self.scan_config = requested;
                }
                let answer = ScanConfigAnswer {
                    status,
                    frequency: self.scan_config.frequency,
                    resolution: self.scan_config.resolution,
                };
                let args = answer.to_args();
                let args: Vec<&str> = args.split(' ').collect();
                Reply::answer("mSCsetscanconfig", &args)
            }
            Command::SelectFilters { mask } if mask <= 0xF => {
                self.filter_mask = mask;
                write_ack
            }
            Command::SetRangeFilter { min_mm, max_mm } if min_mm < max_mm => {
                self.range_filter_mm = (min_mm, max_mm);
                write_ack
            }
            Command::SetMeanFilter { .. } => write_ack,
            Command::SelectFilters { .. } | Command::SetRangeFilter { .. } => {
                Reply::Error(SopasError::INVALID_DATA)
            }
            Command::RequestData(mode) => {
                if mode != DataMode::DistanceRemission {
                    Reply::Error(SopasError::INVALID_DATA)
                } else if session.streaming {
                    Reply::Error(SopasError::LOCAL_CONDITION_FAILED)
                } else if let Err(e) = scanner.start() {
                    queue_reply(
                        session,
                        &self.faults,
                        &Reply::Error(SopasError::LOCAL_CONDITION_FAILED),
                    );
                    return Err(e.into());
                } else {
                    session.streaming = true;
                    Reply::MethodAck {
                        name: "mLRreqdata".into(),
                    }
                }
            }
            Command::StopData => {
                if session.streaming {
                    session.streaming = false;
                    let settings = TelegramSettings {
                        format: DataMode::DistanceRemission.code(),
                        scan_frequency: u16::try_from(self.scan_config.frequency)
                            .unwrap_or(u16::MAX),
                        range_filter_mm: (self.filter_mask & FILTER_RANGE != 0)
                            .then_some(self.range_filter_mm),
                    };
                    if let Err(e) = queue_lines(
                        session,
                        &self.faults,
                        scanner,
                        &settings,
                        &mut self.telegram_counter,
                    ) {
                        let code = match e {
                            EmulatorError::Scanner(_) => SopasError::LOCAL_CONDITION_FAILED,
                            _ => SopasError::INVALID_DATA,
                        };
                        queue_reply(session, &self.faults, &Reply::Error(code));
                        return Err(e);
                    }
                }
                let stop = frame_of(&Reply::answer("mLRstopdata", &["0"]).to_payload())?;
                queue(session, &self.faults, stop, true);
                return Ok(());
            }
            Command::Run => {
                session.access_level = 0;
                Reply::answer("Run", &["1"])
            }
        };
        queue_reply(session, &self.faults, &reply);
        Ok(())
    }

    /// Sends what is due; returns whether anything was sent or the session ended.
    fn flush(&mut self, scanner: &mut dyn LineScanner) -> bool {
        let Some(session) = self.session.as_mut() else {
            return false;
        };
        let now = Instant::now();
        let mut active = false;
        let mut lost = None;
        while let Some(head) = session.outbox.front_mut() {
            if head.due > now {
                break;
            }
            let mut end = head.bytes.len();
            if head.stream
                && let Some(limit) = self.faults.disconnect_after_bytes
            {
                let budget = limit.saturating_sub(session.stream_bytes_sent);
                end = end.min(head.sent + budget);
            }
            let Some(pending) = head.bytes.get(head.sent..end) else {
                break;
            };
            if pending.is_empty() && end < head.bytes.len() {
                lost = Some("fault injection: disconnect".to_owned());
                break;
            }
            match session.stream.write(pending) {
                Ok(n) => {
                    active |= n > 0;
                    head.sent += n;
                    if head.stream {
                        session.stream_bytes_sent += n;
                    }
                    if head.sent >= head.bytes.len() {
                        session.outbox.pop_front();
                    }
                }
                Err(e) if e.kind() == ErrorKind::WouldBlock => break,
                Err(e) if e.kind() == ErrorKind::Interrupted => {}
                Err(e) => {
                    lost = Some(format!("connection lost: {e}"));
                    break;
                }
            }
        }
        if let Some(reason) = lost {
            self.close_session(scanner, &reason);
            active = true;
        }
        active
    }

    fn close_session(&mut self, scanner: &mut dyn LineScanner, reason: &str) {
        let Some(session) = self.session.take() else {
            return;
        };
        tracing::info!(target: "lms400-emulator", "client dropped: {reason}");
        let _ = session.stream.shutdown(Shutdown::Both);
        if session.streaming
            && let Err(e) = scanner.stop()
        {
            tracing::warn!(target: "lms400-emulator", "stopping the backing scanner: {e}");
        }
    }
}

/// Status of a requested scan configuration against the device's limits.
fn check_scan_config(config: &ScanConfig) -> u8 {
    let frequency_ok = (MIN_FREQUENCY..=MAX_FREQUENCY).contains(&config.frequency);
    let resolution_ok = RESOLUTION_RANGE.contains(&config.resolution);
    let start = i64::from(config.start_angle);
    let area_ok =
        SCAN_AREA.contains(&start) && SCAN_AREA.contains(&(start + i64::from(config.span)));
    match (frequency_ok, resolution_ok, area_ok) {
        (false, false, _) => ScanConfigAnswer::BAD_FREQUENCY_AND_RESOLUTION,
        (false, true, _) => ScanConfigAnswer::BAD_FREQUENCY,
        (true, false, _) => ScanConfigAnswer::BAD_RESOLUTION,
        (true, true, false) => ScanConfigAnswer::BAD_SCAN_AREA,
        (true, true, true) => ScanConfigAnswer::OK,
    }
}

/// Stops the backing scanner and queues its lines as telegrams.
fn queue_lines(
    session: &mut Session,
    faults: &Lms400Faults,
    scanner: &mut dyn LineScanner,
    settings: &TelegramSettings,
    counter: &mut u16,
) -> Result<(), EmulatorError> {
    let lines = scanner.stop()?;
    session.stream_bytes_sent = 0;
    for line in &lines {
        let telegram = line_to_telegram(line, settings, *counter)?;
        *counter = counter.wrapping_add(1);
        let mut frame = frame_of(&telegram.encode()?)?;
        if faults.corrupt_checksum
            && let Some(checksum) = frame.last_mut()
        {
            *checksum ^= 0x5A;
        }
        if faults.garbage_before_telegrams {
            queue(session, faults, GARBAGE.to_vec(), true);
        }
        queue(session, faults, frame, true);
    }
    Ok(())
}

fn frame_of(payload: &[u8]) -> Result<Vec<u8>, EmulatorError> {
    Ok(encode_frame(payload)?)
}

fn queue_reply(session: &mut Session, faults: &Lms400Faults, reply: &Reply) {
    match encode_frame(&reply.to_payload()) {
        Ok(frame) => queue(session, faults, frame, false),
        Err(e) => tracing::warn!(target: "lms400-emulator", "reply cannot be framed: {e}"),
    }
}

fn queue(session: &mut Session, faults: &Lms400Faults, bytes: Vec<u8>, stream: bool) {
    let due = Instant::now() + faults.delay_replies.unwrap_or_default();
    session.outbox.push_back(Outgoing {
        due,
        bytes,
        sent: 0,
        stream,
    });
}
