//! [`ScanConfig`]: the `mSCsetscanconfig` parameters (frequency, resolution, start angle,
//! span), the device's answer to it, and the angle convention between the device and
//! [`LineScannerSpec`].
//!
//! Angle convention: the LMS400 numbers its beams by device angle, 55°–125°, with 90° its
//! optical axis. The rig's sensor frame has the fan centred on +z with angles measured from
//! +z towards +x ([`LineScannerSpec::beam_direction`]). The mapping is
//! `spec angle = device angle − 90°` (in radians): device 90° is the sensor frame's +z and
//! device angles grow towards the sensor frame's +x. The URDF frame of the scanner must be
//! mounted accordingly. A spec with field of view `fov` is therefore configured with start
//! angle `90° − fov/2` and span `fov`.

use nbv_core::rig::LineScannerSpec;
use thiserror::Error;

/// Device angle of the optical axis (the sensor frame's +z), degrees.
pub const DEVICE_CENTRE_DEG: f64 = 90.0;

/// Device angles the LMS400 can scan, degrees.
pub const DEVICE_ANGLE_RANGE_DEG: [f64; 2] = [55.0, 125.0];

/// Converts a device angle (degrees) to the spec's convention (radians from +z).
///
/// ```
/// use nbv_hw::lms400::device_to_spec_angle;
/// assert!((device_to_spec_angle(55.0) + 35f64.to_radians()).abs() < 1e-12);
/// ```
pub fn device_to_spec_angle(device_deg: f64) -> f64 {
    (device_deg - DEVICE_CENTRE_DEG).to_radians()
}

/// Converts an angle of the spec's convention (radians from +z) to a device angle (degrees).
pub fn spec_to_device_angle(spec_rad: f64) -> f64 {
    spec_rad.to_degrees() + DEVICE_CENTRE_DEG
}

/// Scan parameters in the device's fixed-point units.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ScanConfig {
    /// Scan frequency, 1/100 Hz.
    pub frequency: u32,
    /// Angular resolution, 1/10000°.
    pub resolution: u32,
    /// Device start angle, 1/10000°.
    pub start_angle: i32,
    /// Angular span, 1/10000°.
    pub span: u32,
}

/// A value that cannot be put into a scan configuration.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum ScanConfigError {
    /// A quantity is NaN, infinite, not positive or too large for the device's units.
    #[error("{what} = {value} cannot be configured")]
    Unrepresentable {
        /// Which quantity.
        what: &'static str,
        /// Its value.
        value: f64,
    },
    /// The `mSCsetscanconfig` arguments are malformed.
    #[error("malformed scan configuration: {0}")]
    Malformed(String),
}

impl ScanConfig {
    /// The configuration that realises `spec`: frequency `line_rate_hz`, resolution
    /// `resolution`, span `fov`, fan centred on the optical axis. Whether the device
    /// accepts it is the device's call (see [`ScanConfigAnswer`]).
    ///
    /// ```
    /// use nbv_core::rig::LineScannerSpec;
    /// use nbv_hw::lms400::ScanConfig;
    /// let spec = LineScannerSpec::lms400();
    /// let config = ScanConfig::from_spec(&spec).unwrap();
    /// assert_eq!(config.to_args(), "+190.00 +0.25 +55.00 +70.00");
    /// ```
    pub fn from_spec(spec: &LineScannerSpec) -> Result<Self, ScanConfigError> {
        let span_deg = spec.fov.to_degrees();
        Ok(Self {
            frequency: to_fixed_unsigned("line rate (Hz)", spec.line_rate_hz, 100.0)?,
            resolution: to_fixed_unsigned("resolution (°)", spec.resolution.to_degrees(), 1e4)?,
            start_angle: i32::try_from(to_fixed_unsigned(
                "start angle (°)",
                DEVICE_CENTRE_DEG - 0.5 * span_deg,
                1e4,
            )?)
            .map_err(|_| ScanConfigError::Unrepresentable {
                what: "start angle (°)",
                value: DEVICE_CENTRE_DEG - 0.5 * span_deg,
            })?,
            span: to_fixed_unsigned("field of view (°)", span_deg, 1e4)?,
        })
    }

    /// Frequency in Hz.
    pub fn frequency_hz(&self) -> f64 {
        f64::from(self.frequency) * 1e-2
    }

    /// Resolution in degrees.
    pub fn resolution_deg(&self) -> f64 {
        f64::from(self.resolution) * 1e-4
    }

