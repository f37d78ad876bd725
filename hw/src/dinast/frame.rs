//! The IPA-1110 bulk packet: [`RawFrame`] (the two raw 320×240 images of one packet) and
//! [`FrameDecoder`], which finds packets in the stream of bulk reads.
//!
//! A packet is [`PACKET_LEN`] = 512 + 2×76 800 bytes, the size of one bulk read: the sync
//! marker [`SYNC_MARKER`] starts a 512-byte header (marker included; the rest of the
//! header is ignored), then the two images follow, row-major. The first image is the
//! depth-coded raw image that the vendor model ([`super::raw_model`]) turns into
//! distances; the second one is kept as the amplitude (intensity) image. The vendor driver
//! only ever computes distances from the first one.
//!
//! The decoder does not assume that reads are aligned with packets: a packet may straddle
//! reads, the marker may be anywhere and garbage before it is skipped. A packet cut short by
//! the next marker is dropped (counted in [`DecoderStats::truncated_packets`]); image bytes
//! equal to the 8-byte marker would be taken for such a cut, a chance of one in 2⁶⁴ per
//! position. Memory is bounded: at most one packet of buffered bytes and
//! [`MAX_QUEUED_FRAMES`] decoded frames (older ones are dropped).

use super::raw_model::{RAW_HEIGHT, RAW_WIDTH};
use std::collections::VecDeque;

/// The 8 bytes that start every packet.
pub const SYNC_MARKER: [u8; 8] = [0xAA, 0xAA, 0x44, 0x44, 0xBB, 0xBB, 0x77, 0x77];
/// Bytes from the start of the marker to the first image byte.
pub const HEADER_LEN: usize = 512;
/// Bytes of one 8-bit 320×240 image.
pub const IMAGE_LEN: usize = RAW_WIDTH * RAW_HEIGHT;
/// Bytes of one packet, and of one bulk read.
pub const PACKET_LEN: usize = HEADER_LEN + 2 * IMAGE_LEN;
/// Decoded frames kept until popped; older ones are dropped.
pub const MAX_QUEUED_FRAMES: usize = 2;

/// The two raw images of one packet (320×240, row-major).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RawFrame {
    /// Depth-coded raw values (the vendor model's `p`; 0 means no return).
    pub depth_code: Vec<u8>,
    /// Amplitude (intensity) image.
    pub amplitude: Vec<u8>,
}

impl RawFrame {
    /// A frame of all-zero images (no return anywhere).
    pub fn empty() -> Self {
        Self {
            depth_code: vec![0; IMAGE_LEN],
            amplitude: vec![0; IMAGE_LEN],
        }
    }

    /// Raw depth code at column `x`, row `y`, if inside the image.
    pub fn depth_code_at(&self, x: usize, y: usize) -> Option<u8> {
        if x >= RAW_WIDTH || y >= RAW_HEIGHT {
            return None;
        }
        self.depth_code.get(y * RAW_WIDTH + x).copied()
    }

    /// The device packet carrying this frame (marker, zero header, the two images; images
    /// of the wrong size are cut or zero-padded to 320×240).
    ///
    /// ```
    /// use nbv_hw::dinast::{FrameDecoder, RawFrame, PACKET_LEN};
    /// let mut frame = RawFrame::empty();
    /// frame.depth_code[5] = 42;
    /// let packet = frame.to_packet();
    /// assert_eq!(packet.len(), PACKET_LEN);
    /// let mut decoder = FrameDecoder::new();
    /// decoder.push(&packet);
    /// assert_eq!(decoder.pop_frame(), Some(frame));
    /// ```
    pub fn to_packet(&self) -> Vec<u8> {
        let mut packet = Vec::with_capacity(PACKET_LEN);
        packet.extend_from_slice(&SYNC_MARKER);
        packet.resize(HEADER_LEN, 0);
        for image in [&self.depth_code, &self.amplitude] {
            let start = packet.len();
            packet.extend(image.iter().take(IMAGE_LEN));
            packet.resize(start + IMAGE_LEN, 0);
        }
        packet
    }
}

