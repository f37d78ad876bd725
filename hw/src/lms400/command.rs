//! [`Command`]: the text commands the driver sends the LMS400 (login, scan configuration,
//! filters, streaming), with their exact wire text.

use super::scan_config::ScanConfig;
use std::fmt;
use thiserror::Error;

/// Access level of the login the driver uses ("service").
pub const SERVICE_LEVEL: u8 = 4;

/// Password hash of [`SERVICE_LEVEL`].
pub const SERVICE_PASSWORD: u32 = 0x81BE_23AA;

/// `FLsel` bit of the median filter.
pub const FILTER_MEDIAN: u8 = 1;
/// `FLsel` bit of the edge filter.
pub const FILTER_EDGE: u8 = 2;
/// `FLsel` bit of the range filter (limits set with `FLrang`).
pub const FILTER_RANGE: u8 = 4;
/// `FLsel` bit of the mean filter.
pub const FILTER_MEAN: u8 = 8;

/// What `mLRreqdata` asks the device to stream.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DataMode {
    /// Distance and remission (`20`).
    DistanceRemission,
    /// Distance only (`21`).
    Distance,
    /// Remission only (`22`).
    Remission,
}

impl DataMode {
    /// The mode's number on the wire.
    pub fn code(self) -> u16 {
        match self {
            Self::DistanceRemission => 20,
            Self::Distance => 21,
            Self::Remission => 22,
        }
    }

    fn from_code(code: &str) -> Option<Self> {
        match code {
            "20" => Some(Self::DistanceRemission),
            "21" => Some(Self::Distance),
            "22" => Some(Self::Remission),
            _ => None,
        }
    }
}

/// A command to the device.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Command {
    /// `sMN SetAccessMode <level> <password hash, 8 hex digits>`.
    SetAccessMode {
        /// Access level (4 = service).
        level: u8,
        /// Password hash.
        password: u32,
    },
    /// `sMN mSCsetscanconfig +<freq> +<res> +<start> +<span>`.
    SetScanConfig(ScanConfig),
    /// `sWN FLsel <mask>`: which filters run (bits `FILTER_*`).
    SelectFilters {
        /// Filter bit mask.
        mask: u8,
    },
    /// `sWN FLrang <min mm> <max mm>`: range filter limits.
    SetRangeFilter {
        /// Shortest distance kept, millimetres.
        min_mm: u16,
        /// Longest distance kept, millimetres.
        max_mm: u16,
    },
    /// `sWN FLmean 0 <n>`: mean filter over `n` scans.
    SetMeanFilter {
        /// Scans averaged.
        scans: u16,
    },
    /// `sMN mLRreqdata <mode>`: start streaming.
    RequestData(DataMode),
    /// `sMN mLRstopdata`: stop streaming.
    StopData,
    /// `sMN Run`: apply parameters and return to user level.
    Run,
}

/// Why a payload is not a command the device knows.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum CommandError {
    /// Not ASCII text.
    #[error("command is not ASCII text")]
    NotText,
    /// The command type (first word) is not one the device handles (`sMN`, `sWN`).
    #[error("unknown command type `{0}`")]
    UnknownType(String),
    /// `sMN` with an unknown method name.
    #[error("unknown method `{0}`")]
    UnknownMethod(String),
    /// `sWN` with an unknown variable name.
    #[error("unknown variable `{0}`")]
    UnknownVariable(String),
    /// Known command, wrong arguments.
    #[error("bad arguments for `{name}`: {detail}")]
    BadArguments {
        /// Command name.
        name: &'static str,
        /// What was wrong.
        detail: String,
    },
}

