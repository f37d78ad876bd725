//! The line protocol of the PDL2 server (`hw/pdl2/nbv_server.pdl`): one ASCII command per
//! line from the client, one or more reply lines from the controller.
//!
//! | client → controller      | controller → client                                        |
//! |--------------------------|------------------------------------------------------------|
//! | `HELLO`                  | `OK NBV-C4G <version>`                                     |
//! | `OVR <1..100>`           | `OK` (speed override, % of the joints' maximum speeds)     |
//! | `JNT`                    | `OK <t_ms> <j1> … <j6>` (degrees)                          |
//! | `POS`                    | `OK <t_ms> <x> <y> <z> <a> <e> <r>` (mm, ° — Comau ZYZ)    |
//! | `MOVE <j1> … <j6>`       | `OK`, then `S <t_ms> <j1> … <j6>` every sample period while|
//! |                          | the arm moves, then `DONE <t_ms> <j1> … <j6>` or `ERR …`   |
//! | `STOP`                   | cancels a motion (its `MOVE` ends with `ERR STOPPED …`);   |
//! |                          | `OK` when idle                                             |
//! | `BYE`                    | `OK`, and the server closes the connection                 |
//!
//! Errors are `ERR <CODE> <text>` with `CODE` one of `BADCMD`, `BADARG`, `LIMIT`,
//! `STOPPED`, `ALARM`, `COLLISION` (the controller's collision detection stopped the arm;
//! text `<t_ms> <link> <what it hit>`). `t_ms` is the controller's clock (PDL2 `CLOCK`), milliseconds: it is
//! the rig's time base. Lines end with `\n` (a preceding `\r` is ignored) and are at most
//! [`MAX_LINE`] bytes. The server stops the arm when its client's connection is lost.

use nalgebra::{Rotation3, Translation3, UnitQuaternion, Vector3};
use nbv_core::math::Pose;
use std::fmt;

/// Protocol version spoken by this client and by `nbv_server.pdl`.
pub const PROTOCOL_VERSION: u32 = 1;

/// Longest line either side may send, bytes (the terminator excluded).
pub const MAX_LINE: usize = 256;

/// A command from the client.
#[derive(Debug, Clone, PartialEq)]
pub enum Command {
    /// Greeting; the answer carries the protocol version.
    Hello,
    /// Speed override, percent (1–100).
    Override(u8),
    /// Read the joint positions.
    Joints,
    /// Read the flange pose.
    Pose,
    /// Joint move to six angles, degrees.
    Move([f64; 6]),
    /// Cancel the motion in progress.
    Stop,
    /// Close the session.
    Bye,
}

/// Error codes of `ERR` replies.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ErrorCode {
    /// Unknown command.
    BadCommand,
    /// Missing or malformed argument.
    BadArgument,
    /// Target outside the joint strokes.
    Limit,
    /// Motion cancelled (`STOP`, or the controller's hold).
    Stopped,
    /// The controller raised an alarm (drive fault, …).
    Alarm,
    /// Collision detection stopped the arm.
    Collision,
}

/// A reply line from the controller.
#[derive(Debug, Clone, PartialEq)]
pub enum Reply {
    /// `OK` with its words (`NBV-C4G 1`, a clock and joints, …).
    Ok(Vec<String>),
    /// A joint sample during a motion: clock (ms) and joints (degrees).
    Sample(f64, [f64; 6]),
    /// The motion completed: clock (ms) and the final joints (degrees).
    Done(f64, [f64; 6]),
    /// A failure.
    Err(ErrorCode, String),
}

/// A line that is not valid protocol.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("malformed line `{line}`: {reason}")]
pub struct LineError {
    /// The offending line (truncated to [`MAX_LINE`] characters).
    pub line: String,
    /// What is wrong.
    pub reason: String,
}

impl LineError {
    fn new(line: &str, reason: impl Into<String>) -> Self {
        Self {
            line: line.chars().take(MAX_LINE).collect(),
            reason: reason.into(),
        }
    }
}

impl ErrorCode {
    /// The code as it appears on the wire.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::BadCommand => "BADCMD",
            Self::BadArgument => "BADARG",
            Self::Limit => "LIMIT",
            Self::Stopped => "STOPPED",
            Self::Alarm => "ALARM",
            Self::Collision => "COLLISION",
        }
    }

    fn parse(word: &str) -> Option<Self> {
        Some(match word {
            "BADCMD" => Self::BadCommand,
            "BADARG" => Self::BadArgument,
            "LIMIT" => Self::Limit,
            "STOPPED" => Self::Stopped,
            "ALARM" => Self::Alarm,
            "COLLISION" => Self::Collision,
            _ => return None,
        })
    }
}

