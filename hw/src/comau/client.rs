//! [`C4gArm`]: the Comau C4G behind the PDL2 server, as an [`Arm`].
//!
//! A path is executed as one `MOVE` per waypoint after the first, at the speed override
//! nearest to `speed_fraction` (rounded up, 1–100 %). The joint samples the server streams
//! during each motion, stamped with the controller clock, become the reported [`Motion`]:
//! the controller clock is the rig's time base (the scanner's clock is mapped onto it by its
//! own offset). Joint values cross the wire in degrees as `sign · q + offset`, so a URDF
//! whose zero or sense differs from the controller's can be used unchanged.
//!
//! Every reply is awaited at most `timeout_s`; during a motion, once the server has accepted
//! the `MOVE`, the gap between samples at most `sample_timeout_s` (`timeout_s` unless
//! given). A timeout during a motion sends `STOP` and reports [`RigError::Timeout`]; a lost
//! connection is reported as [`RigError::Disconnected`] (the server stops the arm when its
//! client goes), and the next call reconnects.

use super::line_stream::LineStream;
use super::protocol::{Command, ErrorCode, PROTOCOL_VERSION, Reply, pose_from_xyzaer};
use crate::config_error::{ConfigError, check_address, check_timeout};
use nbv_core::kinematics::Joints;
use nbv_core::math::Pose;
use nbv_core::rig::{Arm, JointPath, Motion, RigError, TimedJoints};
use serde::Deserialize;
use std::net::{TcpStream, ToSocketAddrs};
use std::time::Duration;

const DEVICE: &str = "c4g";

/// How to reach the controller and map its joints.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct C4gConfig {
    /// `host:port` of the PDL2 server.
    pub address: String,
    /// Longest wait for any reply (and between samples during a motion), seconds.
    #[serde(default = "default_timeout")]
    pub timeout_s: f64,
    /// Longest gap between two samples of a motion once its `MOVE` was accepted, seconds
    /// (the server sends one every 20 ms while the arm moves); `timeout_s` if not given.
    #[serde(default)]
    pub sample_timeout_s: Option<f64>,
    /// Connection attempts when the connection is found lost (at least 1).
    #[serde(default = "default_attempts")]
    pub connect_attempts: u32,
    /// Controller joint = sign · model joint + offset: the sign per joint (±1).
    #[serde(default = "default_signs")]
    pub joint_sign: [f64; 6],
    /// … and the offset per joint, degrees.
    #[serde(default)]
    pub joint_offset_deg: [f64; 6],
}

fn default_timeout() -> f64 {
    2.0
}

fn default_attempts() -> u32 {
    3
}

fn default_signs() -> [f64; 6] {
    [1.0; 6]
}

impl C4gConfig {
    /// A configuration with the defaults for `address`.
    pub fn new(address: impl Into<String>) -> Self {
        Self {
            address: address.into(),
            timeout_s: default_timeout(),
            sample_timeout_s: None,
            connect_attempts: default_attempts(),
            joint_sign: default_signs(),
            joint_offset_deg: [0.0; 6],
        }
    }

    fn timeout(&self) -> Duration {
        Duration::from_secs_f64(self.timeout_s.clamp(1e-3, 3600.0))
    }

    fn sample_timeout(&self) -> Duration {
        self.sample_timeout_s.map_or_else(
            || self.timeout(),
            |s| Duration::from_secs_f64(s.clamp(1e-3, 3600.0)),
        )
    }

    fn model_to_controller(&self, q: &Joints) -> [f64; 6] {
        std::array::from_fn(|k| self.joint_sign[k] * q[k].to_degrees() + self.joint_offset_deg[k])
    }

    fn controller_to_model(&self, deg: &[f64; 6]) -> Joints {
        Joints::from_fn(|k, _| {
            ((deg[k] - self.joint_offset_deg[k]) * self.joint_sign[k]).to_radians()
        })
    }