    /// Start angle in degrees.
    pub fn start_angle_deg(&self) -> f64 {
        f64::from(self.start_angle) * 1e-4
    }

    /// Span in degrees.
    pub fn span_deg(&self) -> f64 {
        f64::from(self.span) * 1e-4
    }

    /// The command arguments, e.g. `+360.00 +0.25 +55.00 +70.00`.
    pub fn to_args(&self) -> String {
        format!(
            "{} {} {} {}",
            format_fixed(i64::from(self.frequency), 2),
            format_fixed(i64::from(self.resolution), 4),
            format_fixed(i64::from(self.start_angle), 4),
            format_fixed(i64::from(self.span), 4),
        )
    }

    /// Parses the four command arguments.
    pub fn parse_args(args: &[&str]) -> Result<Self, ScanConfigError> {
        let [frequency, resolution, start, span] = args else {
            return Err(ScanConfigError::Malformed(format!(
                "{} arguments instead of 4",
                args.len()
            )));
        };
        let start_deg = parse_decimal(start)?;
        Ok(Self {
            frequency: to_fixed_unsigned("frequency (Hz)", parse_decimal(frequency)?, 100.0)?,
            resolution: to_fixed_unsigned("resolution (°)", parse_decimal(resolution)?, 1e4)?,
            start_angle: to_fixed_signed("start angle (°)", start_deg, 1e4)?,
            span: to_fixed_unsigned("span (°)", parse_decimal(span)?, 1e4)?,
        })
    }
}

/// The device's answer to `mSCsetscanconfig`: a status code and the applied frequency
/// (1/100 Hz) and resolution (1/10000°), both sent in hexadecimal.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ScanConfigAnswer {
    /// 0 = applied; see [`ScanConfigAnswer::status_text`].
    pub status: u8,
    /// Applied frequency, 1/100 Hz.
    pub frequency: u32,
    /// Applied resolution, 1/10000°.
    pub resolution: u32,
}

impl ScanConfigAnswer {
    /// Status: configuration applied.
    pub const OK: u8 = 0;
    /// Status: frequency not supported.
    pub const BAD_FREQUENCY: u8 = 1;
    /// Status: resolution not supported.
    pub const BAD_RESOLUTION: u8 = 2;
    /// Status: neither frequency nor resolution supported.
    pub const BAD_FREQUENCY_AND_RESOLUTION: u8 = 3;
    /// Status: start angle or span outside the scan area.
    pub const BAD_SCAN_AREA: u8 = 4;

    /// What the status code means.
    pub fn status_text(&self) -> &'static str {
        match self.status {
            Self::OK => "applied",
            Self::BAD_FREQUENCY => "scan frequency not supported",
            Self::BAD_RESOLUTION => "angular resolution not supported",
            Self::BAD_FREQUENCY_AND_RESOLUTION => "frequency and resolution not supported",
            Self::BAD_SCAN_AREA => "start angle or span outside the scan area",
            _ => "unknown status",
        }
    }

    /// The answer's arguments, e.g. `0 4A38 9C4`.
    ///
    /// ```
    /// use nbv_hw::lms400::ScanConfigAnswer;
    /// let answer = ScanConfigAnswer { status: 0, frequency: 19_000, resolution: 2_500 };
    /// assert_eq!(answer.to_args(), "0 4A38 9C4");
    /// assert_eq!(ScanConfigAnswer::parse_args(&["0", "4A38", "9C4"]), Ok(answer));
    /// ```
    pub fn to_args(&self) -> String {
        format!(
            "{:X} {:X} {:X}",
            self.status, self.frequency, self.resolution
        )
    }

    /// Parses the answer's arguments.
    pub fn parse_args(args: &[&str]) -> Result<Self, ScanConfigError> {
        let [status, frequency, resolution] = args else {
            return Err(ScanConfigError::Malformed(format!(
                "{} answer arguments instead of 3",
                args.len()
            )));
        };
        let hex = |s: &str| {
            u32::from_str_radix(s, 16)
                .map_err(|_| ScanConfigError::Malformed(format!("`{s}` is not hexadecimal")))
        };
        Ok(Self {
            status: u8::from_str_radix(status, 16)
                .map_err(|_| ScanConfigError::Malformed(format!("bad status `{status}`")))?,
            frequency: hex(frequency)?,
            resolution: hex(resolution)?,
        })
    }
}

