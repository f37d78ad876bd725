//! The mapping between [`MeasurementTelegram`]s and the rig's [`ScanLine`]s: angles
//! (device degrees ↔ spec radians, see [`super::scan_config`]), distances (scaled
//! millimetres ↔ metres, "no echo" ↔ NaN) and time (the device's wrapping microsecond
//! counter ↔ unwrapped seconds on the rig clock).

use super::scan_config::{device_to_spec_angle, spec_to_device_angle};
use super::telegram::{MAX_POINTS, MeasurementPoint, MeasurementTelegram};
use nbv_core::rig::ScanLine;
use thiserror::Error;

/// Distance scaling the emulator sends: units of 0.1 mm (longest distance 6.5535 m).
pub const EMULATED_DISTANCE_SCALING: u16 = 10;

/// Unwraps the device's 32-bit microsecond timestamps into a monotonic 64-bit count.
///
/// Consecutive timestamps are assumed less than 2³¹ µs (about 35 minutes) apart, so the
/// signed wrapping difference of two raw values is the true difference.
///
/// ```
/// use nbv_hw::lms400::TimestampUnwrapper;
/// let mut clock = TimestampUnwrapper::default();
/// assert_eq!(clock.unwrap(u32::MAX - 9), i64::from(u32::MAX - 9));
/// assert_eq!(clock.unwrap(5), i64::from(u32::MAX) + 6);
/// ```
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct TimestampUnwrapper {
    last: Option<(u32, i64)>,
}

impl TimestampUnwrapper {
    /// The unwrapped value of `raw`, microseconds.
    pub fn unwrap(&mut self, raw: u32) -> i64 {
        let unwrapped = match self.last {
            None => i64::from(raw),
            Some((last_raw, last)) => last + i64::from(raw.wrapping_sub(last_raw) as i32),
        };
        self.last = Some((raw, unwrapped));
        unwrapped
    }
}

/// The scan line a telegram carries.
///
/// `time` is the line's rig time; ranges are metres, NaN where the device saw no echo or
/// the distance is outside `range` (metres, inclusive).
pub fn telegram_to_line(telegram: &MeasurementTelegram, time: f64, range: [f64; 2]) -> ScanLine {
    let ranges = (0..telegram.points.len())
        .map(|i| match telegram.distance_m(i) {
            Some(r) if r >= range[0] && r <= range[1] => r as f32,
            _ => f32::NAN,
        })
        .collect();
    ScanLine {
        time,
        start_angle: device_to_spec_angle(telegram.start_angle_deg()),
        angle_step: telegram.angular_step_deg().to_radians(),
        ranges,
        truth: None,
    }
}

/// A scan line that has no telegram.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum LineMappingError {
    /// Time or an angle is NaN/infinite or does not fit the telegram's units.
    #[error("{what} = {value} does not fit a telegram")]
    Unrepresentable {
        /// Which quantity.
        what: &'static str,
        /// Its value.
        value: f64,
    },
    /// More beams than a telegram can carry.
    #[error("{beams} beams exceed the maximum of {max} per telegram")]
    TooManyBeams {
        /// Beams in the line.
        beams: usize,
        /// [`MAX_POINTS`].
        max: usize,
    },
}

/// Header values of the telegrams an emulated device sends.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TelegramSettings {
    /// `mLRreqdata` mode.
    pub format: u16,
    /// Scan frequency, 1/100 Hz.
    pub scan_frequency: u16,
    /// Range filter limits in millimetres, when the filter is on.
    pub range_filter_mm: Option<(u16, u16)>,
}

/// The telegram a device sends for `line`.
///
/// Distances use [`EMULATED_DISTANCE_SCALING`]; a NaN, non-positive or unrepresentable
/// range, or one the range filter drops, becomes 0 ("no echo"). The timestamp is
/// `line.time` in microseconds modulo 2³². Remission is 0.
pub fn line_to_telegram(
    line: &ScanLine,
    settings: &TelegramSettings,
    telegram_counter: u16,
) -> Result<MeasurementTelegram, LineMappingError> {
    if line.ranges.len() > MAX_POINTS {
        return Err(LineMappingError::TooManyBeams {
            beams: line.ranges.len(),
            max: MAX_POINTS,
        });
    }
    let start_deg = spec_to_device_angle(line.start_angle);
    let start_angle = fixed(start_deg * 1e4, f64::from(i32::MIN), f64::from(i32::MAX))
        .map(|v| v as i32)
        .ok_or(LineMappingError::Unrepresentable {
            what: "start angle (°)",
            value: start_deg,
        })?;
    let step_deg = line.angle_step.to_degrees();
    let angular_step = fixed(step_deg * 1e4, 1.0, f64::from(u16::MAX))
        .map(|v| v as u16)
        .ok_or(LineMappingError::Unrepresentable {
            what: "angle step (°)",
            value: step_deg,
        })?;
    let timestamp_us = fixed(line.time * 1e6, -9e18, 9e18)
        .map(|us| (us as i64).rem_euclid(1 << 32) as u32)
        .ok_or(LineMappingError::Unrepresentable {
            what: "time (s)",
            value: line.time,
        })?;
    let scaling = f64::from(EMULATED_DISTANCE_SCALING);
    let points = line
        .ranges
        .iter()
        .map(|&r| {
            let distance = fixed(f64::from(r) * 1e3 * scaling, 1.0, f64::from(u16::MAX))
                .filter(|&d| match settings.range_filter_mm {
                    Some((min, max)) => {
                        d >= f64::from(min) * scaling && d <= f64::from(max) * scaling
                    }
                    None => true,
                })
                .map_or(0, |d| d as u16);
            MeasurementPoint {
                distance,
                remission: 0,
            }
        })
        .collect();
    Ok(MeasurementTelegram {
        format: settings.format,
        distance_scaling: EMULATED_DISTANCE_SCALING,
        start_angle,
        angular_step,
        scan_frequency: settings.scan_frequency,
        remission_scaling: 1,
        remission_start: 0,
        remission_end: u16::from(u8::MAX),
        points,
        telegram_counter,
        timestamp_us,
    })
}

