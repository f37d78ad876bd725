//! CDR (XCDR1, little-endian) as ROS 2 puts it on the wire: [`CdrWriter`] and
//! [`CdrReader`], the aligned primitives every message in [`messages`](crate::messages) is
//! built from.
//!
//! Hand-written rather than `cdr-encoding` + serde: the ROS layout needs only a dozen
//! primitives, and owning them gives typed errors with byte offsets, bounds on sequence
//! counts before anything is allocated (a corrupt count cannot ask for gigabytes), and no
//! serde machinery in the crate.
//!
//! Layout (see the crate's facts): a 4-byte encapsulation header `00 01 00 00`; every
//! primitive aligned to its own size (1, 2, 4, or 8 for `f64`), counted from the byte after
//! the header; padding bytes are zero; strings are a `u32` length including the NUL, the
//! bytes, the NUL; sequences are a `u32` count then the elements; fixed arrays carry no
//! count; nested structs add no alignment of their own. The reader accepts up to 3 trailing
//! padding bytes, like rosbags. **Big-endian data (`00 00`) is rejected** with
//! [`CdrError::BigEndian`]: ROS 2 on every mainstream platform writes little-endian.

use crate::error::CdrError;

/// The encapsulation header of little-endian CDR (representation id `CDR_LE`, options 0).
pub const CDR_LE_HEADER: [u8; 4] = [0x00, 0x01, 0x00, 0x00];

/// Builds one CDR little-endian message, header included.
///
/// ```
/// use nbv_bag::cdr::CdrWriter;
/// let mut w = CdrWriter::new();
/// w.u8(1);
/// w.f64(2.0); // aligned to 8 after the header: 7 padding bytes
/// assert_eq!(w.finish().len(), 4 + 8 + 8);
/// ```
#[derive(Debug, Clone)]
pub struct CdrWriter {
    buf: Vec<u8>,
}

impl Default for CdrWriter {
    fn default() -> Self {
        Self::new()
    }
}

impl CdrWriter {
    /// An empty message: just the encapsulation header.
    pub fn new() -> Self {
        Self {
            buf: CDR_LE_HEADER.to_vec(),
        }
    }

    fn align(&mut self, n: usize) {
        while !(self.buf.len() - CDR_LE_HEADER.len()).is_multiple_of(n) {
            self.buf.push(0);
        }
    }

    /// A `uint8` (or `byte`/`char`).
    pub fn u8(&mut self, v: u8) {
        self.buf.push(v);
    }

    /// An `int8`.
    pub fn i8(&mut self, v: i8) {
        self.buf.extend_from_slice(&v.to_le_bytes());
    }

    /// A `bool` (one byte, 0 or 1).
    pub fn bool(&mut self, v: bool) {
        self.buf.push(u8::from(v));
    }

    /// A `uint16`, aligned to 2.
    pub fn u16(&mut self, v: u16) {
        self.align(2);
        self.buf.extend_from_slice(&v.to_le_bytes());
    }

    /// A `uint32`, aligned to 4.
    pub fn u32(&mut self, v: u32) {
        self.align(4);
        self.buf.extend_from_slice(&v.to_le_bytes());
    }

    /// An `int32`, aligned to 4.
    pub fn i32(&mut self, v: i32) {
        self.align(4);
        self.buf.extend_from_slice(&v.to_le_bytes());
    }

    /// A `float32`, aligned to 4.
    pub fn f32(&mut self, v: f32) {
        self.align(4);
        self.buf.extend_from_slice(&v.to_le_bytes());
    }

    /// A `float64`, aligned to 8.
    pub fn f64(&mut self, v: f64) {
        self.align(8);
        self.buf.extend_from_slice(&v.to_le_bytes());
    }

    /// A sequence's element count (`u32`, aligned to 4). Lengths over `u32::MAX` are not
    /// representable in CDR and are a caller bug; they saturate.
    pub fn seq_len(&mut self, n: usize) {
        self.u32(u32::try_from(n).unwrap_or(u32::MAX));
    }

    /// A `string`: length including the NUL, the bytes, the NUL.
    pub fn string(&mut self, s: &str) {
        self.seq_len(s.len() + 1);
        self.buf.extend_from_slice(s.as_bytes());
        self.buf.push(0);
    }

    /// A `uint8[]`: the count, then the raw bytes.
    pub fn bytes(&mut self, b: &[u8]) {
        self.seq_len(b.len());
        self.buf.extend_from_slice(b);
    }

    /// A `float64[]`: the count, then the aligned values.
    pub fn f64_seq(&mut self, v: &[f64]) {
        self.seq_len(v.len());
        for &x in v {
            self.f64(x);
        }
    }

    /// A `float64[N]`: the values with no count.
    pub fn f64_array(&mut self, v: &[f64]) {
        for &x in v {
            self.f64(x);
        }
    }