fn to_fixed_unsigned(what: &'static str, value: f64, scale: f64) -> Result<u32, ScanConfigError> {
    let fixed = (value * scale).round();
    if value.is_finite() && fixed > 0.0 && fixed <= f64::from(u32::MAX) {
        Ok(fixed as u32)
    } else {
        Err(ScanConfigError::Unrepresentable { what, value })
    }
}

fn to_fixed_signed(what: &'static str, value: f64, scale: f64) -> Result<i32, ScanConfigError> {
    let fixed = (value * scale).round();
    if value.is_finite() && fixed >= f64::from(i32::MIN) && fixed <= f64::from(i32::MAX) {
        Ok(fixed as i32)
    } else {
        Err(ScanConfigError::Unrepresentable { what, value })
    }
}

/// `+12.5` style decimal (sign optional).
fn parse_decimal(text: &str) -> Result<f64, ScanConfigError> {
    let digits = text.strip_prefix('+').unwrap_or(text);
    let well_formed = !digits.is_empty()
        && digits
            .trim_start_matches('-')
            .chars()
            .all(|c| c.is_ascii_digit() || c == '.');
    digits
        .parse::<f64>()
        .ok()
        .filter(|v| well_formed && v.is_finite())
        .ok_or_else(|| ScanConfigError::Malformed(format!("`{text}` is not a decimal number")))
}

/// Fixed-point `value / 10^decimals` with a sign, at least two decimals and no trailing
/// zeros beyond them: 2500 (4 decimals) → `+0.25`, 1667 → `+0.1667`, 19000 (2) → `+190.00`.
fn format_fixed(value: i64, decimals: u32) -> String {
    let scale = 10i64.pow(decimals);
    let sign = if value < 0 { '-' } else { '+' };
    let magnitude = value.unsigned_abs();
    let scale = scale.unsigned_abs();
    let mut fraction = format!("{:0width$}", magnitude % scale, width = decimals as usize);
    while fraction.len() > 2 && fraction.ends_with('0') {
        fraction.pop();
    }
    format!("{sign}{}.{fraction}", magnitude / scale)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn fixed_point_formatting() {
        assert_eq!(format_fixed(2500, 4), "+0.25");
        assert_eq!(format_fixed(1667, 4), "+0.1667");
        assert_eq!(format_fixed(19_000, 2), "+190.00");
        assert_eq!(format_fixed(-5, 4), "-0.0005");
    }

    #[test]
    fn malformed_arguments_are_rejected() {
        for args in [
            vec!["+190", "+0.25", "+55"],
            vec!["+190", "+0.25", "+55", "x"],
            vec!["+NaN", "+0.25", "+55", "+70"],
            vec!["+inf", "+0.25", "+55", "+70"],
            vec!["+190", "-0.25", "+55", "+70"],
        ] {
            assert!(ScanConfig::parse_args(&args).is_err(), "{args:?}");
        }
    }

    #[test]
    fn non_finite_specs_are_unrepresentable() {
        let spec = LineScannerSpec {
            frame: "lms400".into(),
            range: [0.7, 3.0],
            fov: f64::NAN,
            resolution: 0.01,
            line_rate_hz: 190.0,
        };
        assert!(matches!(
            ScanConfig::from_spec(&spec),
            Err(ScanConfigError::Unrepresentable { .. })
        ));
    }

    proptest! {
        #[test]
        fn args_round_trip(
            frequency in 1u32..100_000,
            resolution in 1u32..100_000,
            start_angle in -1_000_000i32..2_000_000,
            span in 1u32..2_000_000,
        ) {
            let config = ScanConfig { frequency, resolution, start_angle, span };
            let text = config.to_args();
            let args: Vec<&str> = text.split(' ').collect();
            prop_assert_eq!(ScanConfig::parse_args(&args), Ok(config));
        }

        #[test]
        fn spec_fan_is_centred_on_the_optical_axis(fov_deg in 1.0f64..70.0) {
            let spec = LineScannerSpec {
                frame: "lms400".into(),
                range: [0.7, 3.0],
                fov: fov_deg.to_radians(),
                resolution: 0.25f64.to_radians(),
                line_rate_hz: 190.0,
            };
            let config = ScanConfig::from_spec(&spec).unwrap();
            let start = device_to_spec_angle(config.start_angle_deg());
            prop_assert!((start + 0.5 * spec.fov).abs() < 1e-5);
            prop_assert!((config.span_deg() - fov_deg).abs() < 1e-4);
            prop_assert!((spec_to_device_angle(start) - config.start_angle_deg()).abs() < 1e-9);
        }
    }
}
