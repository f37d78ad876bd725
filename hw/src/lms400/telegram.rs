//! [`MeasurementTelegram`]: one scan line as the LMS400 streams it after `mLRreqdata`.
//!
//! Payload layout (inside a CoLa frame):
//!
//! | bytes          | content                                                        |
//! |----------------|----------------------------------------------------------------|
//! | 16             | marker [`TELEGRAM_MARKER`], ASCII `sSN LMDscandata ` (final space) |
//! | 20             | header, little-endian: format u16, distance scaling u16, start angle i32 (1/10000°), angular step u16 (1/10000°), point count N u16, scan frequency u16 (1/100 Hz), remission scaling u16, remission start u16, remission end u16 |
//! | 3 · N          | N records: distance u16 little-endian, remission u8             |
//! | 6              | trailer: telegram counter u16, device timestamp u32 (µs)        |
//!
//! The marker tells a telegram from the text replies (`sMA`, `sAN`, `sWA`, `sFA`): no reply
//! starts with `sSN`.
//!
//! Decisions where the public sources are vague:
//! * **Distance**: the record holds `distance_mm × distance_scaling`, so a distance in
//!   millimetres is `raw / distance_scaling` (scaling 10 means units of 0.1 mm). A raw `0`
//!   means "no echo".
//! * **Scan frequency** is carried in 1/100 Hz (the unit `mSCsetscanconfig` answers in).
//! * **Trailer**: public drivers disagree on its layout; this crate fixes it as a telegram
//!   counter u16 followed by the device timestamp u32 in microseconds (it wraps after about
//!   71.6 minutes; the client unwraps it).
//! * **Plausibility**: a distance scaling or angular step of zero, or a fan that leaves
//!   0°–180° (device angles; the LMS400 itself scans 55°–125°), is rejected as
//!   [`TelegramError::Implausible`].

use super::frame::MAX_PAYLOAD_LEN;
use thiserror::Error;

/// Marker opening a measurement telegram's payload.
pub const TELEGRAM_MARKER: &[u8; 16] = b"sSN LMDscandata ";

/// Bytes of the fixed header after the marker.
pub const HEADER_LEN: usize = 20;

/// Bytes of one measurement record (distance u16 + remission u8).
pub const RECORD_LEN: usize = 3;

/// Bytes of the trailer (telegram counter u16 + timestamp u32).
pub const TRAILER_LEN: usize = 6;

/// Most points a telegram can carry and still fit a frame.
pub const MAX_POINTS: usize =
    (MAX_PAYLOAD_LEN - TELEGRAM_MARKER.len() - HEADER_LEN - TRAILER_LEN) / RECORD_LEN;

/// Device angles a telegram's fan may span, in 1/10000°.
const PLAUSIBLE_ANGLES: std::ops::RangeInclusive<i64> = 0..=1_800_000;

/// One beam of a telegram.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct MeasurementPoint {
    /// Distance, millimetres × the telegram's distance scaling; 0 = no echo.
    pub distance: u16,
    /// Remission (reflectivity) value.
    pub remission: u8,
}

/// One measurement telegram (see the module documentation for the layout).
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct MeasurementTelegram {
    /// Output format (the `mLRreqdata` mode, e.g. 20 = distance and remission).
    pub format: u16,
    /// Distance scaling: raw distances are millimetres × this factor.
    pub distance_scaling: u16,
    /// Device angle of the first beam, 1/10000°.
    pub start_angle: i32,
    /// Angle between beams, 1/10000°.
    pub angular_step: u16,
    /// Scan frequency, 1/100 Hz.
    pub scan_frequency: u16,
    /// Remission scaling factor.
    pub remission_scaling: u16,
    /// Lower end of the remission range.
    pub remission_start: u16,
    /// Upper end of the remission range.
    pub remission_end: u16,
    /// The beams, in angle order.
    pub points: Vec<MeasurementPoint>,
    /// Telegram counter (wraps at 65536).
    pub telegram_counter: u16,
    /// Device timestamp of the line, microseconds (wraps at 2³²).
    pub timestamp_us: u32,
}