fn write_angles(f: &mut fmt::Formatter<'_>, angles: &[f64; 6]) -> fmt::Result {
    for a in angles {
        write!(f, " {a:.4}")?;
    }
    Ok(())
}

impl fmt::Display for Command {
    /// The command's line, without its terminator.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Hello => f.write_str("HELLO"),
            Self::Override(p) => write!(f, "OVR {p}"),
            Self::Joints => f.write_str("JNT"),
            Self::Pose => f.write_str("POS"),
            Self::Move(q) => {
                f.write_str("MOVE")?;
                write_angles(f, q)
            }
            Self::Stop => f.write_str("STOP"),
            Self::Bye => f.write_str("BYE"),
        }
    }
}

impl fmt::Display for Reply {
    /// The reply's line, without its terminator.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Ok(words) if words.is_empty() => f.write_str("OK"),
            Self::Ok(words) => write!(f, "OK {}", words.join(" ")),
            Self::Sample(t, q) => {
                write!(f, "S {t:.0}")?;
                write_angles(f, q)
            }
            Self::Done(t, q) => {
                write!(f, "DONE {t:.0}")?;
                write_angles(f, q)
            }
            Self::Err(code, text) => write!(f, "ERR {} {text}", code.as_str()),
        }
    }
}

fn number(line: &str, word: Option<&str>, what: &str) -> Result<f64, LineError> {
    let word = word.ok_or_else(|| LineError::new(line, format!("missing {what}")))?;
    let v: f64 = word
        .parse()
        .map_err(|_| LineError::new(line, format!("{what} `{word}` is not a number")))?;
    if v.is_finite() {
        Ok(v)
    } else {
        Err(LineError::new(
            line,
            format!("{what} `{word}` is not finite"),
        ))
    }
}

fn six<'a>(line: &str, words: &mut impl Iterator<Item = &'a str>) -> Result<[f64; 6], LineError> {
    let mut q = [0.0; 6];
    for (k, v) in q.iter_mut().enumerate() {
        *v = number(line, words.next(), &format!("joint {}", k + 1))?;
    }
    Ok(q)
}

fn end<'a>(line: &str, mut words: impl Iterator<Item = &'a str>) -> Result<(), LineError> {
    match words.next() {
        None => Ok(()),
        Some(w) => Err(LineError::new(line, format!("unexpected `{w}`"))),
    }
}

impl Command {
    /// Parses a command line (the server's side).
    ///
    /// ```
    /// use nbv_hw::comau::protocol::Command;
    /// let c = Command::parse("MOVE 0 10 -90 0 45.5 0")?;
    /// assert_eq!(c, Command::Move([0.0, 10.0, -90.0, 0.0, 45.5, 0.0]));
    /// assert_eq!(Command::parse(&c.to_string())?, c);
    /// assert!(Command::parse("MOVE 0 10").is_err());
    /// # Ok::<(), nbv_hw::comau::protocol::LineError>(())
    /// ```
    pub fn parse(line: &str) -> Result<Self, LineError> {
        let line = line.trim_end_matches('\r');
        let mut words = line.split_ascii_whitespace();
        let cmd = match words.next() {
            Some("HELLO") => Self::Hello,
            Some("OVR") => {
                let p = number(line, words.next(), "override")?;
                if !(1.0..=100.0).contains(&p) || p.fract() != 0.0 {
                    return Err(LineError::new(
                        line,
                        "override must be an integer in 1..=100",
                    ));
                }
                Self::Override(p as u8)
            }
            Some("JNT") => Self::Joints,
            Some("POS") => Self::Pose,
            Some("MOVE") => Self::Move(six(line, &mut words)?),
            Some("STOP") => Self::Stop,
            Some("BYE") => Self::Bye,
            Some(w) => return Err(LineError::new(line, format!("unknown command `{w}`"))),
            None => return Err(LineError::new(line, "empty line")),
        };
        end(line, words)?;
        Ok(cmd)
    }
}

