//! [`Lms400Scanner`]: the LMS400 driver, a [`LineScanner`] over TCP.
//!
//! Session: login (`SetAccessMode 4`), scan configuration from the spec (see
//! [`ScanConfig::from_spec`] for the angle convention), range filter from `spec.range`
//! (`FLsel 4`, `FLrang <min> <max>` in mm), `Run`. [`LineScanner::start`] sends
//! `mLRreqdata 20`; [`LineScanner::stop`] sends `mLRstopdata` and collects every telegram
//! up to the stop answer. A lost connection is re-established (session included) by the
//! next call, up to `reconnect_attempts` times; a call that fails drops the connection so
//! that the next one starts clean.

use super::command::{Command, DataMode, FILTER_RANGE, SERVICE_LEVEL, SERVICE_PASSWORD};
use super::config::Lms400Config;
use super::line_mapping::{TimestampUnwrapper, telegram_to_line};
use super::link::{DEVICE, Inbound, Link};
use super::reply::Reply;
use super::scan_config::{ScanConfig, ScanConfigAnswer};
use super::telegram::MeasurementTelegram;
use nbv_core::rig::{LineScanner, LineScannerSpec, RigError, ScanLine};

/// The LMS400 driver.
///
/// ```no_run
/// use nbv_core::rig::LineScanner;
/// use nbv_hw::lms400::{Lms400Config, Lms400Scanner};
/// let mut scanner = Lms400Scanner::connect(Lms400Config::default())?;
/// scanner.start()?;
/// std::thread::sleep(std::time::Duration::from_secs(1));
/// let lines = scanner.stop()?;
/// println!("{} lines", lines.len());
/// # Ok::<(), nbv_core::rig::RigError>(())
/// ```
pub struct Lms400Scanner {
    config: Lms400Config,
    scan_config: ScanConfig,
    range_filter_mm: (u16, u16),
    link: Option<Link>,
    streaming: bool,
    clock: TimestampUnwrapper,
    /// Telegrams that arrived while the driver waited for a reply.
    held: Vec<MeasurementTelegram>,
}

impl std::fmt::Debug for Lms400Scanner {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Lms400Scanner")
            .field("address", &self.config.address)
            .field("scan_config", &self.scan_config)
            .field("connected", &self.link.is_some())
            .field("streaming", &self.streaming)
            .finish_non_exhaustive()
    }
}

impl Lms400Scanner {
    /// Connects, logs in and configures the scanner for `config.spec`.
    pub fn connect(config: Lms400Config) -> Result<Self, RigError> {
        let state = |detail: String| RigError::State {
            device: DEVICE.into(),
            detail,
        };
        let scan_config = ScanConfig::from_spec(&config.spec)
            .map_err(|e| state(format!("spec cannot be configured: {e}")))?;
        let millimetres = |m: f64| {
            let mm = (m * 1e3).round();
            (mm.is_finite() && (0.0..=f64::from(u16::MAX)).contains(&mm)).then_some(mm as u16)
        };
        let range_filter_mm = match config.spec.range.map(millimetres) {
            [Some(min), Some(max)] if min < max => (min, max),
            _ => {
                return Err(state(format!(
                    "range {:?} m cannot be a range filter",
                    config.spec.range
                )));
            }
        };
        let mut scanner = Self {
            config,
            scan_config,
            range_filter_mm,
            link: None,
            streaming: false,
            clock: TimestampUnwrapper::default(),
            held: Vec::new(),
        };
        scanner.link = Some(scanner.open_session()?);
        Ok(scanner)
    }

    /// The driver's settings.
    pub fn config(&self) -> &Lms400Config {
        &self.config
    }

    /// Changes the longest wait for any answer or read from now on, on the live connection
    /// and on those re-established later (e.g. a generous one while the session is set up,
    /// a short one while streaming).
    pub fn set_timeout(&mut self, timeout: std::time::Duration) {
        self.config.timeout = timeout;
        if let Some(link) = self.link.as_mut() {
            link.set_timeout(timeout);
        }
    }

    /// The scan configuration sent to the device.
    pub fn scan_config(&self) -> ScanConfig {
        self.scan_config
    }

    /// Whether a connection is up (as far as the driver knows).
    pub fn is_connected(&self) -> bool {
        self.link.as_ref().is_some_and(|link| !link.is_closed())
    }