    /// Checks the values a file may get wrong; keys are those of the rig file's `[arm]`.
    pub fn validate(&self) -> Result<(), ConfigError> {
        check_address("address", &self.address)?;
        check_timeout("timeout_s", self.timeout_s)?;
        if let Some(s) = self.sample_timeout_s {
            check_timeout("sample_timeout_s", s)?;
        }
        if self.connect_attempts == 0 {
            return Err(ConfigError::new("connect_attempts", "must be at least 1"));
        }
        if let Some(k) = self.joint_sign.iter().position(|s| s.abs() != 1.0) {
            return Err(ConfigError::new(
                format!("joint_sign[{k}]"),
                "must be 1 or -1",
            ));
        }
        if let Some(k) = self.joint_offset_deg.iter().position(|o| !o.is_finite()) {
            return Err(ConfigError::new(
                format!("joint_offset_deg[{k}]"),
                "must be finite",
            ));
        }
        Ok(())
    }
}

/// The arm, driven through the PDL2 server.
///
/// ```no_run
/// use nbv_core::rig::{Arm, JointPath};
/// use nbv_hw::comau::{C4gArm, C4gConfig};
/// let mut arm = C4gArm::connect(C4gConfig::new("192.168.1.10:12345"))?;
/// let q0 = arm.joints()?;
/// let mut q1 = q0;
/// q1[0] += 0.1;
/// let motion = arm.execute(&JointPath { waypoints: vec![q0, q1], speed_fraction: 0.2 })?;
/// assert!(motion.samples.len() >= 2);
/// # Ok::<(), nbv_core::rig::RigError>(())
/// ```
#[derive(Debug)]
pub struct C4gArm {
    config: C4gConfig,
    link: Option<LineStream>,
    override_pct: Option<u8>,
}

impl C4gArm {
    /// Connects and greets the server (checking its protocol version).
    pub fn connect(config: C4gConfig) -> Result<Self, RigError> {
        config.validate().map_err(|e| RigError::State {
            device: DEVICE.into(),
            detail: format!("configuration: {e}"),
        })?;
        let mut arm = Self {
            config,
            link: None,
            override_pct: None,
        };
        arm.link()?;
        Ok(arm)
    }

    /// The configuration.
    pub fn config(&self) -> &C4gConfig {
        &self.config
    }

    fn open(&self) -> Result<LineStream, RigError> {
        let timeout = self.config.timeout();
        let addrs = self
            .config
            .address
            .to_socket_addrs()
            .map_err(|e| disconnected(format!("address `{}`: {e}", self.config.address)))?;
        let mut last = format!("address `{}` resolves to nothing", self.config.address);
        for addr in addrs {
            match TcpStream::connect_timeout(&addr, timeout) {
                Ok(stream) => {
                    let mut link = LineStream::new(stream, DEVICE);
                    link.send(&Command::Hello.to_string(), timeout)?;
                    let line = link.receive(timeout)?;
                    let reply = Reply::parse(&line).map_err(|e| {
                        protocol(format!(
                            "{addr} does not speak the nbv PDL2 protocol (is hw/pdl2/nbv_server.pdl running there?): {e}"
                        ))
                    })?;
                    let version = match &reply {
                        Reply::Ok(words)
                            if words.first().map(String::as_str) == Some("NBV-C4G") =>
                        {
                            words.get(1).and_then(|v| v.parse::<u32>().ok())
                        }
                        _ => None,
                    };
                    return match version {
                        Some(PROTOCOL_VERSION) => Ok(link),
                        _ => Err(protocol(format!(
                            "greeting answered `{reply}`, expected `OK NBV-C4G {PROTOCOL_VERSION}`"
                        ))),
                    };
                }
                Err(e) => last = format!("connecting to {addr}: {e}"),
            }
        }
        Err(disconnected(last))
    }

