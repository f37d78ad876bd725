//! [`Lms400Faults`]: what the emulator can do wrong on purpose, so that tests see the
//! driver's behaviour on a broken wire.

use std::time::Duration;

/// Faults the emulator injects (all off by default).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Lms400Faults {
    /// Drop the connection once this many bytes of a stop's output (telegrams, garbage and
    /// the stop answer) have been sent, i.e. possibly in the middle of a telegram.
    pub disconnect_after_bytes: Option<usize>,
    /// Send a few garbage bytes (including a partial frame marker) before every telegram.
    pub garbage_before_telegrams: bool,
    /// Send every telegram with a wrong checksum byte.
    pub corrupt_checksum: bool,
    /// Hold every reply (and the telegrams that go with it) back this long.
    pub delay_replies: Option<Duration>,
}