/// `value` rounded, if finite and within `[min, max]`.
fn fixed(value: f64, min: f64, max: f64) -> Option<f64> {
    let rounded = value.round();
    (rounded.is_finite() && rounded >= min && rounded <= max).then_some(rounded)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    const SETTINGS: TelegramSettings = TelegramSettings {
        format: 20,
        scan_frequency: 19_000,
        range_filter_mm: None,
    };

    fn line(ranges: Vec<f32>) -> ScanLine {
        ScanLine {
            time: 12.5,
            start_angle: -35f64.to_radians(),
            angle_step: 0.25f64.to_radians(),
            ranges,
            truth: None,
        }
    }

    #[test]
    fn invalid_ranges_become_no_echo_and_come_back_as_nan() {
        let source = line(vec![f32::NAN, -1.0, 0.0, 7.0, f32::INFINITY, 1.5, 0.5]);
        let telegram = line_to_telegram(&source, &SETTINGS, 0).unwrap();
        let distances: Vec<u16> = telegram.points.iter().map(|p| p.distance).collect();
        assert_eq!(distances, [0, 0, 0, 0, 0, 15_000, 5_000]);
        let back = telegram_to_line(&telegram, 1.0, [0.7, 3.0]);
        assert!(back.ranges[..5].iter().all(|r| r.is_nan()));
        assert!((back.ranges[5] - 1.5).abs() < 1e-6);
        assert!(back.ranges[6].is_nan(), "outside the spec range");
    }

    #[test]
    fn the_range_filter_drops_distances_outside_its_limits() {
        let settings = TelegramSettings {
            range_filter_mm: Some((700, 3000)),
            ..SETTINGS
        };
        let telegram = line_to_telegram(&line(vec![0.5, 0.7, 3.0, 3.1]), &settings, 0).unwrap();
        let distances: Vec<u16> = telegram.points.iter().map(|p| p.distance).collect();
        assert_eq!(distances, [0, 7_000, 30_000, 0]);
    }

    #[test]
    fn non_finite_geometry_is_rejected() {
        let mut bad = line(vec![1.0]);
        bad.angle_step = f64::NAN;
        assert!(line_to_telegram(&bad, &SETTINGS, 0).is_err());
        let mut bad = line(vec![1.0]);
        bad.time = f64::INFINITY;
        assert!(line_to_telegram(&bad, &SETTINGS, 0).is_err());
        let mut bad = line(vec![1.0]);
        bad.angle_step = -0.01;
        assert!(line_to_telegram(&bad, &SETTINGS, 0).is_err());
    }

    #[test]
    fn timestamps_unwrap_forwards_and_tolerate_small_steps_back() {
        let mut clock = TimestampUnwrapper::default();
        assert_eq!(clock.unwrap(100), 100);
        assert_eq!(clock.unwrap(90), 90);
        assert_eq!(clock.unwrap(u32::MAX), -(1 << 32) + i64::from(u32::MAX));
    }

    proptest! {
        #[test]
        fn lines_round_trip_within_a_tenth_of_a_millimetre(
            ranges in prop::collection::vec(0.7f32..3.0, 1..120),
            time in 0.0f64..4000.0,
            start_deg in -35.0f64..0.0,
            step_e4 in 1000u32..5_000,
        ) {
            let source = ScanLine {
                time,
                start_angle: start_deg.to_radians(),
                angle_step: (f64::from(step_e4) * 1e-4).to_radians(),
                ranges,
                truth: None,
            };
            let telegram = line_to_telegram(&source, &SETTINGS, 3).unwrap();
            let payload = telegram.encode().unwrap();
            let parsed = MeasurementTelegram::parse(&payload).unwrap();
            let mut clock = TimestampUnwrapper::default();
            let back = telegram_to_line(&parsed, clock.unwrap(parsed.timestamp_us) as f64 * 1e-6, [0.7, 3.0]);
            prop_assert!((back.time - time).abs() <= 0.5e-6 + 1e-9);
            prop_assert!((back.start_angle - source.start_angle).abs() < 1e-6);
            prop_assert!((back.angle_step - source.angle_step).abs() < 1e-9);
            prop_assert_eq!(back.ranges.len(), source.ranges.len());
            for (a, b) in back.ranges.iter().zip(&source.ranges) {
                prop_assert!((a - b).abs() <= 0.5e-4 + 1e-6, "{} vs {}", a, b);
            }
        }

        #[test]
        fn unwrapping_restores_any_monotonic_sequence(
            start in 0i64..(1 << 40),
            steps in prop::collection::vec(0i64..(1 << 31), 1..50),
        ) {
            let mut clock = TimestampUnwrapper::default();
            let first = clock.unwrap(start.rem_euclid(1 << 32) as u32);
            let mut truth = start;
            for step in steps {
                truth += step;
                let got = clock.unwrap(truth.rem_euclid(1 << 32) as u32);
                prop_assert_eq!(got - first, truth - start);
            }
        }
    }
}
