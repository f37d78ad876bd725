//! [`C4gEmulator`]: the PDL2 server's protocol on loopback, backed by any [`Arm`] (the CLI
//! and the tests plug in the twin), so that [`C4gArm`](super::C4gArm) is exercised byte for
//! byte without a controller.
//!
//! Poll-driven and single-threaded: [`C4gEmulator::poll`] accepts a client, answers
//! complete command lines and flushes due output without blocking; the backing arm is
//! passed at each poll. A `MOVE` executes on the backing arm at once and its reported
//! samples are streamed as `S` lines, then `DONE`. The clock it reports is the backing
//! arm's: the time of its latest sample (between motions the arm stands still, so a
//! stale clock poses nothing wrongly). One client at a time, like the PDL2 server; when a
//! client is lost during a motion the emulator counts a stop, as the server stops the arm.
//!
//! [`C4gFaults`] injects the failures the client must survive: a connection dropped
//! mid-motion, a controller that stops answering, garbage, slow replies.

use super::protocol::{Command, ErrorCode, MAX_LINE, PROTOCOL_VERSION, Reply, xyzaer_from_pose};
use nbv_core::kinematics::Joints;
use nbv_core::kinematics::Robot;
use nbv_core::rig::{Arm, JointPath, RigError};
use std::collections::VecDeque;
use std::io::{self, ErrorKind, Read, Write};
use std::net::{SocketAddr, TcpListener, TcpStream, ToSocketAddrs};
use std::time::{Duration, Instant};

/// Failures to inject.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct C4gFaults {
    /// Close the connection after sending this many `S` samples of a motion.
    pub disconnect_after_samples: Option<usize>,
    /// Stop answering (but keep the connection open) after this many `S` samples.
    pub silent_after_samples: Option<usize>,
    /// Send a line of garbage instead of the answer to the next command.
    pub garbage_reply: bool,
    /// Hold every reply this long before sending it.
    pub reply_delay: Option<Duration>,
}

/// What the emulator has seen, for tests and logs.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct C4gEmulatorStats {
    /// Clients accepted.
    pub connections: usize,
    /// Commands answered.
    pub commands: usize,
    /// Motions executed on the backing arm.
    pub motions: usize,
    /// Motions cut short because the client was lost while their samples were still
    /// going out (the PDL2 server cancels the motion of a lost client). A client that says
    /// `BYE` between motions is not one.
    pub stops: usize,
    /// `STOP` commands received, answered or not (a silent controller ignores them).
    pub stop_requests: usize,
    /// Clients gone: after `BYE`, hung up by the client, or dropped by a fault.
    pub disconnections: usize,
}

struct Client {
    stream: TcpStream,
    input: Vec<u8>,
    output: VecDeque<(Instant, Vec<u8>)>,
    /// Samples of the current motion sent so far, while one is being streamed.
    moving: Option<usize>,
    silent: bool,
}

/// The emulated C4G with its PDL2 server.
///
/// ```
/// use nbv_hw::comau::{C4gArm, C4gConfig, C4gEmulator};
/// let emulator = C4gEmulator::bind("127.0.0.1:0")?;
/// let address = emulator.local_addr()?.to_string();
/// assert!(address.starts_with("127.0.0.1:"));
/// # Ok::<(), std::io::Error>(())
/// ```
pub struct C4gEmulator {
    listener: TcpListener,
    client: Option<Client>,
    override_pct: u8,
    clock_s: f64,
    faults: C4gFaults,
    stats: C4gEmulatorStats,
    kinematics: Option<(Robot, String)>,
}

impl C4gEmulator {
    /// Listens on `address` (`127.0.0.1:0` picks a free port).
    pub fn bind(address: impl ToSocketAddrs) -> io::Result<Self> {
        let listener = TcpListener::bind(address)?;
        listener.set_nonblocking(true)?;
        Ok(Self {
            listener,
            client: None,
            override_pct: 100,
            clock_s: 0.0,
            faults: C4gFaults::default(),
            stats: C4gEmulatorStats::default(),
            kinematics: None,
        })
    }

    /// Answers `POS` with the pose of `flange` by `robot`'s forward kinematics, as the
    /// controller does with its own model (without it, `POS` is refused).
    pub fn with_kinematics(mut self, robot: Robot, flange: impl Into<String>) -> Self {
        self.kinematics = Some((robot, flange.into()));
        self
    }

    /// The address it listens on.
    pub fn local_addr(&self) -> io::Result<SocketAddr> {
        self.listener.local_addr()
    }

    /// Sets the failures to inject from now on.
    pub fn set_faults(&mut self, faults: C4gFaults) {
        self.faults = faults;
    }