/// Counters of what the decoder has seen.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct DecoderStats {
    /// Complete frames decoded.
    pub frames: u64,
    /// Bytes skipped while looking for a marker.
    pub skipped_bytes: u64,
    /// Packets cut short by the next marker.
    pub truncated_packets: u64,
    /// Decoded frames dropped because the queue was full.
    pub dropped_frames: u64,
}

/// Reassembles packets from bulk reads (see the module documentation).
#[derive(Debug, Default)]
pub struct FrameDecoder {
    /// Bytes of the packet in progress; starts with the marker unless shorter than it.
    /// Always shorter than [`PACKET_LEN`] between calls.
    buffer: Vec<u8>,
    /// Offset in `buffer` from which a second marker has not been searched yet.
    unscanned: usize,
    frames: VecDeque<RawFrame>,
    stats: DecoderStats,
}

fn find_marker(bytes: &[u8]) -> Option<usize> {
    bytes
        .windows(SYNC_MARKER.len())
        .position(|window| window == SYNC_MARKER)
}

impl FrameDecoder {
    /// An empty decoder.
    pub fn new() -> Self {
        Self::default()
    }

    /// Feeds the bytes of one bulk read (any length).
    pub fn push(&mut self, mut data: &[u8]) {
        while !data.is_empty() {
            let room = PACKET_LEN.saturating_sub(self.buffer.len()).max(1);
            let (now, later) = data.split_at(room.min(data.len()));
            self.buffer.extend_from_slice(now);
            data = later;
            self.process();
        }
    }

    /// The oldest decoded frame not yet popped.
    pub fn pop_frame(&mut self) -> Option<RawFrame> {
        self.frames.pop_front()
    }

    /// Forgets buffered bytes and queued frames (not the statistics).
    pub fn reset(&mut self) {
        self.buffer.clear();
        self.unscanned = 0;
        self.frames.clear();
    }

    /// Bytes buffered towards the next packet (always less than [`PACKET_LEN`]).
    pub fn buffered_len(&self) -> usize {
        self.buffer.len()
    }

    /// Decoded frames waiting to be popped (at most [`MAX_QUEUED_FRAMES`]).
    pub fn queued_frames(&self) -> usize {
        self.frames.len()
    }

    /// What the decoder has seen so far.
    pub fn stats(&self) -> DecoderStats {
        self.stats
    }

    fn discard_front(&mut self, count: usize) {
        self.buffer.drain(..count);
        self.unscanned = self.unscanned.saturating_sub(count);
    }