    /// A `string[]`.
    pub fn string_seq(&mut self, v: &[String]) {
        self.seq_len(v.len());
        for s in v {
            self.string(s);
        }
    }

    /// The finished message.
    pub fn finish(self) -> Vec<u8> {
        self.buf
    }
}

/// Reads one CDR little-endian message, checking bounds at every step.
///
/// ```
/// use nbv_bag::cdr::CdrReader;
/// let mut r = CdrReader::new(&[0, 1, 0, 0, 7, 0, 0, 0]).unwrap();
/// assert_eq!(r.u32().unwrap(), 7);
/// r.finish().unwrap();
/// assert!(CdrReader::new(&[0, 1, 0]).is_err());
/// ```
#[derive(Debug, Clone)]
pub struct CdrReader<'a> {
    buf: &'a [u8],
    pos: usize,
}

impl<'a> CdrReader<'a> {
    /// Checks the encapsulation header and positions after it.
    ///
    /// # Errors
    /// [`CdrError::Truncated`] under 4 bytes, [`CdrError::BigEndian`] for `00 00`,
    /// [`CdrError::Encapsulation`] for any other representation id.
    pub fn new(buf: &'a [u8]) -> Result<Self, CdrError> {
        if buf.len() < CDR_LE_HEADER.len() {
            return Err(CdrError::Truncated {
                offset: 0,
                need: CDR_LE_HEADER.len(),
                len: buf.len(),
            });
        }
        match [buf[0], buf[1]] {
            [0x00, 0x01] => Ok(Self { buf, pos: 4 }),
            [0x00, 0x00] => Err(CdrError::BigEndian),
            id => Err(CdrError::Encapsulation { id }),
        }
    }

    /// Bytes not yet read.
    pub fn remaining(&self) -> usize {
        self.buf.len().saturating_sub(self.pos)
    }

    fn align(&mut self, n: usize) {
        let rel = self.pos - CDR_LE_HEADER.len();
        self.pos += (n - rel % n) % n;
    }

