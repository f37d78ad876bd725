//! MeasurementTelegram::parse on arbitrary payloads (with and without the marker): never
//! panics, and whatever parses encodes back to the same bytes.
#![no_main]

use libfuzzer_sys::fuzz_target;
use nbv_hw::lms400::{MeasurementTelegram, TELEGRAM_MARKER};

fuzz_target!(|data: &[u8]| {
    if let Ok(telegram) = MeasurementTelegram::parse(data) {
        assert_eq!(telegram.encode().as_deref(), Ok(data));
    }
    let mut payload = TELEGRAM_MARKER.to_vec();
    payload.extend_from_slice(data);
    if let Ok(telegram) = MeasurementTelegram::parse(&payload) {
        assert_eq!(telegram.encode(), Ok(payload));
    }
});