/// Why a payload is not a valid measurement telegram.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum TelegramError {
    /// The payload does not start with [`TELEGRAM_MARKER`].
    #[error("payload is not a measurement telegram (no `sSN LMDscandata ` marker)")]
    NotATelegram,
    /// The payload is too short for the header.
    #[error("telegram of {len} bytes is shorter than its {needed}-byte header")]
    Truncated {
        /// Payload length.
        len: usize,
        /// Bytes needed for marker and header.
        needed: usize,
    },
    /// The payload length does not match the point count.
    #[error("telegram announces {points} points ({expected} bytes) but has {len} bytes")]
    LengthMismatch {
        /// Announced point count.
        points: u16,
        /// Payload length those points need.
        expected: usize,
        /// Actual payload length.
        len: usize,
    },
    /// More points than fit a frame (encoding only).
    #[error("{points} points exceed the maximum of {max} per telegram")]
    TooManyPoints {
        /// Points given.
        points: usize,
        /// [`MAX_POINTS`].
        max: usize,
    },
    /// A header value no device sends.
    #[error("implausible telegram: {0}")]
    Implausible(String),
}

impl MeasurementTelegram {
    /// Device angle of the first beam, degrees.
    pub fn start_angle_deg(&self) -> f64 {
        f64::from(self.start_angle) * 1e-4
    }

    /// Angle between beams, degrees.
    pub fn angular_step_deg(&self) -> f64 {
        f64::from(self.angular_step) * 1e-4
    }

    /// Distance of beam `i` in metres; `None` for "no echo" or an index out of range.
    pub fn distance_m(&self, i: usize) -> Option<f64> {
        let point = self.points.get(i)?;
        if point.distance == 0 || self.distance_scaling == 0 {
            return None;
        }
        Some(f64::from(point.distance) / f64::from(self.distance_scaling) * 1e-3)
    }

    /// The payload (marker, header, records, trailer).
    ///
    /// ```
    /// use nbv_hw::lms400::{MeasurementPoint, MeasurementTelegram};
    /// let telegram = MeasurementTelegram {
    ///     format: 20,
    ///     distance_scaling: 10,
    ///     start_angle: 550_000,
    ///     angular_step: 2_500,
    ///     points: vec![MeasurementPoint { distance: 12_345, remission: 7 }],
    ///     timestamp_us: 1_000,
    ///     ..Default::default()
    /// };
    /// let payload = telegram.encode().unwrap();
    /// assert_eq!(MeasurementTelegram::parse(&payload).unwrap(), telegram);
    /// assert!((telegram.distance_m(0).unwrap() - 1.2345).abs() < 1e-12);
    /// ```
    pub fn encode(&self) -> Result<Vec<u8>, TelegramError> {
        let count = u16::try_from(self.points.len())
            .ok()
            .filter(|&n| usize::from(n) <= MAX_POINTS)
            .ok_or(TelegramError::TooManyPoints {
                points: self.points.len(),
                max: MAX_POINTS,
            })?;
        self.check_plausible(count)?;
        let mut out = Vec::with_capacity(payload_len(count));
        out.extend_from_slice(TELEGRAM_MARKER);
        for field in [self.format, self.distance_scaling] {
            out.extend_from_slice(&field.to_le_bytes());
        }
        out.extend_from_slice(&self.start_angle.to_le_bytes());
        for field in [
            self.angular_step,
            count,
            self.scan_frequency,
            self.remission_scaling,
            self.remission_start,
            self.remission_end,
        ] {
            out.extend_from_slice(&field.to_le_bytes());
        }
        for point in &self.points {
            out.extend_from_slice(&point.distance.to_le_bytes());
            out.push(point.remission);
        }
        out.extend_from_slice(&self.telegram_counter.to_le_bytes());
        out.extend_from_slice(&self.timestamp_us.to_le_bytes());
        Ok(out)
    }