impl Reply {
    /// Parses a reply line (the client's side).
    ///
    /// ```
    /// use nbv_hw::comau::protocol::{ErrorCode, Reply};
    /// assert_eq!(Reply::parse("S 1520 0 1 2 3 4 5")?, Reply::Sample(1520.0, [0.0, 1.0, 2.0, 3.0, 4.0, 5.0]));
    /// assert_eq!(Reply::parse("ERR LIMIT joint 3")?, Reply::Err(ErrorCode::Limit, "joint 3".into()));
    /// assert!(Reply::parse("HELLO").is_err());
    /// # Ok::<(), nbv_hw::comau::protocol::LineError>(())
    /// ```
    pub fn parse(line: &str) -> Result<Self, LineError> {
        let line = line.trim_end_matches('\r');
        let mut words = line.split_ascii_whitespace();
        let reply = match words.next() {
            Some("OK") => return Ok(Self::Ok(words.map(str::to_owned).collect())),
            Some("S") => {
                let t = number(line, words.next(), "clock")?;
                Self::Sample(t, six(line, &mut words)?)
            }
            Some("DONE") => {
                let t = number(line, words.next(), "clock")?;
                Self::Done(t, six(line, &mut words)?)
            }
            Some("ERR") => {
                let word = words.next().unwrap_or("");
                let code = ErrorCode::parse(word)
                    .ok_or_else(|| LineError::new(line, format!("unknown error code `{word}`")))?;
                return Ok(Self::Err(code, words.collect::<Vec<_>>().join(" ")));
            }
            Some(w) => return Err(LineError::new(line, format!("unknown reply `{w}`"))),
            None => return Err(LineError::new(line, "empty line")),
        };
        end(line, words)?;
        Ok(reply)
    }

    /// The clock and joints of an `OK <t_ms> <j1> … <j6>` answer to `JNT`.
    pub fn clock_and_joints(words: &[String]) -> Result<(f64, [f64; 6]), LineError> {
        let line = format!("OK {}", words.join(" "));
        let mut it = words.iter().map(String::as_str);
        let t = number(&line, it.next(), "clock")?;
        let q = six(&line, &mut it)?;
        end(&line, it)?;
        Ok((t, q))
    }
}

/// A pose as the controller writes it: `[x, y, z]` in millimetres and Comau's `[a, e, r]`
/// in degrees, Euler angles about z, then the new y, then the new z (R = Rz(a)·Ry(e)·Rz(r)).
/// At e = 0 or 180° only a ± r is defined: a is reported as 0.
///
/// ```
/// use nbv_hw::comau::protocol::{pose_from_xyzaer, xyzaer_from_pose};
/// let v = [800.0, -50.0, 1170.0, 30.0, 90.0, -45.0];
/// let back = xyzaer_from_pose(&pose_from_xyzaer(&v));
/// assert!(v.iter().zip(&back).all(|(a, b)| (a - b).abs() < 1e-9));
/// ```
pub fn xyzaer_from_pose(pose: &Pose) -> [f64; 6] {
    let t = pose.translation.vector * 1000.0;
    let m = pose.rotation.to_rotation_matrix().into_inner();
    let e = m[(0, 2)].hypot(m[(1, 2)]).atan2(m[(2, 2)]);
    let (a, r) = if e.sin().abs() > 1e-9 {
        (m[(1, 2)].atan2(m[(0, 2)]), m[(2, 1)].atan2(-m[(2, 0)]))
    } else if m[(2, 2)] > 0.0 {
        (0.0, m[(1, 0)].atan2(m[(0, 0)]))
    } else {
        (0.0, m[(1, 0)].atan2(m[(1, 1)]))
    };
    [
        t.x,
        t.y,
        t.z,
        a.to_degrees(),
        e.to_degrees(),
        r.to_degrees(),
    ]
}

