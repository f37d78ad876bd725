//! LZF (Marc Lehmann's format, as PCL uses for `DATA binary_compressed`): a bounds-checked
//! decompressor and a small greedy compressor.
//!
//! A stream is a sequence of chunks. A control byte `c < 32` is followed by `c + 1`
//! literal bytes. Otherwise `len = c >> 5` (if 7, plus the next byte) plus 2 bytes are
//! copied from `offset + 1` bytes back in the output, where `offset` is the low 5 bits of
//! `c` followed by the next byte.

/// Longest back-reference: `7 + 255 + 2` bytes.
const MAX_MATCH: usize = 264;
/// Farthest back-reference: 13 bits of offset.
const MAX_OFFSET: usize = 1 << 13;
/// Most output bytes one input byte can produce (a 3-byte reference of 264 bytes).
pub(crate) const MAX_RATIO: u64 = 88;

/// Decompresses `input`, which must produce exactly `expected` bytes.
pub(crate) fn lzf_decompress(input: &[u8], expected: usize) -> Result<Vec<u8>, String> {
    let mut out = Vec::with_capacity(expected);
    let mut ip = 0usize;
    while let Some(&ctrl) = input.get(ip) {
        ip += 1;
        let ctrl = usize::from(ctrl);
        if ctrl < 32 {
            let len = ctrl + 1;
            let lit = input.get(ip..ip + len).ok_or_else(|| {
                format!(
                    "literal run of {len} bytes at input byte {} runs past the end",
                    ip - 1
                )
            })?;
            if out.len() + len > expected {
                return Err(format!("output exceeds the declared {expected} bytes"));
            }
            out.extend_from_slice(lit);
            ip += len;
        } else {
            let mut len = ctrl >> 5;
            if len == 7 {
                len += usize::from(*input.get(ip).ok_or("back-reference cut short")?);
                ip += 1;
            }
            len += 2;
            let low = usize::from(*input.get(ip).ok_or("back-reference cut short")?);
            ip += 1;
            let distance = ((ctrl & 0x1f) << 8 | low) + 1;
            if distance > out.len() {
                return Err(format!(
                    "back-reference {distance} bytes back with only {} bytes decoded",
                    out.len()
                ));
            }
            if out.len() + len > expected {
                return Err(format!("output exceeds the declared {expected} bytes"));
            }
            let start = out.len() - distance;
            // Byte by byte: the source may overlap the bytes being written.
            for k in 0..len {
                let b = out[start + k];
                out.push(b);
            }
        }
    }
    if out.len() != expected {
        return Err(format!("decoded {} bytes, {expected} declared", out.len()));
    }
    Ok(out)
}

/// Compresses `input` (greedy matching through a hash of the next 3 bytes).
pub(crate) fn lzf_compress(input: &[u8]) -> Vec<u8> {
    const HASH_BITS: u32 = 14;
    let hash = |p: usize| {
        let v = u32::from(input[p]) << 16 | u32::from(input[p + 1]) << 8 | u32::from(input[p + 2]);
        (v.wrapping_mul(2_654_435_761) >> (32 - HASH_BITS)) as usize
    };
    let mut table = vec![usize::MAX; 1 << HASH_BITS];
    let mut out = Vec::with_capacity(input.len() + input.len() / 32 + 2);
    let mut ctrl = out.len();
    out.push(0u8);
    let mut lit = 0usize;
    let mut i = 0usize;
    while i < input.len() {
        let mut matched = 0usize;
        let mut distance = 0usize;
        if i + 3 <= input.len() {
            let h = hash(i);
            let r = table[h];
            table[h] = i;
            if r != usize::MAX && i - r <= MAX_OFFSET && input[r..r + 3] == input[i..i + 3] {
                let max = MAX_MATCH.min(input.len() - i);
                let mut len = 3;
                while len < max && input[r + len] == input[i + len] {
                    len += 1;
                }
                matched = len;
                distance = i - r;
            }
        }
        if matched > 0 {
            if lit > 0 {
                out[ctrl] = (lit - 1) as u8;
            } else {
                out.pop();
            }
            let off = distance - 1;
            let l = matched - 2;
            if l < 7 {
                out.push((l << 5 | off >> 8) as u8);
            } else {
                out.push((7 << 5 | off >> 8) as u8);
                out.push((l - 7) as u8);
            }
            out.push((off & 0xff) as u8);
            i += matched;
            ctrl = out.len();
            out.push(0);
            lit = 0;
        } else {
            out.push(input[i]);
            lit += 1;
            i += 1;
            if lit == 32 {
                out[ctrl] = 31;
                ctrl = out.len();
                out.push(0);
                lit = 0;
            }
        }
    }
    if lit > 0 {
        out[ctrl] = (lit - 1) as u8;
    } else {
        out.pop();
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn hand_made_stream() {
        // "abc" literal, then a 6-byte reference 3 back ("abcabc"), then literal "d".
        let stream = [2, b'a', b'b', b'c', (4 << 5) as u8, 2, 0, b'd'];
        assert_eq!(lzf_decompress(&stream, 10).unwrap(), b"abcabcabcd");
        assert!(lzf_decompress(&stream, 9).is_err());
        assert!(lzf_decompress(&stream, 11).is_err());
        assert!(lzf_decompress(&[(1 << 5) as u8, 0], 3).is_err());
        assert!(lzf_decompress(&[5, b'a'], 6).is_err());
    }

    #[test]
    fn long_runs_use_extended_lengths() {
        let data = vec![7u8; 10_000];
        let c = lzf_compress(&data);
        assert!(c.len() < 200, "{}", c.len());
        assert_eq!(lzf_decompress(&c, data.len()).unwrap(), data);
        assert!(data.len() as u64 <= MAX_RATIO * c.len() as u64);
    }

    proptest! {
        #[test]
        fn round_trip(data in proptest::collection::vec(0u8..4, 0..3000)) {
            let c = lzf_compress(&data);
            prop_assert_eq!(lzf_decompress(&c, data.len()).unwrap(), data);
        }

        #[test]
        fn garbage_never_panics(data in proptest::collection::vec(any::<u8>(), 0..200), n in 0usize..2000) {
            let _ = lzf_decompress(&data, n);
        }
    }
}
