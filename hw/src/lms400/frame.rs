//! CoLa binary framing: `02 02 02 02`, payload length (u32 big-endian), payload, XOR of the
//! payload. [`encode_frame`] writes a frame; [`FrameDecoder`] cuts frames out of a byte
//! stream incrementally, resynchronising on garbage.
//!
//! Resynchronisation rule: a frame starts at the *last* four bytes of a run of `0x02`
//! bytes. The first length byte of any admissible frame is `0x00` (payloads are at most
//! [`MAX_PAYLOAD_LEN`] bytes), so garbage ending in `0x02` right before a real frame does
//! not shift the header.

use thiserror::Error;

/// The start-of-text marker opening every frame.
pub const STX: [u8; 4] = [0x02; 4];

/// Largest payload the codec accepts (64 KiB). A longer declared length is rejected
/// before anything is allocated for it.
pub const MAX_PAYLOAD_LEN: usize = 64 * 1024;

/// Bytes of framing around a payload: marker, length and checksum.
pub const FRAME_OVERHEAD: usize = STX.len() + 4 + 1;

/// Largest whole frame: [`MAX_PAYLOAD_LEN`] plus [`FRAME_OVERHEAD`].
pub const MAX_FRAME_LEN: usize = MAX_PAYLOAD_LEN + FRAME_OVERHEAD;

/// Why a frame could not be encoded or decoded.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum FrameError {
    /// The payload (declared or given) is longer than [`MAX_PAYLOAD_LEN`].
    #[error("payload of {len} bytes exceeds the maximum of {max} bytes")]
    PayloadTooLong {
        /// Declared or given payload length.
        len: u64,
        /// [`MAX_PAYLOAD_LEN`].
        max: usize,
    },
    /// The checksum byte does not match the XOR of the payload; the frame is dropped.
    #[error("checksum mismatch: expected {expected:#04x}, received {actual:#04x}")]
    Checksum {
        /// XOR of the received payload.
        expected: u8,
        /// Checksum byte that came with it.
        actual: u8,
    },
}

/// XOR of all bytes of `payload`: the frame checksum.
///
/// ```
/// use nbv_hw::lms400::checksum;
/// assert_eq!(checksum(b"sAN"), b's' ^ b'A' ^ b'N');
/// ```
pub fn checksum(payload: &[u8]) -> u8 {
    payload.iter().fold(0, |acc, b| acc ^ b)
}

/// Wraps `payload` in a frame.
///
/// ```
/// use nbv_hw::lms400::encode_frame;
/// let frame = encode_frame(b"sMN Run").unwrap();
/// assert_eq!(&frame[..8], &[2, 2, 2, 2, 0, 0, 0, 7]);
/// assert_eq!(frame.len(), 7 + 9);
/// ```
pub fn encode_frame(payload: &[u8]) -> Result<Vec<u8>, FrameError> {
    let len = u32::try_from(payload.len())
        .ok()
        .filter(|&len| len as usize <= MAX_PAYLOAD_LEN)
        .ok_or(FrameError::PayloadTooLong {
            len: payload.len() as u64,
            max: MAX_PAYLOAD_LEN,
        })?;
    let mut frame = Vec::with_capacity(payload.len() + FRAME_OVERHEAD);
    frame.extend_from_slice(&STX);
    frame.extend_from_slice(&len.to_be_bytes());
    frame.extend_from_slice(payload);
    frame.push(checksum(payload));
    Ok(frame)
}

/// Incremental frame decoder: [`push`](FrameDecoder::push) bytes as they arrive, then call
/// [`next_frame`](FrameDecoder::next_frame) until it returns `Ok(None)`.
///
/// Bytes that cannot start a frame are skipped (and counted, see
/// [`skipped_bytes`](FrameDecoder::skipped_bytes)). Once `next_frame` has returned
/// `Ok(None)`, at most [`MAX_FRAME_LEN`] bytes stay buffered.
///
/// ```
/// use nbv_hw::lms400::{FrameDecoder, encode_frame};
/// let frame = encode_frame(b"sAN Run 1").unwrap();
/// let mut decoder = FrameDecoder::new();
/// decoder.push(b"noise");
/// decoder.push(&frame[..5]);
/// assert_eq!(decoder.next_frame(), Ok(None));
/// decoder.push(&frame[5..]);
/// assert_eq!(decoder.next_frame(), Ok(Some(b"sAN Run 1".to_vec())));
/// assert_eq!(decoder.skipped_bytes(), 5);
/// ```
#[derive(Debug, Default, Clone)]
pub struct FrameDecoder {
    buffer: Vec<u8>,
    skipped: u64,
}

