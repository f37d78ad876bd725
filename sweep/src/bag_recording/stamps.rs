//! Stamps: the rig's clock (seconds) as bag log times and message header stamps
//! (nanoseconds, offset by [`STAMP_OFFSET_NS`] so that no stamp is 0).

use nbv_bag::messages::{Header, Time};

/// Added to every stamp: rig time 0 is stamp 1 s (a stamp of 0 means "the latest" to tf2).
pub const STAMP_OFFSET_NS: u64 = 1_000_000_000;

/// The stamp (ns) of rig time `seconds` (negative or NaN times count as 0).
///
/// ```
/// use nbv_sweep::bag_recording::{STAMP_OFFSET_NS, stamp_ns};
/// assert_eq!(stamp_ns(0.0), STAMP_OFFSET_NS);
/// assert_eq!(stamp_ns(1.5), STAMP_OFFSET_NS + 1_500_000_000);
/// ```
pub fn stamp_ns(seconds: f64) -> u64 {
    let ns = (seconds * 1e9).round();
    let ns = if ns.is_finite() && ns > 0.0 {
        ns as u64
    } else {
        0
    };
    STAMP_OFFSET_NS.saturating_add(ns)
}

/// A header in `frame` at stamp `ns`.
pub fn header(frame: &str, ns: u64) -> Header {
    Header {
        stamp: Time::from_nanos(i64::try_from(ns).unwrap_or(i64::MAX)),
        frame_id: frame.to_owned(),
    }
}