    /// The live connection, reconnecting if it was lost.
    fn link(&mut self) -> Result<&mut LineStream, RigError> {
        if self.link.is_none() {
            let mut error = None;
            for attempt in 0..self.config.connect_attempts {
                match self.open() {
                    Ok(link) => {
                        self.link = Some(link);
                        self.override_pct = None;
                        error = None;
                        break;
                    }
                    Err(e) => {
                        tracing::warn!(attempt, "{e}");
                        error = Some(e);
                    }
                }
            }
            if let Some(e) = error {
                return Err(e);
            }
        }
        self.link
            .as_mut()
            .ok_or_else(|| disconnected("not connected"))
    }

    /// Runs `f` on the connection; a transport failure drops it so the next call reconnects.
    fn with_link<T>(
        &mut self,
        f: impl FnOnce(&mut LineStream, Duration) -> Result<T, RigError>,
    ) -> Result<T, RigError> {
        let timeout = self.config.timeout();
        let result = f(self.link()?, timeout);
        if matches!(
            result,
            Err(RigError::Disconnected { .. } | RigError::Protocol { .. })
        ) {
            self.link = None;
        }
        result
    }

    fn request_ok(&mut self, command: Command) -> Result<Vec<String>, RigError> {
        self.with_link(|link, timeout| {
            link.send(&command.to_string(), timeout)?;
            match parse(&link.receive(timeout)?)? {
                Reply::Ok(words) => Ok(words),
                Reply::Err(code, text) => Err(refused(&command, code, &text)),
                other => Err(protocol(format!("`{command}` answered `{other}`"))),
            }
        })
    }

    /// Reads the joints with the controller clock (seconds).
    pub fn timed_joints(&mut self) -> Result<TimedJoints, RigError> {
        let words = self.request_ok(Command::Joints)?;
        let (t, deg) = Reply::clock_and_joints(&words).map_err(|e| protocol(e.to_string()))?;
        Ok(TimedJoints {
            time: t / 1000.0,
            joints: self.config.controller_to_model(&deg),
        })
    }

    /// Reads the flange pose as the controller computes it (its own kinematic model), in
    /// the controller's base frame.
    pub fn reported_pose(&mut self) -> Result<Pose, RigError> {
        let words = self.request_ok(Command::Pose)?;
        let values: Vec<f64> = words
            .iter()
            .skip(1)
            .filter_map(|w| w.parse().ok())
            .collect();
        let v = <[f64; 6]>::try_from(values.as_slice())
            .ok()
            .filter(|v| v.iter().all(|x| x.is_finite()))
            .ok_or_else(|| protocol(format!("`POS` answered `OK {}`", words.join(" "))))?;
        Ok(pose_from_xyzaer(&v))
    }

    /// Cancels any motion in progress.
    pub fn stop(&mut self) -> Result<(), RigError> {
        self.request_ok(Command::Stop).map(|_| ())
    }

    fn set_override(&mut self, speed_fraction: f64) -> Result<(), RigError> {
        let pct = override_percent(speed_fraction);
        if self.override_pct != Some(pct) {
            self.request_ok(Command::Override(pct))?;
            self.override_pct = Some(pct);
        }
        Ok(())
    }

    /// One `MOVE`: its samples are appended to `samples`.
    fn move_to(&mut self, target: &Joints, samples: &mut Vec<TimedJoints>) -> Result<(), RigError> {
        let command = Command::Move(self.config.model_to_controller(target));
        let config = self.config.clone();
        let sample_timeout = config.sample_timeout();
        self.with_link(|link, timeout| {
            link.send(&command.to_string(), timeout)?;
            match parse(&link.receive(timeout)?)? {
                Reply::Ok(_) => {}
                Reply::Err(code, text) => return Err(refused(&command, code, &text)),
                other => return Err(protocol(format!("`MOVE` answered `{other}`"))),
            }
            loop {
                let line = match link.receive(sample_timeout) {
                    Ok(line) => line,
                    Err(e @ RigError::Timeout { .. }) => {
                        // Best effort: the controller must not keep moving unattended.
                        let _ = link.send(&Command::Stop.to_string(), timeout);
                        return Err(e);
                    }
                    Err(RigError::Disconnected { detail, .. }) => {
                        return Err(disconnected(format!(
                            "connection lost during a motion ({detail}); the server stops the arm"
                        )));
                    }
                    Err(e) => return Err(e),
                };
                match parse(&line)? {
                    Reply::Sample(t, deg) => samples.push(TimedJoints {
                        time: t / 1000.0,
                        joints: config.controller_to_model(&deg),
                    }),
                    Reply::Done(t, deg) => {
                        samples.push(TimedJoints {
                            time: t / 1000.0,
                            joints: config.controller_to_model(&deg),
                        });
                        return Ok(());
                    }
                    Reply::Err(code, text) => return Err(refused(&command, code, &text)),
                    Reply::Ok(_) => return Err(protocol("`OK` in the middle of a motion")),
                }
            }
        })
    }
}