impl FrameDecoder {
    /// An empty decoder.
    pub fn new() -> Self {
        Self::default()
    }

    /// Appends received bytes.
    pub fn push(&mut self, bytes: &[u8]) {
        self.buffer.extend_from_slice(bytes);
    }

    /// Bytes currently buffered (an incomplete frame, or not yet decoded ones).
    pub fn buffered_len(&self) -> usize {
        self.buffer.len()
    }

    /// Bytes skipped so far because they could not start a frame.
    pub fn skipped_bytes(&self) -> u64 {
        self.skipped
    }

    /// The next complete frame's payload, `Ok(None)` if more bytes are needed, or an error
    /// for a frame that was dropped (later calls go on with the following bytes).
    pub fn next_frame(&mut self) -> Result<Option<Vec<u8>>, FrameError> {
        let Some(start) = self.find_header() else {
            return Ok(None);
        };
        self.discard(start, true);
        let header_len = STX.len() + 4;
        let Some(len_bytes) = self.buffer.get(STX.len()..header_len) else {
            return Ok(None);
        };
        let declared = len_bytes
            .iter()
            .fold(0u64, |acc, &b| (acc << 8) | u64::from(b));
        if declared > MAX_PAYLOAD_LEN as u64 {
            // Drop the marker only: whatever follows may still hold a real frame.
            self.discard(STX.len(), true);
            return Err(FrameError::PayloadTooLong {
                len: declared,
                max: MAX_PAYLOAD_LEN,
            });
        }
        let payload_len = declared as usize;
        let frame_len = header_len + payload_len + 1;
        let (Some(payload), Some(&actual)) = (
            self.buffer.get(header_len..header_len + payload_len),
            self.buffer.get(frame_len - 1),
        ) else {
            return Ok(None);
        };
        let expected = checksum(payload);
        let result = if expected == actual {
            Ok(Some(payload.to_vec()))
        } else {
            Err(FrameError::Checksum { expected, actual })
        };
        self.discard(frame_len, false);
        result
    }

    /// Index of the first frame header in the buffer (the last four bytes of a run of
    /// `0x02` that is followed by a non-`0x02` byte). If there is none yet, drops
    /// everything that cannot be part of one and returns `None`.
    fn find_header(&mut self) -> Option<usize> {
        let mut run_start = None;
        for (i, &b) in self.buffer.iter().enumerate() {
            if b == STX[0] {
                run_start.get_or_insert(i);
                continue;
            }
            if let Some(start) = run_start.take()
                && i - start >= STX.len()
            {
                return Some(i - STX.len());
            }
        }
        // No complete header: keep a trailing run of 0x02 (at most a marker's worth).
        let keep_from = match run_start {
            Some(start) => start.max(self.buffer.len().saturating_sub(STX.len())),
            None => self.buffer.len(),
        };
        self.discard(keep_from, true);
        None
    }

