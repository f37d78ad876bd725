//! [`TextLines`]: a cursor over the text lines of a byte buffer (headers and ASCII
//! bodies), tolerant of `\r\n` line ends and blank lines, that knows its line number.

use super::error::{CloudIoError, CloudIoErrorKind, Location, excerpt};

/// Lines of `bytes` from a byte offset on, numbered from 1 at the start of the file.
pub(crate) struct TextLines<'a> {
    bytes: &'a [u8],
    pos: usize,
    /// Number of the line that starts at `pos`.
    line: usize,
}

impl<'a> TextLines<'a> {
    /// Lines from byte `pos`, the first of which is line `line`.
    pub(crate) fn new(bytes: &'a [u8], pos: usize, line: usize) -> Self {
        Self { bytes, pos, line }
    }

    /// Byte offset of the next line.
    pub(crate) fn pos(&self) -> usize {
        self.pos
    }

    /// Number of the next line.
    pub(crate) fn line(&self) -> usize {
        self.line
    }

    /// The next line without its `\n` and any trailing `\r`, and its number; `None` at
    /// the end of the buffer.
    pub(crate) fn next_raw(&mut self) -> Option<(usize, &'a [u8])> {
        let rest = self.bytes.get(self.pos..).filter(|r| !r.is_empty())?;
        let (mut line, advance) = match rest.iter().position(|&b| b == b'\n') {
            Some(n) => (&rest[..n], n + 1),
            None => (rest, rest.len()),
        };
        if let [head @ .., b'\r'] = line {
            line = head;
        }
        let number = self.line;
        self.pos += advance;
        self.line += 1;
        Some((number, line))
    }

    /// The next line as text, and its number; `None` at the end of the buffer.
    pub(crate) fn next_text(&mut self) -> Option<Result<(usize, &'a str), CloudIoError>> {
        let (number, raw) = self.next_raw()?;
        Some(match std::str::from_utf8(raw) {
            Ok(s) => Ok((number, s)),
            Err(_) => Err(CloudIoError::at(
                Location::Line(number),
                CloudIoErrorKind::BadValue {
                    token: excerpt(&String::from_utf8_lossy(raw)),
                    expected: "line of text",
                },
            )),
        })
    }

    /// The next line that is not blank (whitespace only), as text.
    pub(crate) fn next_nonblank(&mut self) -> Option<Result<(usize, &'a str), CloudIoError>> {
        loop {
            match self.next_text()? {
                Ok((_, s)) if s.trim().is_empty() => continue,
                other => return Some(other),
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn crlf_blank_lines_and_numbers() {
        let b = b"a b\r\n\r\n  \nc\nd";
        let mut l = TextLines::new(b, 0, 1);
        assert_eq!(l.next_nonblank().unwrap().unwrap(), (1, "a b"));
        assert_eq!(l.next_nonblank().unwrap().unwrap(), (4, "c"));
        assert_eq!(l.pos(), 12);
        assert_eq!(l.next_nonblank().unwrap().unwrap(), (5, "d"));
        assert!(l.next_nonblank().is_none());
        let mut l = TextLines::new(b"\xff\xfe\n", 0, 7);
        let e = l.next_text().unwrap().unwrap_err();
        assert_eq!(e.location, Location::Line(7));
    }
}
