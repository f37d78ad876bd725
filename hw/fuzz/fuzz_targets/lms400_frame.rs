//! FrameDecoder on arbitrary bytes, pushed in chunks whose sizes come from the input:
//! never panics, never yields a payload above the maximum, never buffers more than a frame.
#![no_main]

use libfuzzer_sys::fuzz_target;
use nbv_hw::lms400::{FrameDecoder, MAX_FRAME_LEN, MAX_PAYLOAD_LEN};

fuzz_target!(|data: &[u8]| {
    let Some((&chunk, bytes)) = data.split_first() else {
        return;
    };
    let chunk = usize::from(chunk).max(1);
    let mut decoder = FrameDecoder::new();
    for piece in bytes.chunks(chunk) {
        decoder.push(piece);
        while let Some(frame) = decoder.next_frame().transpose() {
            if let Ok(payload) = frame {
                assert!(payload.len() <= MAX_PAYLOAD_LEN);
            }
        }
        assert!(decoder.buffered_len() <= MAX_FRAME_LEN);
    }
});
