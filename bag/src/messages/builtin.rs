//! `builtin_interfaces`: [`Time`] and [`Duration`] (`int32 sec`, `uint32 nanosec`).

use super::{CdrStruct, ros_message};
use crate::cdr::{CdrReader, CdrWriter};
use crate::error::CdrError;

const NS_PER_S: i64 = 1_000_000_000;

/// `builtin_interfaces/msg/Time`: a stamp, seconds and nanoseconds since the epoch.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Time {
    /// Whole seconds.
    pub sec: i32,
    /// Nanoseconds, `0..1e9`.
    pub nanosec: u32,
}

impl Time {
    /// The stamp of `ns` nanoseconds (seconds saturate at the `i32` range).
    ///
    /// ```
    /// use nbv_bag::messages::Time;
    /// let t = Time::from_nanos(1_500_000_000);
    /// assert_eq!((t.sec, t.nanosec), (1, 500_000_000));
    /// assert_eq!(Time::from_nanos(-1).to_nanos(), -1);
    /// ```
    pub fn from_nanos(ns: i64) -> Self {
        let sec = ns.div_euclid(NS_PER_S);
        let nanosec = ns.rem_euclid(NS_PER_S);
        Self {
            sec: i32::try_from(sec).unwrap_or(if sec < 0 { i32::MIN } else { i32::MAX }),
            nanosec: u32::try_from(nanosec).unwrap_or(0),
        }
    }

    /// Nanoseconds since the epoch.
    pub fn to_nanos(self) -> i64 {
        i64::from(self.sec) * NS_PER_S + i64::from(self.nanosec)
    }
}

impl CdrStruct for Time {
    fn write_cdr(&self, w: &mut CdrWriter) {
        w.i32(self.sec);
        w.u32(self.nanosec);
    }
    fn read_cdr(r: &mut CdrReader<'_>) -> Result<Self, CdrError> {
        Ok(Self {
            sec: r.i32()?,
            nanosec: r.u32()?,
        })
    }
}

ros_message!(
    Time,
    "builtin_interfaces/msg/Time",
    "RIHS01_b106235e25a4c5ed35098aa0a61a3ee9c9b18d197f398b0e4206cea9acf9c197",
    "int32 sec\nuint32 nanosec\n",
    []
);

/// `builtin_interfaces/msg/Duration`: a span, seconds and nanoseconds.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash)]
pub struct Duration {
    /// Whole seconds.
    pub sec: i32,
    /// Nanoseconds, `0..1e9`.
    pub nanosec: u32,
}

impl CdrStruct for Duration {
    fn write_cdr(&self, w: &mut CdrWriter) {
        w.i32(self.sec);
        w.u32(self.nanosec);
    }
    fn read_cdr(r: &mut CdrReader<'_>) -> Result<Self, CdrError> {
        Ok(Self {
            sec: r.i32()?,
            nanosec: r.u32()?,
        })
    }
}

ros_message!(
    Duration,
    "builtin_interfaces/msg/Duration",
    "RIHS01_e8d009f659816f758b75334ee1a9ca5b5c0b859843261f14c7f937349599d93b",
    "int32 sec\nuint32 nanosec\n",
    []
);