impl Drop for C4gArm {
    /// Says goodbye, so the server closes the session at once (best effort).
    fn drop(&mut self) {
        if let Some(link) = self.link.as_mut() {
            let _ = link.send(&Command::Bye.to_string(), Duration::from_millis(200));
        }
    }
}

impl Arm for C4gArm {
    fn joints(&mut self) -> Result<Joints, RigError> {
        Ok(self.timed_joints()?.joints)
    }

    fn execute(&mut self, path: &JointPath) -> Result<Motion, RigError> {
        if path.waypoints.is_empty() {
            return Err(RigError::InvalidPath("no waypoint".into()));
        }
        if !(path.speed_fraction > 0.0 && path.speed_fraction <= 1.0) {
            return Err(RigError::InvalidPath(format!(
                "speed fraction {} is not in (0, 1]",
                path.speed_fraction
            )));
        }
        if let Some(k) = path
            .waypoints
            .iter()
            .position(|q| q.iter().any(|v| !v.is_finite()))
        {
            return Err(RigError::InvalidPath(format!("waypoint {k} is not finite")));
        }
        self.set_override(path.speed_fraction)?;
        let mut samples = vec![self.timed_joints()?];
        for target in &path.waypoints[1..] {
            self.move_to(target, &mut samples)?;
        }
        Ok(Motion { samples })
    }
}

/// The controller's speed override for a path's speed fraction: the whole percent at or
/// above it (never slower than asked, up to float rounding), 1–100.
fn override_percent(speed_fraction: f64) -> u8 {
    (speed_fraction * 100.0 - 1e-9).ceil().clamp(1.0, 100.0) as u8
}

fn parse(line: &str) -> Result<Reply, RigError> {
    Reply::parse(line).map_err(|e| protocol(e.to_string()))
}

fn disconnected(detail: impl Into<String>) -> RigError {
    RigError::Disconnected {
        device: DEVICE.into(),
        detail: detail.into(),
    }
}

fn protocol(detail: impl Into<String>) -> RigError {
    RigError::Protocol {
        device: DEVICE.into(),
        detail: detail.into(),
    }
}

fn refused(command: &Command, code: ErrorCode, text: &str) -> RigError {
    match code {
        ErrorCode::Collision => {
            let mut words = text.split_ascii_whitespace();
            let time = words
                .next()
                .and_then(|t| t.parse::<f64>().ok())
                .unwrap_or(f64::NAN);
            let link = words.next().unwrap_or("unknown link").to_owned();
            RigError::Collision {
                link,
                with: words.collect::<Vec<_>>().join(" "),
                time: time / 1000.0,
            }
        }
        ErrorCode::Limit => RigError::InvalidPath(format!("`{command}`: {text}")),
        _ => RigError::State {
            device: DEVICE.into(),
            detail: format!("`{command}` refused: {} {text}", code.as_str()),
        },
    }
}

#[cfg(test)]
mod tests {
    use super::override_percent;

    #[test]
    fn the_override_is_the_whole_percent_at_or_above_the_fraction() {
        assert_eq!(override_percent(0.2), 20); // 0.2 · 100 = 20.000000000000004
        assert_eq!(override_percent(0.201), 21);
        assert_eq!(override_percent(0.07), 7);
        assert_eq!(override_percent(1.0), 100);
        assert_eq!(override_percent(0.001), 1);
    }
}