    /// What it has seen so far.
    pub fn stats(&self) -> &C4gEmulatorStats {
        &self.stats
    }

    /// Does the pending work without blocking; `true` if anything happened.
    pub fn poll(&mut self, arm: &mut dyn Arm) -> bool {
        let mut busy = false;
        if self.client.is_none()
            && let Ok((stream, _)) = self.listener.accept()
            && stream.set_nonblocking(true).is_ok()
        {
            let _ = stream.set_nodelay(true);
            self.client = Some(Client {
                stream,
                input: Vec::new(),
                output: VecDeque::new(),
                moving: None,
                silent: false,
            });
            self.stats.connections += 1;
            busy = true;
        }
        let Some(mut client) = self.client.take() else {
            return busy;
        };
        let alive = self.serve(&mut client, arm, &mut busy);
        if alive {
            self.client = Some(client);
        } else {
            self.stats.disconnections += 1;
            if client.moving.is_some() || client.output.iter().any(|(_, l)| l.starts_with(b"S ")) {
                // Lost while a motion was still streaming (a fault cut it, or samples were
                // still queued): the PDL2 server cancels the motion of a lost client.
                self.stats.stops += 1;
            }
        }
        busy
    }

    /// Reads, answers and flushes one client; `false` once it is gone.
    fn serve(&mut self, client: &mut Client, arm: &mut dyn Arm, busy: &mut bool) -> bool {
        let mut chunk = [0u8; 512];
        // The client hung up; the lines it sent before are still answered (as the PDL2
        // server reads them), so what it last said (`BYE`, `STOP`) is seen whatever the
        // timing of its hang-up.
        let mut gone = false;
        loop {
            match client.stream.read(&mut chunk) {
                Ok(0) => {
                    gone = true;
                    break;
                }
                Ok(n) => {
                    client.input.extend_from_slice(&chunk[..n]);
                    *busy = true;
                }
                Err(e) if e.kind() == ErrorKind::WouldBlock => break,
                Err(e) if e.kind() == ErrorKind::Interrupted => {}
                Err(_) => {
                    gone = true;
                    break;
                }
            }
            if client.input.len() > 4 * MAX_LINE {
                break;
            }
        }
        while let Some(end) = client.input.iter().position(|&b| b == b'\n') {
            let line: Vec<u8> = client.input.drain(..=end).collect();
            let text = String::from_utf8_lossy(&line[..end]).into_owned();
            self.stats.commands += 1;
            *busy = true;
            self.answer(client, &text, arm);
        }
        if gone {
            *busy = true;
            return false;
        }
        if client.input.len() > MAX_LINE {
            client.input.clear();
            self.queue(
                client,
                &Reply::Err(ErrorCode::BadCommand, "line too long".into()),
            );
        }
        self.flush(client, busy)
    }

    fn queue(&mut self, client: &mut Client, reply: &Reply) {
        if client.silent {
            return;
        }
        let is_sample = matches!(reply, Reply::Sample(..));
        if is_sample {
            let sent = client.moving.unwrap_or(0);
            if self.faults.silent_after_samples == Some(sent) {
                client.silent = true;
                return;
            }
            client.moving = Some(sent + 1);
        }
        let release = Instant::now() + self.faults.reply_delay.unwrap_or_default();
        let mut line = reply.to_string().into_bytes();
        line.push(b'\n');
        client.output.push_back((release, line));
    }

    fn answer(&mut self, client: &mut Client, line: &str, arm: &mut dyn Arm) {
        if std::mem::take(&mut self.faults.garbage_reply) {
            let release = Instant::now();
            client
                .output
                .push_back((release, b"\x07#?%garbage\n".to_vec()));
            return;
        }
        let command = match Command::parse(line) {
            Ok(c) => c,
            Err(e) => {
                let code = if e.reason.starts_with("unknown") || e.reason == "empty line" {
                    ErrorCode::BadCommand
                } else {
                    ErrorCode::BadArgument
                };
                self.queue(client, &Reply::Err(code, e.reason));
                return;
            }
        };
        match command {
            Command::Hello => self.queue(
                client,
                &Reply::Ok(vec!["NBV-C4G".into(), PROTOCOL_VERSION.to_string()]),
            ),
            Command::Override(p) => {
                self.override_pct = p;
                self.queue(client, &Reply::Ok(Vec::new()));
            }
            Command::Joints => match arm.joints() {
                Ok(q) => {
                    let mut words = vec![format!("{:.0}", self.clock_s * 1000.0)];
                    words.extend(degrees(&q).iter().map(|d| format!("{d:.4}")));
                    self.queue(client, &Reply::Ok(words));
                }
                Err(e) => self.queue(client, &Reply::Err(ErrorCode::Alarm, e.to_string())),
            },
            Command::Pose => {
                let pose = match (&self.kinematics, arm.joints()) {
                    (Some((robot, flange)), Ok(q)) => {
                        robot.fk(&q, flange).map_err(|e| e.to_string())
                    }
                    (None, _) => Err(
                        "POS needs the controller's kinematics (C4gEmulator::with_kinematics)"
                            .into(),
                    ),
                    (_, Err(e)) => Err(e.to_string()),
                };
                match pose {
                    Ok(pose) => {
                        let mut words = vec![format!("{:.0}", self.clock_s * 1000.0)];
                        words.extend(xyzaer_from_pose(&pose).iter().map(|v| format!("{v:.4}")));
                        self.queue(client, &Reply::Ok(words));
                    }
                    Err(e) => self.queue(client, &Reply::Err(ErrorCode::Alarm, e)),
                }
            }
            Command::Stop => {
                self.stats.stop_requests += 1;
                self.queue(client, &Reply::Ok(Vec::new()));
            }
            Command::Bye => {
                self.queue(client, &Reply::Ok(Vec::new()));
                client.input.clear();
                // Hang up once the answer is out.
                let release = client.output.back().map_or_else(Instant::now, |(t, _)| *t);
                client.output.push_back((release, Vec::new()));
            }
            Command::Move(target) => self.execute(client, target, arm),
        }
    }