    fn take(&mut self, n: usize) -> Result<&'a [u8], CdrError> {
        let end = self.pos.checked_add(n).filter(|&e| e <= self.buf.len());
        match end {
            Some(end) => {
                let s = &self.buf[self.pos..end];
                self.pos = end;
                Ok(s)
            }
            None => Err(CdrError::Truncated {
                offset: self.pos,
                need: n,
                len: self.buf.len(),
            }),
        }
    }

    fn array<const N: usize>(&mut self) -> Result<[u8; N], CdrError> {
        let s = self.take(N)?;
        let mut a = [0u8; N];
        a.copy_from_slice(s);
        Ok(a)
    }

    /// A `uint8`.
    pub fn u8(&mut self) -> Result<u8, CdrError> {
        Ok(self.array::<1>()?[0])
    }

    /// An `int8`.
    pub fn i8(&mut self) -> Result<i8, CdrError> {
        Ok(i8::from_le_bytes(self.array()?))
    }

    /// A `bool`: any non-zero byte is true.
    pub fn bool(&mut self) -> Result<bool, CdrError> {
        Ok(self.u8()? != 0)
    }

    /// A `uint16`.
    pub fn u16(&mut self) -> Result<u16, CdrError> {
        self.align(2);
        Ok(u16::from_le_bytes(self.array()?))
    }

    /// A `uint32`.
    pub fn u32(&mut self) -> Result<u32, CdrError> {
        self.align(4);
        Ok(u32::from_le_bytes(self.array()?))
    }

    /// An `int32`.
    pub fn i32(&mut self) -> Result<i32, CdrError> {
        self.align(4);
        Ok(i32::from_le_bytes(self.array()?))
    }

    /// A `float32`.
    pub fn f32(&mut self) -> Result<f32, CdrError> {
        self.align(4);
        Ok(f32::from_le_bytes(self.array()?))
    }

    /// A `float64`.
    pub fn f64(&mut self) -> Result<f64, CdrError> {
        self.align(8);
        Ok(f64::from_le_bytes(self.array()?))
    }

    /// A sequence count, checked against the bytes left: each element takes at least
    /// `min_element_bytes`, so a corrupt count fails here instead of allocating.
    ///
    /// # Errors
    /// [`CdrError::Truncated`] when the count cannot fit in the rest of the buffer.
    pub fn seq_len(&mut self, min_element_bytes: usize) -> Result<usize, CdrError> {
        let offset = self.pos;
        let n = self.u32()? as usize;
        let need = n.saturating_mul(min_element_bytes.max(1));
        if min_element_bytes > 0 && need > self.remaining() {
            return Err(CdrError::Truncated {
                offset,
                need,
                len: self.buf.len(),
            });
        }
        Ok(n)
    }

    /// A `string`: the length must include a NUL and the bytes must be UTF-8.
    ///
    /// # Errors
    /// [`CdrError::Truncated`], or [`CdrError::BadString`] for a zero length, a missing
    /// NUL or invalid UTF-8.
    pub fn string(&mut self) -> Result<String, CdrError> {
        let offset = self.pos;
        let n = self.seq_len(1)?;
        let bytes = self.take(n)?;
        match bytes.split_last() {
            Some((0, text)) => String::from_utf8(text.to_vec()).map_err(|_| CdrError::BadString {
                offset,
                why: "not UTF-8",
            }),
            Some(_) => Err(CdrError::BadString {
                offset,
                why: "no terminating NUL",
            }),
            None => Err(CdrError::BadString {
                offset,
                why: "length 0 (a string's length counts its NUL)",
            }),
        }
    }

    /// A `uint8[]`.
    pub fn bytes(&mut self) -> Result<Vec<u8>, CdrError> {
        let n = self.seq_len(1)?;
        Ok(self.take(n)?.to_vec())
    }

    /// A `float64[]`.
    pub fn f64_seq(&mut self) -> Result<Vec<f64>, CdrError> {
        let n = self.seq_len(8)?;
        (0..n).map(|_| self.f64()).collect()
    }

    /// A `float64[N]`.
    pub fn f64_array<const N: usize>(&mut self) -> Result<[f64; N], CdrError> {
        let mut a = [0.0; N];
        for x in &mut a {
            *x = self.f64()?;
        }
        Ok(a)
    }

    /// A `string[]`.
    pub fn string_seq(&mut self) -> Result<Vec<String>, CdrError> {
        let n = self.seq_len(5)?;
        (0..n).map(|_| self.string()).collect()
    }

    /// Ends the message: at most 3 trailing (padding) bytes may be left.
    ///
    /// # Errors
    /// [`CdrError::TrailingBytes`] for 4 or more.
    pub fn finish(self) -> Result<(), CdrError> {
        match self.remaining() {
            0..=3 => Ok(()),
            extra => Err(CdrError::TrailingBytes { extra }),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn alignment_counts_from_after_the_header() {
        let mut w = CdrWriter::new();
        w.string("base"); // 4 + 4 + 5 = 13 bytes, relative 9
        w.f64(1.0); // relative 16, not 16 from the buffer's start (which would be 24)
        let b = w.finish();
        assert_eq!(b.len(), 20 + 8);
        assert_eq!(&b[13..20], &[0; 7]);
        assert_eq!(&b[20..28], &1.0f64.to_le_bytes());
    }

    #[test]
    fn empty_string_is_length_one() {
        let mut w = CdrWriter::new();
        w.string("");
        assert_eq!(w.finish(), vec![0, 1, 0, 0, 1, 0, 0, 0, 0]);
    }

    #[test]
    fn truncated_is_an_error() {
        let mut r = CdrReader::new(&[0, 1, 0, 0, 1, 2]).unwrap();
        let e = r.u32().unwrap_err();
        assert_eq!(
            e,
            CdrError::Truncated {
                offset: 4,
                need: 4,
                len: 6
            }
        );
        assert!(e.to_string().contains("truncated"), "{e}");
    }

    #[test]
    fn huge_count_fails_before_allocating() {
        let mut r = CdrReader::new(&[0, 1, 0, 0, 0xff, 0xff, 0xff, 0xff]).unwrap();
        assert!(matches!(r.bytes(), Err(CdrError::Truncated { .. })));
    }

    #[test]
    fn encapsulation_ids() {
        assert_eq!(
            CdrReader::new(&[0, 0, 0, 0]).unwrap_err(),
            CdrError::BigEndian
        );
        assert_eq!(
            CdrReader::new(&[0, 3, 0, 0]).unwrap_err(),
            CdrError::Encapsulation { id: [0, 3] }
        );
    }

    #[test]
    fn up_to_three_trailing_bytes() {
        for extra in 0..=3 {
            let mut b = vec![0, 1, 0, 0, 9, 0, 0, 0];
            b.extend(std::iter::repeat_n(0, extra));
            let mut r = CdrReader::new(&b).unwrap();
            assert_eq!(r.u32().unwrap(), 9);
            r.finish().unwrap();
        }
        let mut r = CdrReader::new(&[0, 1, 0, 0, 9, 0, 0, 0, 0, 0, 0, 0]).unwrap();
        r.u32().unwrap();
        assert_eq!(
            r.finish().unwrap_err(),
            CdrError::TrailingBytes { extra: 4 }
        );
    }

    #[test]
    fn bad_strings() {
        let r = |b: &[u8]| CdrReader::new(b).unwrap().string().unwrap_err();
        assert!(matches!(
            r(&[0, 1, 0, 0, 0, 0, 0, 0]),
            CdrError::BadString { .. }
        ));
        assert!(matches!(
            r(&[0, 1, 0, 0, 1, 0, 0, 0, b'a']),
            CdrError::BadString { .. }
        ));
        assert!(matches!(
            r(&[0, 1, 0, 0, 2, 0, 0, 0, 0xff, 0]),
            CdrError::BadString { .. }
        ));
    }
}