impl Command {
    /// The command's name as replies echo it (e.g. `mLRreqdata`).
    pub fn name(&self) -> &'static str {
        match self {
            Self::SetAccessMode { .. } => "SetAccessMode",
            Self::SetScanConfig(_) => "mSCsetscanconfig",
            Self::SelectFilters { .. } => "FLsel",
            Self::SetRangeFilter { .. } => "FLrang",
            Self::SetMeanFilter { .. } => "FLmean",
            Self::RequestData(_) => "mLRreqdata",
            Self::StopData => "mLRstopdata",
            Self::Run => "Run",
        }
    }

    /// Whether the command writes a variable (`sWN`, answered by `sWA`) rather than
    /// calling a method (`sMN`, answered by `sMA`/`sAN`).
    pub fn is_write(&self) -> bool {
        matches!(
            self,
            Self::SelectFilters { .. } | Self::SetRangeFilter { .. } | Self::SetMeanFilter { .. }
        )
    }

    /// The payload to frame.
    ///
    /// ```
    /// use nbv_hw::lms400::{Command, SERVICE_LEVEL, SERVICE_PASSWORD};
    /// let login = Command::SetAccessMode { level: SERVICE_LEVEL, password: SERVICE_PASSWORD };
    /// assert_eq!(login.to_payload(), b"sMN SetAccessMode 4 81BE23AA");
    /// assert_eq!(Command::parse(&login.to_payload()), Ok(login));
    /// ```
    pub fn to_payload(&self) -> Vec<u8> {
        self.to_string().into_bytes()
    }

    /// Parses a command payload (what the emulator receives).
    pub fn parse(payload: &[u8]) -> Result<Self, CommandError> {
        let text = std::str::from_utf8(payload)
            .ok()
            .filter(|t| t.is_ascii())
            .ok_or(CommandError::NotText)?;
        let mut words = text.split(' ');
        let kind = words.next().unwrap_or_default();
        let name = words.next().unwrap_or_default();
        let args: Vec<&str> = words.collect();
        match kind {
            "sMN" => Self::parse_method(name, &args),
            "sWN" => Self::parse_write(name, &args),
            other => Err(CommandError::UnknownType(other.to_owned())),
        }
    }

    fn parse_method(name: &str, args: &[&str]) -> Result<Self, CommandError> {
        match name {
            "SetAccessMode" => {
                let bad = |detail: &str| CommandError::BadArguments {
                    name: "SetAccessMode",
                    detail: detail.to_owned(),
                };
                let [level, password] = args else {
                    return Err(bad("expected <level> <password>"));
                };
                Ok(Self::SetAccessMode {
                    level: level.parse().map_err(|_| bad("bad level"))?,
                    password: u32::from_str_radix(password, 16)
                        .map_err(|_| bad("bad password hash"))?,
                })
            }
            "mSCsetscanconfig" => ScanConfig::parse_args(args)
                .map(Self::SetScanConfig)
                .map_err(|e| CommandError::BadArguments {
                    name: "mSCsetscanconfig",
                    detail: e.to_string(),
                }),
            "mLRreqdata" => match args {
                [mode] => DataMode::from_code(mode).map(Self::RequestData),
                _ => None,
            }
            .ok_or_else(|| CommandError::BadArguments {
                name: "mLRreqdata",
                detail: format!("mode {args:?} is not 20, 21 or 22"),
            }),
            "mLRstopdata" => no_arguments(Self::StopData, args),
            "Run" => no_arguments(Self::Run, args),
            other => Err(CommandError::UnknownMethod(other.to_owned())),
        }
    }

    fn parse_write(name: &str, args: &[&str]) -> Result<Self, CommandError> {
        let parsed = match (name, args) {
            ("FLsel", [mask]) => mask.parse().ok().map(|mask| Self::SelectFilters { mask }),
            ("FLrang", [min, max]) => min
                .parse()
                .ok()
                .zip(max.parse().ok())
                .map(|(min_mm, max_mm)| Self::SetRangeFilter { min_mm, max_mm }),
            ("FLmean", ["0", scans]) => scans
                .parse()
                .ok()
                .map(|scans| Self::SetMeanFilter { scans }),
            ("FLsel" | "FLrang" | "FLmean", _) => None,
            (other, _) => return Err(CommandError::UnknownVariable(other.to_owned())),
        };
        parsed.ok_or_else(|| CommandError::BadArguments {
            name: match name {
                "FLsel" => "FLsel",
                "FLrang" => "FLrang",
                _ => "FLmean",
            },
            detail: format!("arguments {args:?}"),
        })
    }
}

fn no_arguments(command: Command, args: &[&str]) -> Result<Command, CommandError> {
    if args.is_empty() {
        Ok(command)
    } else {
        Err(CommandError::BadArguments {
            name: command.name(),
            detail: "takes no arguments".into(),
        })
    }
}

impl fmt::Display for Command {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let kind = if self.is_write() { "sWN" } else { "sMN" };
        write!(f, "{kind} {}", self.name())?;
        match self {
            Self::SetAccessMode { level, password } => write!(f, " {level} {password:08X}"),
            Self::SetScanConfig(config) => write!(f, " {}", config.to_args()),
            Self::SelectFilters { mask } => write!(f, " {mask}"),
            Self::SetRangeFilter { min_mm, max_mm } => write!(f, " {min_mm} {max_mm}"),
            Self::SetMeanFilter { scans } => write!(f, " 0 {scans}"),
            Self::RequestData(mode) => write!(f, " {}", mode.code()),
            Self::StopData | Self::Run => Ok(()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn all_commands() -> Vec<Command> {
        vec![
            Command::SetAccessMode {
                level: SERVICE_LEVEL,
                password: SERVICE_PASSWORD,
            },
            Command::SetScanConfig(ScanConfig {
                frequency: 36_000,
                resolution: 2_500,
                start_angle: 550_000,
                span: 700_000,
            }),
            Command::SelectFilters { mask: FILTER_RANGE },
            Command::SetRangeFilter {
                min_mm: 700,
                max_mm: 3000,
            },
            Command::SetMeanFilter { scans: 4 },
            Command::RequestData(DataMode::DistanceRemission),
            Command::StopData,
            Command::Run,
        ]
    }

    #[test]
    fn wire_text_is_the_documented_one() {
        let texts: Vec<String> = all_commands().iter().map(Command::to_string).collect();
        assert_eq!(
            texts,
            [
                "sMN SetAccessMode 4 81BE23AA",
                "sMN mSCsetscanconfig +360.00 +0.25 +55.00 +70.00",
                "sWN FLsel 4",
                "sWN FLrang 700 3000",
                "sWN FLmean 0 4",
                "sMN mLRreqdata 20",
                "sMN mLRstopdata",
                "sMN Run",
            ]
        );
    }

    #[test]
    fn every_command_parses_back() {
        for command in all_commands() {
            assert_eq!(Command::parse(&command.to_payload()), Ok(command));
        }
    }

    #[test]
    fn unknown_or_malformed_commands_are_typed_errors() {
        assert_eq!(
            Command::parse(b"sRN LMDscandata"),
            Err(CommandError::UnknownType("sRN".into()))
        );
        assert_eq!(
            Command::parse(b"sMN mLMPsetscancfg"),
            Err(CommandError::UnknownMethod("mLMPsetscancfg".into()))
        );
        assert_eq!(
            Command::parse(b"sWN FLfoo 1"),
            Err(CommandError::UnknownVariable("FLfoo".into()))
        );
        assert!(matches!(
            Command::parse(b"sMN mLRreqdata 23"),
            Err(CommandError::BadArguments { .. })
        ));
        assert!(matches!(
            Command::parse(b"sWN FLrang 700"),
            Err(CommandError::BadArguments { name: "FLrang", .. })
        ));
        assert_eq!(Command::parse(&[0xFF, 0x00]), Err(CommandError::NotText));
    }
}