    fn discard(&mut self, count: usize, skipped: bool) {
        let count = count.min(self.buffer.len());
        if skipped {
            self.skipped += count as u64;
        }
        self.buffer.drain(..count);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn decode_all(decoder: &mut FrameDecoder) -> Vec<Result<Vec<u8>, FrameError>> {
        let mut out = Vec::new();
        loop {
            match decoder.next_frame() {
                Ok(None) => return out,
                Ok(Some(p)) => out.push(Ok(p)),
                Err(e) => out.push(Err(e)),
            }
        }
    }

    #[test]
    fn checksum_error_carries_both_values_and_decoder_goes_on() {
        let mut bad = encode_frame(b"sAN Run 1").unwrap();
        let last = bad.len() - 1;
        bad[last] ^= 0xFF;
        let good = encode_frame(b"sWA FLsel").unwrap();
        let mut decoder = FrameDecoder::new();
        decoder.push(&bad);
        decoder.push(&good);
        let expected = checksum(b"sAN Run 1");
        assert_eq!(
            decode_all(&mut decoder),
            vec![
                Err(FrameError::Checksum {
                    expected,
                    actual: expected ^ 0xFF
                }),
                Ok(b"sWA FLsel".to_vec())
            ]
        );
    }

    #[test]
    fn oversized_length_is_rejected_without_waiting_for_it() {
        let mut decoder = FrameDecoder::new();
        decoder.push(&[2, 2, 2, 2, 0, 1, 0, 1]);
        assert_eq!(
            decoder.next_frame(),
            Err(FrameError::PayloadTooLong {
                len: 65537,
                max: MAX_PAYLOAD_LEN
            })
        );
        assert_eq!(decoder.next_frame(), Ok(None));
        assert!(decoder.buffered_len() <= STX.len());
    }

    #[test]
    fn garbage_ending_in_stx_bytes_does_not_shift_the_header() {
        let mut decoder = FrameDecoder::new();
        decoder.push(&[0xFF, 2, 2, 2]);
        decoder.push(&encode_frame(b"x").unwrap());
        assert_eq!(decode_all(&mut decoder), vec![Ok(b"x".to_vec())]);
        assert_eq!(decoder.skipped_bytes(), 4);
    }

    #[test]
    fn empty_payload_round_trips() {
        let mut decoder = FrameDecoder::new();
        decoder.push(&encode_frame(b"").unwrap());
        assert_eq!(decode_all(&mut decoder), vec![Ok(Vec::new())]);
    }

    #[test]
    fn encoding_rejects_a_payload_above_the_maximum() {
        let payload = vec![0u8; MAX_PAYLOAD_LEN + 1];
        assert!(matches!(
            encode_frame(&payload),
            Err(FrameError::PayloadTooLong { .. })
        ));
    }

    proptest! {
        #[test]
        fn encode_then_decode_round_trips(
            payloads in prop::collection::vec(prop::collection::vec(any::<u8>(), 0..600), 1..5)
        ) {
            let mut decoder = FrameDecoder::new();
            for p in &payloads {
                decoder.push(&encode_frame(p).unwrap());
            }
            let decoded = decode_all(&mut decoder);
            let expected: Vec<_> = payloads.iter().cloned().map(Ok).collect();
            prop_assert_eq!(decoded, expected);
            prop_assert_eq!(decoder.buffered_len(), 0);
            prop_assert_eq!(decoder.skipped_bytes(), 0);
        }

        #[test]
        fn split_at_any_boundary_decodes_the_same(
            payloads in prop::collection::vec(prop::collection::vec(any::<u8>(), 0..300), 1..4),
            cuts in prop::collection::vec(any::<prop::sample::Index>(), 0..6),
        ) {
            let stream: Vec<u8> = payloads.iter().flat_map(|p| encode_frame(p).unwrap()).collect();
            let mut cut_points: Vec<usize> = cuts.iter().map(|c| c.index(stream.len() + 1)).collect();
            cut_points.sort_unstable();
            let mut decoder = FrameDecoder::new();
            let mut decoded = Vec::new();
            let mut from = 0;
            for cut in cut_points.into_iter().chain(std::iter::once(stream.len())) {
                decoder.push(&stream[from..cut]);
                from = cut;
                decoded.extend(decode_all(&mut decoder));
            }
            let expected: Vec<_> = payloads.iter().cloned().map(Ok).collect();
            prop_assert_eq!(decoded, expected);
        }

        #[test]
        fn garbage_before_frames_is_skipped(
            garbage in prop::collection::vec(any::<u8>().prop_filter("no STX", |b| *b != 2), 0..200),
            tail in 0usize..4,
            payload in prop::collection::vec(any::<u8>(), 0..300),
        ) {
            let mut decoder = FrameDecoder::new();
            decoder.push(&garbage);
            decoder.push(&vec![2u8; tail]);
            decoder.push(&encode_frame(&payload).unwrap());
            prop_assert_eq!(decode_all(&mut decoder), vec![Ok(payload)]);
            prop_assert_eq!(decoder.skipped_bytes(), (garbage.len() + tail) as u64);
        }

        #[test]
        fn arbitrary_bytes_never_panic_and_stay_bounded(
            chunks in prop::collection::vec(prop::collection::vec(any::<u8>(), 0..2000), 0..8),
        ) {
            let mut decoder = FrameDecoder::new();
            for chunk in &chunks {
                decoder.push(chunk);
                for frame in decode_all(&mut decoder).into_iter().flatten() {
                    prop_assert!(frame.len() <= MAX_PAYLOAD_LEN);
                }
                prop_assert!(decoder.buffered_len() <= MAX_FRAME_LEN);
            }
        }

        #[test]
        fn stx_heavy_bytes_never_panic_and_stay_bounded(
            bytes in prop::collection::vec(prop::sample::select(vec![0u8, 1, 2, 2, 2, 0xFF]), 0..3000),
        ) {
            let mut decoder = FrameDecoder::new();
            decoder.push(&bytes);
            for frame in decode_all(&mut decoder).into_iter().flatten() {
                prop_assert!(frame.len() <= MAX_PAYLOAD_LEN);
            }
            prop_assert!(decoder.buffered_len() <= MAX_FRAME_LEN);
        }
    }
}