    /// A new connection with login, scan configuration, range filter and `Run` done.
    fn open_session(&self) -> Result<Link, RigError> {
        let mut link = Link::open(&self.config.address, self.config.timeout)?;
        let mut held = Vec::new();
        let login = Command::SetAccessMode {
            level: SERVICE_LEVEL,
            password: SERVICE_PASSWORD,
        };
        match exchange(&mut link, &login, &mut held)? {
            Reply::MethodAnswer { args, .. } if args == ["1"] => {}
            Reply::MethodAnswer { args, .. } if args == ["0"] => {
                return Err(protocol("login refused (wrong password)".into()));
            }
            other => return Err(unexpected(&login, &other)),
        }
        let configure = Command::SetScanConfig(self.scan_config);
        let reply = exchange(&mut link, &configure, &mut held)?;
        let Reply::MethodAnswer { args, .. } = &reply else {
            return Err(unexpected(&configure, &reply));
        };
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let answer = ScanConfigAnswer::parse_args(&args)
            .map_err(|e| protocol(format!("answer to mSCsetscanconfig: {e}")))?;
        if answer.status != ScanConfigAnswer::OK {
            return Err(protocol(format!(
                "scan configuration `{}` refused: status {} ({})",
                self.scan_config.to_args(),
                answer.status,
                answer.status_text()
            )));
        }
        if (answer.frequency, answer.resolution)
            != (self.scan_config.frequency, self.scan_config.resolution)
        {
            tracing::warn!(
                target: "lms400",
                "device applied {:.2} Hz / {:.4}° instead of {:.2} Hz / {:.4}°",
                f64::from(answer.frequency) * 1e-2,
                f64::from(answer.resolution) * 1e-4,
                self.scan_config.frequency_hz(),
                self.scan_config.resolution_deg()
            );
        }
        let (min_mm, max_mm) = self.range_filter_mm;
        for write in [
            Command::SelectFilters { mask: FILTER_RANGE },
            Command::SetRangeFilter { min_mm, max_mm },
        ] {
            match exchange(&mut link, &write, &mut held)? {
                Reply::WriteAck { .. } => {}
                other => return Err(unexpected(&write, &other)),
            }
        }
        match exchange(&mut link, &Command::Run, &mut held)? {
            Reply::MethodAnswer { args, .. } if args == ["1"] => {}
            other => return Err(unexpected(&Command::Run, &other)),
        }
        if !held.is_empty() {
            tracing::warn!(target: "lms400", "dropped {} telegrams of an earlier stream", held.len());
        }
        tracing::info!(target: "lms400", "connected to {} ({})", self.config.address, self.scan_config.to_args());
        Ok(link)
    }

    /// Makes sure a live link exists; returns whether it was opened by this call.
    fn ensure_link(&mut self) -> Result<bool, RigError> {
        if self.is_connected() {
            return Ok(false);
        }
        self.link = None;
        let mut last_error = None;
        for attempt in 1..=self.config.reconnect_attempts {
            match self.open_session() {
                Ok(link) => {
                    tracing::info!(target: "lms400", "reconnected (attempt {attempt})");
                    self.link = Some(link);
                    return Ok(true);
                }
                Err(e) => {
                    tracing::warn!(target: "lms400", "reconnection attempt {attempt} failed: {e}");
                    last_error = Some(e);
                }
            }
        }
        Err(last_error.unwrap_or_else(|| RigError::Disconnected {
            device: DEVICE.into(),
            detail: "connection lost and reconnect_attempts is 0".into(),
        }))
    }

    fn request_data(&mut self) -> Result<(), RigError> {
        let link = self.link.as_mut().ok_or_else(not_connected)?;
        let command = Command::RequestData(DataMode::DistanceRemission);
        match exchange(link, &command, &mut self.held)? {
            Reply::MethodAck { .. } => Ok(()),
            Reply::MethodAnswer { args, .. } if args == ["0"] => Ok(()),
            other => Err(unexpected(&command, &other)),
        }
    }