    /// Parses a payload; the point count must match the payload length exactly.
    pub fn parse(payload: &[u8]) -> Result<Self, TelegramError> {
        let body = payload
            .strip_prefix(TELEGRAM_MARKER.as_slice())
            .ok_or(TelegramError::NotATelegram)?;
        let mut reader = LeReader { bytes: body };
        let header = (|| {
            Some((
                reader.u16()?,
                reader.u16()?,
                reader.i32()?,
                [reader.u16()?, reader.u16()?, reader.u16()?],
                [reader.u16()?, reader.u16()?, reader.u16()?],
            ))
        })();
        let Some((
            format,
            distance_scaling,
            start_angle,
            [angular_step, count, scan_frequency],
            [remission_scaling, remission_start, remission_end],
        )) = header
        else {
            return Err(TelegramError::Truncated {
                len: payload.len(),
                needed: TELEGRAM_MARKER.len() + HEADER_LEN,
            });
        };
        let expected = payload_len(count);
        if payload.len() != expected {
            return Err(TelegramError::LengthMismatch {
                points: count,
                expected,
                len: payload.len(),
            });
        }
        let mut telegram = Self {
            format,
            distance_scaling,
            start_angle,
            angular_step,
            scan_frequency,
            remission_scaling,
            remission_start,
            remission_end,
            points: Vec::with_capacity(usize::from(count)),
            telegram_counter: 0,
            timestamp_us: 0,
        };
        telegram.check_plausible(count)?;
        let short = TelegramError::LengthMismatch {
            points: count,
            expected,
            len: payload.len(),
        };
        for _ in 0..count {
            let distance = reader.u16().ok_or(short.clone())?;
            let remission = reader.u8().ok_or(short.clone())?;
            telegram.points.push(MeasurementPoint {
                distance,
                remission,
            });
        }
        telegram.telegram_counter = reader.u16().ok_or(short.clone())?;
        telegram.timestamp_us = reader.u32().ok_or(short)?;
        Ok(telegram)
    }

    fn check_plausible(&self, count: u16) -> Result<(), TelegramError> {
        if self.distance_scaling == 0 {
            return Err(TelegramError::Implausible("distance scaling 0".into()));
        }
        if self.angular_step == 0 {
            return Err(TelegramError::Implausible("angular step 0".into()));
        }
        let start = i64::from(self.start_angle);
        let end = start + i64::from(count.saturating_sub(1)) * i64::from(self.angular_step);
        if !PLAUSIBLE_ANGLES.contains(&start) || !PLAUSIBLE_ANGLES.contains(&end) {
            return Err(TelegramError::Implausible(format!(
                "fan {:.4}°..{:.4}° leaves 0°..180°",
                start as f64 * 1e-4,
                end as f64 * 1e-4
            )));
        }
        Ok(())
    }
}

/// Payload length of a telegram with `count` points.
fn payload_len(count: u16) -> usize {
    TELEGRAM_MARKER.len() + HEADER_LEN + usize::from(count) * RECORD_LEN + TRAILER_LEN
}

/// Little-endian field reader that never reads past its slice.
struct LeReader<'a> {
    bytes: &'a [u8],
}