    fn execute(&mut self, client: &mut Client, target_deg: [f64; 6], arm: &mut dyn Arm) {
        let current = match arm.joints() {
            Ok(q) => q,
            Err(e) => return self.queue(client, &Reply::Err(ErrorCode::Alarm, e.to_string())),
        };
        let target = Joints::from_fn(|k, _| target_deg[k].to_radians());
        let path = JointPath {
            waypoints: vec![current, target],
            speed_fraction: f64::from(self.override_pct) / 100.0,
        };
        match arm.execute(&path) {
            Ok(motion) => {
                self.stats.motions += 1;
                self.queue(client, &Reply::Ok(Vec::new()));
                client.moving = Some(0);
                let n = motion.samples.len();
                for (k, s) in motion.samples.iter().enumerate() {
                    self.clock_s = self.clock_s.max(s.time);
                    let t = s.time * 1000.0;
                    let deg = degrees(&s.joints);
                    if k + 1 < n {
                        self.queue(client, &Reply::Sample(t, deg));
                        if self.faults.disconnect_after_samples == client.moving {
                            // Flush what is due, then drop the connection mid-motion.
                            client.output.push_back((Instant::now(), Vec::new()));
                            return;
                        }
                    } else {
                        self.queue(client, &Reply::Done(t, deg));
                    }
                }
                client.moving = None;
            }
            Err(RigError::JointLimit { joint, value_deg }) => self.queue(
                client,
                &Reply::Err(
                    ErrorCode::Limit,
                    format!(
                        "joint {} at {value_deg:.2} deg is outside its stroke",
                        joint + 1
                    ),
                ),
            ),
            Err(RigError::Collision { link, with, time }) => {
                self.clock_s = self.clock_s.max(time);
                let text = format!("{:.0} {link} {with}", time * 1000.0);
                self.queue(client, &Reply::Err(ErrorCode::Collision, text));
            }
            Err(e) => self.queue(client, &Reply::Err(ErrorCode::Alarm, e.to_string())),
        }
    }

    /// Writes the output that is due; an empty line queued is the signal to hang up.
    fn flush(&mut self, client: &mut Client, busy: &mut bool) -> bool {
        let now = Instant::now();
        while let Some((release, bytes)) = client.output.front() {
            if *release > now {
                break;
            }
            if bytes.is_empty() {
                // Hang up. Whether a motion was cut short is the caller's to judge from
                // `moving` and what is still queued: after `BYE` nothing is.
                let _ = client.stream.shutdown(std::net::Shutdown::Both);
                return false;
            }
            match client.stream.write(bytes) {
                Ok(n) if n == bytes.len() => {
                    client.output.pop_front();
                    *busy = true;
                }
                Ok(n) => {
                    if let Some((_, b)) = client.output.front_mut() {
                        b.drain(..n);
                    }
                    *busy = true;
                    break;
                }
                Err(e) if e.kind() == ErrorKind::WouldBlock => break,
                Err(e) if e.kind() == ErrorKind::Interrupted => {}
                Err(_) => return false,
            }
        }
        if client.output.is_empty() && client.moving.is_some() && !client.silent {
            // Every sample of the motion went out: it is complete on the wire.
            client.moving = None;
        }
        true
    }
}

fn degrees(q: &Joints) -> [f64; 6] {
    std::array::from_fn(|k| q[k].to_degrees())
}