    fn process(&mut self) {
        loop {
            if !self.buffer.starts_with(&SYNC_MARKER) {
                match find_marker(&self.buffer) {
                    Some(start) => {
                        self.stats.skipped_bytes += start as u64;
                        self.discard_front(start);
                        self.unscanned = SYNC_MARKER.len();
                    }
                    None => {
                        // Keep a tail that may be the start of a marker.
                        let keep = SYNC_MARKER.len() - 1;
                        let skip = self.buffer.len().saturating_sub(keep);
                        self.stats.skipped_bytes += skip as u64;
                        self.discard_front(skip);
                        self.unscanned = 0;
                        return;
                    }
                }
            }
            // The buffer starts with a marker: look for the next one inside this packet.
            let from = self.unscanned.max(SYNC_MARKER.len());
            let end = self.buffer.len().min(PACKET_LEN);
            let next = self
                .buffer
                .get(from..end)
                .and_then(find_marker)
                .map(|offset| from + offset);
            if let Some(next) = next {
                self.stats.truncated_packets += 1;
                self.discard_front(next);
                self.unscanned = SYNC_MARKER.len();
                continue;
            }
            if self.buffer.len() < PACKET_LEN {
                self.unscanned = self.buffer.len().saturating_sub(SYNC_MARKER.len() - 1);
                return;
            }
            let depth_code = self.buffer.get(HEADER_LEN..HEADER_LEN + IMAGE_LEN);
            let amplitude = self.buffer.get(HEADER_LEN + IMAGE_LEN..PACKET_LEN);
            if let (Some(depth_code), Some(amplitude)) = (depth_code, amplitude) {
                let frame = RawFrame {
                    depth_code: depth_code.to_vec(),
                    amplitude: amplitude.to_vec(),
                };
                if self.frames.len() >= MAX_QUEUED_FRAMES {
                    self.frames.pop_front();
                    self.stats.dropped_frames += 1;
                }
                self.frames.push_back(frame);
                self.stats.frames += 1;
            }
            self.discard_front(PACKET_LEN);
            self.unscanned = 0;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn patterned_frame(seed: u8) -> RawFrame {
        // No 0xAA/0x44/0xBB/0x77 run of the marker can appear: values stay below 0x44.
        let image = |salt: u8| -> Vec<u8> {
            (0..IMAGE_LEN)
                .map(|i| ((i as u32).wrapping_mul(31) as u8 ^ seed ^ salt) % 0x40)
                .collect()
        };
        RawFrame {
            depth_code: image(1),
            amplitude: image(2),
        }
    }

    #[test]
    fn garbage_before_the_marker_is_skipped() {
        let frame = patterned_frame(3);
        let mut stream = vec![0x55; 1000];
        stream.extend_from_slice(&[0xAA, 0xAA, 0x44]); // a false start
        stream.extend(frame.to_packet());
        let mut decoder = FrameDecoder::new();
        decoder.push(&stream);
        assert_eq!(decoder.pop_frame(), Some(frame));
        assert_eq!(decoder.stats().skipped_bytes, 1003);
    }

    #[test]
    fn truncated_packet_is_dropped_and_the_next_one_decodes() {
        let first = patterned_frame(4);
        let second = patterned_frame(5);
        let mut stream = first.to_packet();
        stream.truncate(HEADER_LEN + 1000);
        stream.extend(second.to_packet());
        let mut decoder = FrameDecoder::new();
        for chunk in stream.chunks(PACKET_LEN) {
            decoder.push(chunk);
        }
        assert_eq!(decoder.pop_frame(), Some(second));
        assert_eq!(decoder.pop_frame(), None);
        assert_eq!(decoder.stats().truncated_packets, 1);
    }

    #[test]
    fn queue_keeps_only_the_newest_frames() {
        let mut decoder = FrameDecoder::new();
        for seed in 0..4 {
            decoder.push(&patterned_frame(seed).to_packet());
        }
        assert_eq!(decoder.queued_frames(), MAX_QUEUED_FRAMES);
        assert_eq!(decoder.stats().dropped_frames, 2);
        assert_eq!(decoder.pop_frame(), Some(patterned_frame(2)));
    }

    #[test]
    fn byte_by_byte_feeding_decodes() {
        let frame = patterned_frame(9);
        let mut decoder = FrameDecoder::new();
        for byte in frame.to_packet() {
            decoder.push(&[byte]);
        }
        assert_eq!(decoder.pop_frame(), Some(frame));
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(48))]

        #[test]
        fn arbitrary_bytes_never_panic_and_memory_stays_bounded(
            chunks in proptest::collection::vec(
                proptest::collection::vec(
                    prop_oneof![any::<u8>(), Just(0xAA), Just(0x44), Just(0xBB), Just(0x77)],
                    0..4000,
                ),
                0..40,
            ),
            markers in proptest::collection::vec(any::<bool>(), 40),
        ) {
            let mut decoder = FrameDecoder::new();
            for (chunk, marker) in chunks.iter().zip(&markers) {
                if *marker {
                    decoder.push(&SYNC_MARKER);
                }
                decoder.push(chunk);
                prop_assert!(decoder.buffered_len() < PACKET_LEN);
                prop_assert!(decoder.queued_frames() <= MAX_QUEUED_FRAMES);
            }
        }

        #[test]
        fn a_packet_split_anywhere_decodes_the_same(
            seed in any::<u8>(),
            garbage in proptest::collection::vec(0u8..0x40, 0..600),
            cut_a in 0..PACKET_LEN + 600,
            cut_b in 0..PACKET_LEN + 600,
        ) {
            let frame = patterned_frame(seed);
            let mut stream = garbage;
            stream.extend(frame.to_packet());
            let (a, b) = (cut_a.min(cut_b).min(stream.len()), cut_a.max(cut_b).min(stream.len()));
            let mut decoder = FrameDecoder::new();
            decoder.push(&stream[..a]);
            decoder.push(&stream[a..b]);
            decoder.push(&stream[b..]);
            prop_assert_eq!(decoder.pop_frame(), Some(frame));
            prop_assert_eq!(decoder.pop_frame(), None);
        }
    }
}