impl LeReader<'_> {
    fn take<const N: usize>(&mut self) -> Option<[u8; N]> {
        let (head, rest) = self.bytes.split_first_chunk::<N>()?;
        self.bytes = rest;
        Some(*head)
    }

    fn u8(&mut self) -> Option<u8> {
        self.take::<1>().map(|[b]| b)
    }

    fn u16(&mut self) -> Option<u16> {
        self.take().map(u16::from_le_bytes)
    }

    fn u32(&mut self) -> Option<u32> {
        self.take().map(u32::from_le_bytes)
    }

    fn i32(&mut self) -> Option<i32> {
        self.take().map(i32::from_le_bytes)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn telegram_strategy() -> impl Strategy<Value = MeasurementTelegram> {
        (
            (any::<u16>(), 1u16.., 0i32..=1_000_000, 1u16..=10_000),
            (any::<u16>(), any::<u16>(), any::<u16>(), any::<u16>()),
            prop::collection::vec((any::<u16>(), any::<u8>()), 0..80),
            (any::<u16>(), any::<u32>()),
        )
            .prop_map(
                |(
                    (format, distance_scaling, start_angle, angular_step),
                    (scan_frequency, remission_scaling, remission_start, remission_end),
                    points,
                    (telegram_counter, timestamp_us),
                )| MeasurementTelegram {
                    format,
                    distance_scaling,
                    start_angle,
                    angular_step,
                    scan_frequency,
                    remission_scaling,
                    remission_start,
                    remission_end,
                    points: points
                        .into_iter()
                        .map(|(distance, remission)| MeasurementPoint {
                            distance,
                            remission,
                        })
                        .collect(),
                    telegram_counter,
                    timestamp_us,
                },
            )
    }

    fn sample() -> MeasurementTelegram {
        MeasurementTelegram {
            format: 20,
            distance_scaling: 10,
            start_angle: 550_000,
            angular_step: 2_500,
            scan_frequency: 19_000,
            points: vec![MeasurementPoint::default(); 3],
            ..Default::default()
        }
    }

    #[test]
    fn layout_matches_the_documented_offsets() {
        let mut telegram = sample();
        telegram.points[2] = MeasurementPoint {
            distance: 0x1234,
            remission: 0x56,
        };
        telegram.telegram_counter = 0xBEEF;
        telegram.timestamp_us = 0x0102_0304;
        let payload = telegram.encode().unwrap();
        assert_eq!(payload.len(), 16 + 20 + 9 + 6);
        assert_eq!(&payload[..16], b"sSN LMDscandata ");
        assert_eq!(&payload[16..18], &[20, 0]);
        assert_eq!(&payload[20..24], &550_000i32.to_le_bytes());
        assert_eq!(&payload[26..28], &[3, 0]);
        assert_eq!(&payload[42..45], &[0x34, 0x12, 0x56]);
        assert_eq!(&payload[45..], &[0xEF, 0xBE, 4, 3, 2, 1]);
    }

    #[test]
    fn point_count_must_match_the_length() {
        let mut payload = sample().encode().unwrap();
        payload.pop();
        assert!(matches!(
            MeasurementTelegram::parse(&payload),
            Err(TelegramError::LengthMismatch { points: 3, .. })
        ));
        let mut payload = sample().encode().unwrap();
        payload[26] = 0xFF;
        payload[27] = 0xFF;
        assert!(matches!(
            MeasurementTelegram::parse(&payload),
            Err(TelegramError::LengthMismatch { points: 0xFFFF, .. })
        ));
    }

    #[test]
    fn implausible_headers_are_rejected() {
        for bad in [
            MeasurementTelegram {
                distance_scaling: 0,
                ..sample()
            },
            MeasurementTelegram {
                angular_step: 0,
                ..sample()
            },
            MeasurementTelegram {
                start_angle: -10,
                ..sample()
            },
            MeasurementTelegram {
                start_angle: 1_799_999,
                ..sample()
            },
        ] {
            assert!(matches!(bad.encode(), Err(TelegramError::Implausible(_))));
            let mut payload = sample().encode().unwrap();
            payload[18..20].copy_from_slice(&bad.distance_scaling.to_le_bytes());
            payload[20..24].copy_from_slice(&bad.start_angle.to_le_bytes());
            payload[24..26].copy_from_slice(&bad.angular_step.to_le_bytes());
            assert!(matches!(
                MeasurementTelegram::parse(&payload),
                Err(TelegramError::Implausible(_))
            ));
        }
    }

    #[test]
    fn text_replies_and_short_payloads_are_not_telegrams() {
        assert_eq!(
            MeasurementTelegram::parse(b"sAN mLRstopdata 0"),
            Err(TelegramError::NotATelegram)
        );
        assert!(matches!(
            MeasurementTelegram::parse(b"sSN LMDscandata \x14\x00"),
            Err(TelegramError::Truncated { .. })
        ));
    }

    #[test]
    fn too_many_points_do_not_encode() {
        let telegram = MeasurementTelegram {
            angular_step: 1,
            points: vec![MeasurementPoint::default(); MAX_POINTS + 1],
            ..sample()
        };
        assert!(matches!(
            telegram.encode(),
            Err(TelegramError::TooManyPoints { .. })
        ));
    }

    proptest! {
        #[test]
        fn encode_then_parse_round_trips(telegram in telegram_strategy()) {
            match telegram.encode() {
                Ok(payload) => prop_assert_eq!(MeasurementTelegram::parse(&payload), Ok(telegram)),
                Err(TelegramError::Implausible(_)) => {
                    let end = i64::from(telegram.start_angle)
                        + i64::from(telegram.angular_step) * (telegram.points.len() as i64 - 1);
                    prop_assert!(end > 1_800_000);
                }
                Err(e) => prop_assert!(false, "unexpected {e}"),
            }
        }

        #[test]
        fn arbitrary_bytes_never_panic(body in prop::collection::vec(any::<u8>(), 0..400)) {
            let _ = MeasurementTelegram::parse(&body);
            let mut payload = TELEGRAM_MARKER.to_vec();
            payload.extend_from_slice(&body);
            if let Ok(telegram) = MeasurementTelegram::parse(&payload) {
                prop_assert_eq!(telegram.encode(), Ok(payload));
            }
        }
    }
}