/// The pose of `[x, y, z]` mm and Comau `[a, e, r]` degrees (see [`xyzaer_from_pose`]).
pub fn pose_from_xyzaer(v: &[f64; 6]) -> Pose {
    let z = |deg: f64| Rotation3::from_axis_angle(&Vector3::z_axis(), deg.to_radians());
    let y = Rotation3::from_axis_angle(&Vector3::y_axis(), v[4].to_radians());
    let rotation = z(v[3]) * y * z(v[5]);
    Pose::from_parts(
        Translation3::new(v[0] / 1000.0, v[1] / 1000.0, v[2] / 1000.0),
        UnitQuaternion::from_rotation_matrix(&rotation),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn angle() -> impl Strategy<Value = f64> {
        (-2700_0000i64..2700_0000).prop_map(|v| v as f64 / 1e4)
    }

    proptest! {
        #[test]
        fn move_round_trips(q in proptest::array::uniform6(angle())) {
            let c = Command::Move(q);
            prop_assert_eq!(Command::parse(&c.to_string()).unwrap(), c);
        }

        #[test]
        fn sample_round_trips(t in 0u32..u32::MAX, q in proptest::array::uniform6(angle())) {
            let r = Reply::Sample(f64::from(t), q);
            prop_assert_eq!(Reply::parse(&r.to_string()).unwrap(), r);
        }

        #[test]
        fn comau_euler_round_trips(
            a in -3.1f64..3.1, e in -1.5f64..1.5, r in -3.1f64..3.1,
            x in -2.0f64..2.0, y in -2.0f64..2.0, z in 0.0f64..2.0,
        ) {
            let pose = Pose::from_parts(
                Translation3::new(x, y, z),
                UnitQuaternion::from_euler_angles(a, e, r),
            );
            let back = pose_from_xyzaer(&xyzaer_from_pose(&pose));
            prop_assert!((back.translation.vector - pose.translation.vector).norm() < 1e-9);
            prop_assert!(back.rotation.angle_to(&pose.rotation) < 1e-9);
        }

        #[test]
        fn any_text_parses_or_errs(s in "\\PC{0,80}") {
            let _ = Command::parse(&s);
            let _ = Reply::parse(&s);
        }
    }

    /// Comau's a, e, r against rotations worked out by hand (R = Rz(a)·Ry(e)·Rz(r)): the
    /// convention itself, which the round trips cannot catch.
    #[test]
    fn comau_euler_angles_match_hand_computed_rotations() {
        let close = |p: &Pose, x: [f64; 3], z: [f64; 3]| {
            let (px, pz) = (p.rotation * Vector3::x(), p.rotation * Vector3::z());
            (px - Vector3::from(x)).norm() < 1e-12 && (pz - Vector3::from(z)).norm() < 1e-12
        };
        // a = 90°, e = 90°: Rz(90°)·Ry(90°) = [[0, −1, 0], [0, 0, 1], [−1, 0, 0]]: the
        // tool's x points down, its z along world +y.
        let p = pose_from_xyzaer(&[100.0, 200.0, 300.0, 90.0, 90.0, 0.0]);
        assert!(close(&p, [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]), "{p}");
        assert!((p.translation.vector - Vector3::new(0.1, 0.2, 0.3)).norm() < 1e-15);
        // r = 30° alone turns about z: x to (cos 30°, sin 30°, 0).
        let p = pose_from_xyzaer(&[0.0, 0.0, 0.0, 0.0, 0.0, 30.0]);
        let (c, s) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
        assert!(close(&p, [c, s, 0.0], [0.0, 0.0, 1.0]), "{p}");
        // e = 90°, r = 90°: Ry(90°)·Rz(90°) = [[0, 0, 1], [1, 0, 0], [0, 1, 0]].
        let p = pose_from_xyzaer(&[0.0, 0.0, 0.0, 0.0, 90.0, 90.0]);
        assert!(close(&p, [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]), "{p}");
        // And back: the tool pointing down (Ry(180°)) reads a = 0, e = 180°, r = 0.
        let down = Pose::from_parts(
            Translation3::new(0.8, 0.0, 0.5),
            UnitQuaternion::from_axis_angle(&Vector3::y_axis(), std::f64::consts::PI),
        );
        let v = xyzaer_from_pose(&down);
        let want = [800.0, 0.0, 500.0, 0.0, 180.0, 0.0];
        assert!(
            v.iter().zip(&want).all(|(a, b)| (a - b).abs() < 1e-9),
            "{v:?}"
        );
        // x along world +y, z along world +x reads a = 0, e = 90°, r = 90°.
        let v = xyzaer_from_pose(&pose_from_xyzaer(&[0.0, 0.0, 0.0, 0.0, 90.0, 90.0]));
        let want = [0.0, 0.0, 0.0, 0.0, 90.0, 90.0];
        assert!(
            v.iter().zip(&want).all(|(a, b)| (a - b).abs() < 1e-9),
            "{v:?}"
        );
    }

    #[test]
    fn errors_name_the_problem() {
        let e = Command::parse("OVR 150").unwrap_err();
        assert!(e.reason.contains("1..=100"), "{e}");
        let e = Reply::parse("DONE 10 1 2 3 4 5 nan").unwrap_err();
        assert!(e.reason.contains("joint 6"), "{e}");
        assert_eq!(
            Reply::parse("ERR STOPPED by client").unwrap(),
            Reply::Err(ErrorCode::Stopped, "by client".into())
        );
        assert!(Reply::parse("ERR WHAT x").is_err());
        assert!(Command::parse("JNT 1").is_err());
    }
}
