//! Fuzzes the Dinast packet decoder: arbitrary bytes, fed in arbitrary chunk sizes, never
//! panic, keep the decoder's memory bounded, and every decoded frame has two 320×240 images.
#![no_main]

use libfuzzer_sys::fuzz_target;
use nbv_hw::dinast::{FrameDecoder, IMAGE_LEN, MAX_QUEUED_FRAMES, PACKET_LEN, SYNC_MARKER};

fuzz_target!(|data: &[u8]| {
    // Byte 0-1: chunk size. Byte 2, bit 0: a marker before every chunk; bit 1: the rest is
    // repeated up to two packets' length, so that small inputs reach complete packets.
    let (chunk, flags, rest) = match data {
        [a, b, c, rest @ ..] => (usize::from(u16::from_le_bytes([*a, *b])).max(1), *c, rest),
        _ => (1, 0, data),
    };
    let stream: Vec<u8> = if flags & 2 == 2 && !rest.is_empty() {
        rest.iter().copied().cycle().take(2 * PACKET_LEN).collect()
    } else {
        rest.to_vec()
    };
    let mut decoder = FrameDecoder::new();
    for piece in stream.chunks(chunk) {
        if flags & 1 == 1 {
            decoder.push(&SYNC_MARKER);
        }
        decoder.push(piece);
        assert!(decoder.buffered_len() < PACKET_LEN);
        assert!(decoder.queued_frames() <= MAX_QUEUED_FRAMES);
        while let Some(frame) = decoder.pop_frame() {
            assert_eq!(frame.depth_code.len(), IMAGE_LEN);
            assert_eq!(frame.amplitude.len(), IMAGE_LEN);
        }
    }
});
