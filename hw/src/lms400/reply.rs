//! [`Reply`]: the device's text replies (`sMA`, `sAN`, `sWA`, `sFA`) and the error codes
//! `sFA` carries ([`SopasError`]).
//!
//! Replies the driver expects (and the emulator sends, byte for byte):
//!
//! | command              | reply                                                |
//! |----------------------|------------------------------------------------------|
//! | `SetAccessMode`      | `sAN SetAccessMode 1` (0: wrong password)            |
//! | `mSCsetscanconfig`   | `sAN mSCsetscanconfig <status> <freq hex> <res hex>` |
//! | `FLsel`, `FLrang`, `FLmean` | `sWA <name>`                                  |
//! | `mLRreqdata`         | `sMA mLRreqdata` (the stream follows)                |
//! | `mLRstopdata`        | telegrams still in flight, then `sAN mLRstopdata 0`  |
//! | `Run`                | `sAN Run 1`                                          |
//! | anything refused     | `sFA <code hex>`                                     |

use std::fmt;
use thiserror::Error;

/// An error code of an `sFA` reply (the subset of SICK's SOPAS error table the driver
/// names; any other code is kept as is).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SopasError(pub u16);

impl SopasError {
    /// Method call refused at the current access level.
    pub const METHOD_ACCESS_DENIED: Self = Self(0x1);
    /// Unknown method.
    pub const UNKNOWN_METHOD: Self = Self(0x2);
    /// Unknown variable.
    pub const UNKNOWN_VARIABLE: Self = Self(0x3);
    /// The device's state does not allow the call.
    pub const LOCAL_CONDITION_FAILED: Self = Self(0x4);
    /// Arguments out of range or malformed.
    pub const INVALID_DATA: Self = Self(0x5);
    /// Variable write refused at the current access level.
    pub const WRITE_ACCESS_DENIED: Self = Self(0xA);
    /// Unknown command type.
    pub const UNKNOWN_COMMAND: Self = Self(0xC);

    /// What the code means.
    pub fn meaning(self) -> &'static str {
        match self {
            Self::METHOD_ACCESS_DENIED => "method access denied (login required)",
            Self::UNKNOWN_METHOD => "unknown method",
            Self::UNKNOWN_VARIABLE => "unknown variable",
            Self::LOCAL_CONDITION_FAILED => "local condition failed",
            Self::INVALID_DATA => "invalid data",
            Self::WRITE_ACCESS_DENIED => "variable write access denied (login required)",
            Self::UNKNOWN_COMMAND => "unknown command",
            _ => "unknown error code",
        }
    }
}

impl fmt::Display for SopasError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "sFA {:X} ({})", self.0, self.meaning())
    }
}

/// A text reply from the device.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Reply {
    /// `sMA <method>`: the method was accepted (its answer may follow).
    MethodAck {
        /// Method name.
        name: String,
    },
    /// `sAN <method> <args…>`: the method's answer.
    MethodAnswer {
        /// Method name.
        name: String,
        /// Answer arguments (status codes, values).
        args: Vec<String>,
    },
    /// `sWA <variable>`: a variable was written.
    WriteAck {
        /// Variable name.
        name: String,
    },
    /// `sFA <code>`: the command was refused.
    Error(SopasError),
}

/// Why a payload is not a reply.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum ReplyError {
    /// Not ASCII text.
    #[error("reply is not ASCII text")]
    NotText,
    /// Text that is not one of the known replies.
    #[error("unexpected reply `{0}`")]
    Unexpected(String),
}

impl Reply {
    /// Shorthand for an `sAN` reply.
    pub fn answer(name: &str, args: &[&str]) -> Self {
        Self::MethodAnswer {
            name: name.to_owned(),
            args: args.iter().map(|a| (*a).to_owned()).collect(),
        }
    }

    /// The payload to frame.
    ///
    /// ```
    /// use nbv_hw::lms400::{Reply, SopasError};
    /// assert_eq!(Reply::answer("SetAccessMode", &["1"]).to_payload(), b"sAN SetAccessMode 1");
    /// assert_eq!(Reply::parse(b"sFA A"), Ok(Reply::Error(SopasError::WRITE_ACCESS_DENIED)));
    /// ```
    pub fn to_payload(&self) -> Vec<u8> {
        let text = match self {
            Self::MethodAck { name } => format!("sMA {name}"),
            Self::MethodAnswer { name, args } if args.is_empty() => format!("sAN {name}"),
            Self::MethodAnswer { name, args } => format!("sAN {name} {}", args.join(" ")),
            Self::WriteAck { name } => format!("sWA {name}"),
            Self::Error(code) => format!("sFA {:X}", code.0),
        };
        text.into_bytes()
    }

    /// Parses a reply payload.
    pub fn parse(payload: &[u8]) -> Result<Self, ReplyError> {
        let text = std::str::from_utf8(payload)
            .ok()
            .filter(|t| t.is_ascii())
            .ok_or(ReplyError::NotText)?;
        let unexpected = || ReplyError::Unexpected(text.chars().take(80).collect());
        let mut words = text.split(' ');
        let kind = words.next().unwrap_or_default();
        let name = words
            .next()
            .filter(|n| !n.is_empty())
            .ok_or_else(unexpected)?
            .to_owned();
        let args: Vec<String> = words.map(str::to_owned).collect();
        match (kind, args.is_empty()) {
            ("sMA", true) => Ok(Self::MethodAck { name }),
            ("sAN", _) => Ok(Self::MethodAnswer { name, args }),
            ("sWA", true) => Ok(Self::WriteAck { name }),
            ("sFA", true) => u16::from_str_radix(&name, 16)
                .map(|code| Self::Error(SopasError(code)))
                .map_err(|_| unexpected()),
            _ => Err(unexpected()),
        }
    }
}

impl fmt::Display for Reply {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&String::from_utf8_lossy(&self.to_payload()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn replies_round_trip() {
        for reply in [
            Reply::MethodAck {
                name: "mLRreqdata".into(),
            },
            Reply::answer("mSCsetscanconfig", &["0", "8CA0", "9C4"]),
            Reply::answer("mLRstopdata", &["0"]),
            Reply::WriteAck {
                name: "FLrang".into(),
            },
            Reply::Error(SopasError::METHOD_ACCESS_DENIED),
            Reply::Error(SopasError(0x1F)),
        ] {
            assert_eq!(Reply::parse(&reply.to_payload()), Ok(reply));
        }
    }

    #[test]
    fn malformed_replies_are_typed_errors() {
        for bad in [
            &b"sSN LMDscandata"[..],
            b"sMA",
            b"sFA xyz",
            b"sWA FLsel 1",
            b"",
        ] {
            assert!(
                matches!(Reply::parse(bad), Err(ReplyError::Unexpected(_))),
                "{bad:?}"
            );
        }
        assert_eq!(Reply::parse(&[0xC3, 0x28]), Err(ReplyError::NotText));
    }

    #[test]
    fn error_codes_are_named() {
        assert_eq!(
            Reply::Error(SopasError::METHOD_ACCESS_DENIED).to_string(),
            "sFA 1"
        );
        assert!(SopasError(0xA).to_string().contains("write access denied"));
    }
}