    /// Sends the stop and collects telegrams into `telegrams` until its answer.
    fn collect_until_stopped(
        &mut self,
        telegrams: &mut Vec<MeasurementTelegram>,
    ) -> Result<(), RigError> {
        let link = self.link.as_mut().ok_or_else(not_connected)?;
        link.send(&Command::StopData)?;
        loop {
            match link.receive()? {
                Inbound::Telegram(telegram) => telegrams.push(telegram),
                Inbound::Reply(Reply::MethodAck { name }) if name == "mLRstopdata" => {}
                Inbound::Reply(Reply::MethodAnswer { name, args }) if name == "mLRstopdata" => {
                    return if args == ["0"] {
                        Ok(())
                    } else {
                        Err(protocol(format!("mLRstopdata answered {args:?}")))
                    };
                }
                Inbound::Reply(Reply::Error(code)) => {
                    return Err(protocol(format!("mLRstopdata refused: {code}")));
                }
                Inbound::Reply(other) => {
                    return Err(protocol(format!(
                        "unexpected reply `{other}` while stopping"
                    )));
                }
                Inbound::Garbled(detail) => return Err(protocol(detail)),
                Inbound::Closed(detail) => {
                    return Err(RigError::Disconnected {
                        device: DEVICE.into(),
                        detail,
                    });
                }
            }
        }
    }
}

impl LineScanner for Lms400Scanner {
    fn spec(&self) -> &LineScannerSpec {
        &self.config.spec
    }

    fn start(&mut self) -> Result<(), RigError> {
        if self.streaming {
            return Err(RigError::State {
                device: DEVICE.into(),
                detail: "start while already streaming".into(),
            });
        }
        self.held.clear();
        let fresh = self.ensure_link()?;
        let result = match self.request_data() {
            Err(RigError::Disconnected { detail, .. }) if !fresh => {
                tracing::warn!(target: "lms400", "link lost since the last call ({detail}); reconnecting");
                self.link = None;
                self.ensure_link()?;
                self.request_data()
            }
            other => other,
        };
        match result {
            Ok(()) => {
                self.streaming = true;
                Ok(())
            }
            Err(e) => {
                self.link = None;
                Err(e)
            }
        }
    }

    fn stop(&mut self) -> Result<Vec<ScanLine>, RigError> {
        if !self.streaming {
            return Err(RigError::State {
                device: DEVICE.into(),
                detail: "stop without start".into(),
            });
        }
        self.streaming = false;
        let mut telegrams = std::mem::take(&mut self.held);
        let collected = self.collect_until_stopped(&mut telegrams);
        // Even the telegrams of a failed stop advance the clock unwrapping.
        let range = self.config.spec.range;
        let lines = telegrams
            .iter()
            .map(|telegram| {
                let micros = self.clock.unwrap(telegram.timestamp_us);
                let time = micros as f64 * 1e-6 + self.config.clock_offset_s;
                telegram_to_line(telegram, time, range)
            })
            .collect();
        match collected {
            Ok(()) => Ok(lines),
            Err(e) => {
                self.link = None;
                Err(e)
            }
        }
    }
}

/// Sends `command` and returns its reply (an `sMA` is skipped when an `sAN` follows;
/// telegrams met on the way are kept in `held`).
fn exchange(
    link: &mut Link,
    command: &Command,
    held: &mut Vec<MeasurementTelegram>,
) -> Result<Reply, RigError> {
    link.send(command)?;
    let ack_is_final = matches!(command, Command::RequestData(_));
    loop {
        match link.receive()? {
            Inbound::Telegram(telegram) => held.push(telegram),
            Inbound::Reply(Reply::Error(code)) => {
                return Err(protocol(format!("`{command}` refused: {code}")));
            }
            Inbound::Reply(Reply::MethodAck { name })
                if name == command.name() && !ack_is_final => {}
            Inbound::Reply(reply) => {
                let name = match &reply {
                    Reply::MethodAck { name }
                    | Reply::MethodAnswer { name, .. }
                    | Reply::WriteAck { name } => name.as_str(),
                    Reply::Error(_) => "",
                };
                return if name == command.name() {
                    Ok(reply)
                } else {
                    Err(unexpected(command, &reply))
                };
            }
            Inbound::Garbled(detail) => return Err(protocol(detail)),
            Inbound::Closed(detail) => {
                return Err(RigError::Disconnected {
                    device: DEVICE.into(),
                    detail,
                });
            }
        }
    }
}

fn protocol(detail: String) -> RigError {
    RigError::Protocol {
        device: DEVICE.into(),
        detail,
    }
}

fn unexpected(command: &Command, reply: &Reply) -> RigError {
    protocol(format!("unexpected reply `{reply}` to `{command}`"))
}

fn not_connected() -> RigError {
    RigError::Disconnected {
        device: DEVICE.into(),
        detail: "not connected".into(),
    }
}
