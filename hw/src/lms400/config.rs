//! [`Lms400Config`]: where the scanner is and how the driver talks to it (deserialisable,
//! every field defaulted to the paper's rig).

use nbv_core::rig::LineScannerSpec;
use serde::{Deserialize, Deserializer};
use std::time::Duration;

/// Driver settings of an LMS400.
///
/// ```
/// let config: nbv_hw::lms400::Lms400Config =
///     toml::from_str("address = \"10.0.0.2:2111\"\ntimeout_s = 0.5").unwrap();
/// assert_eq!(config.timeout.as_millis(), 500);
/// assert_eq!(config.spec.line_rate_hz, 190.0);
/// ```
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Lms400Config {
    /// `host:port` of the scanner. Default `192.168.0.1:2111` (factory setting).
    pub address: String,
    /// What to configure the scanner for. Default: the paper's 70° fan at 0.25°, 190 Hz,
    /// 0.7–3.0 m, frame `lms400`.
    #[serde(with = "SpecDef")]
    pub spec: LineScannerSpec,
    /// Longest wait for any answer or read. Default 2 s. (TOML key `timeout_s`, seconds.)
    #[serde(rename = "timeout_s", deserialize_with = "seconds")]
    pub timeout: Duration,
    /// Added to the device timestamp (seconds) to put lines on the rig clock. Default 0.
    pub clock_offset_s: f64,
    /// Connection attempts when the link is down. Default 3.
    pub reconnect_attempts: u32,
}

impl Default for Lms400Config {
    fn default() -> Self {
        Self {
            address: "192.168.0.1:2111".into(),
            spec: LineScannerSpec::lms400(),
            timeout: Duration::from_secs(2),
            clock_offset_s: 0.0,
            reconnect_attempts: 3,
        }
    }
}

/// Serde mirror of [`LineScannerSpec`] (angles in radians, as the spec has them).
#[derive(Deserialize)]
#[serde(remote = "LineScannerSpec", deny_unknown_fields)]
struct SpecDef {
    frame: String,
    range: [f64; 2],
    fov: f64,
    resolution: f64,
    line_rate_hz: f64,
}

fn seconds<'de, D: Deserializer<'de>>(deserializer: D) -> Result<Duration, D::Error> {
    let seconds = f64::deserialize(deserializer)?;
    Duration::try_from_secs_f64(seconds).map_err(serde::de::Error::custom)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_full_table_overrides_every_default() {
        let config: Lms400Config = toml::from_str(
            r#"
            address = "127.0.0.1:1"
            timeout_s = 0.25
            clock_offset_s = -3.5
            reconnect_attempts = 0
            [spec]
            frame = "laser"
            range = [0.5, 2.0]
            fov = 1.0
            resolution = 0.01
            line_rate_hz = 300.0
            "#,
        )
        .unwrap();
        assert_eq!(config.address, "127.0.0.1:1");
        assert_eq!(config.timeout, Duration::from_millis(250));
        assert_eq!(config.clock_offset_s, -3.5);
        assert_eq!(config.reconnect_attempts, 0);
        assert_eq!(config.spec.frame, "laser");
        assert_eq!(config.spec.line_rate_hz, 300.0);
    }

    #[test]
    fn negative_timeouts_and_unknown_keys_are_rejected() {
        assert!(toml::from_str::<Lms400Config>("timeout_s = -1.0").is_err());
        assert!(toml::from_str::<Lms400Config>("port = 2111").is_err());
    }
}
