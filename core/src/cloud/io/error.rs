//! [`CloudIoError`]: what went wrong while reading or writing a cloud or depth file, where
//! (file, line or byte offset, record) and why.

use std::fmt;
use std::path::PathBuf;

use thiserror::Error;

use crate::cloud::CloudError;

/// Where in a file an error was found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Location {
    /// The file as a whole (or no finer position is meaningful).
    File,
    /// A 1-based line number in a text header or an ASCII body.
    Line(usize),
    /// A byte offset from the start of the file, and the index of the record (point, face,
    /// ...) being read there, if any.
    Byte {
        /// Offset from the start of the file.
        offset: u64,
        /// 0-based index of the record within its element, if the offset is inside one.
        record: Option<u64>,
    },
    /// A 0-based point index (checks made after decoding, such as finiteness).
    Point(usize),
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Location::File => Ok(()),
            Location::Line(line) => write!(f, ", line {line}"),
            Location::Byte {
                offset,
                record: Some(r),
            } => write!(f, ", byte {offset} (record {r})"),
            Location::Byte {
                offset,
                record: None,
            } => write!(f, ", byte {offset}"),
            Location::Point(i) => write!(f, ", point {i}"),
        }
    }
}

/// What is wrong (the part of [`CloudIoError`] that does not depend on the position).
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum CloudIoErrorKind {
    /// The operating system refused a read, write, create or rename.
    #[error("I/O error: {0}")]
    Io(std::io::Error),
    /// The file name does not end in an extension this module knows.
    #[error("unknown cloud file extension `{extension}`: expected `.ply` or `.pcd`")]
    UnknownExtension {
        /// The extension found (empty if none).
        extension: String,
    },
    /// The file does not start as the format requires.
    #[error("not a {format} file: {detail}")]
    BadMagic {
        /// Expected format name.
        format: &'static str,
        /// What was found instead.
        detail: String,
    },
    /// The header ends before the line that closes it.
    #[error("the header has no `{expected}` line (file truncated or not a {format} file)")]
    MissingHeaderEnd {
        /// Format name.
        format: &'static str,
        /// The closing keyword (`end_header`, `DATA`).
        expected: &'static str,
    },
    /// A header line is malformed or inconsistent with the others.
    #[error("bad header: {0}")]
    Header(String),
    /// A well-formed feature that this reader does not implement.
    #[error("unsupported: {0}")]
    Unsupported(String),
    /// The binary data is shorter than the header declares.
    #[error("data ends early: {what} needs {needed} bytes but only {available} remain")]
    Truncated {
        /// What was being read.
        what: String,
        /// Bytes needed from the current offset.
        needed: u64,
        /// Bytes left in the file from the current offset.
        available: u64,
    },
    /// An ASCII body has fewer records than the header declares.
    #[error("the file ends after {found} of the {expected} declared `{element}` records")]
    MissingRecords {
        /// Element (`vertex`, `face`, `point`).
        element: String,
        /// Declared record count.
        expected: u64,
        /// Records found.
        found: u64,
    },
    /// Data follows the last declared record (a wrong count in the header).
    #[error("{detail} after the last declared record (wrong count in the header?)")]
    TrailingData {
        /// What was found.
        detail: String,
    },
    /// An ASCII record has the wrong number of values.
    #[error("expected {expected} values on the line, found {found}")]
    ValueCount {
        /// Values the header implies.
        expected: usize,
        /// Values present.
        found: usize,
    },
    /// A token is not a number of the declared type.
    #[error("`{token}` is not a valid {expected}")]
    BadValue {
        /// The offending text (shortened if long).
        token: String,
        /// The expected type.
        expected: &'static str,
    },
    /// A label or view value is not an integer in `0..=u32::MAX`.
    #[error("{column} value {value} is not an integer in 0..=4294967295")]
    BadIndex {
        /// `label` or `view`.
        column: &'static str,
        /// The value read.
        value: f64,
    },
    /// A point, origin or normal coordinate is NaN or infinite (see `NonFinite::Reject`).
    #[error("{column} is not finite")]
    NonFinite {
        /// Column name.
        column: &'static str,
    },
    /// The cloud to write is inconsistent (a column of the wrong length).
    #[error("invalid cloud: {0}")]
    InvalidCloud(CloudError),
    /// A finite value overflows the chosen output type.
    #[error("{column} value {value} does not fit in a 32-bit float: write with FloatType::F64")]
    NotRepresentable {
        /// Column name.
        column: &'static str,
        /// The value.
        value: f64,
    },
    /// LZF-compressed PCD data is corrupt.
    #[error("corrupt binary_compressed data: {0}")]
    Compressed(String),
    /// The PNG encoder or decoder failed.
    #[error("PNG error: {0}")]
    Png(image::ImageError),
    /// A depth image has the wrong shape, pixel type, scale or value.
    #[error("depth image: {0}")]
    Depth(String),
}

/// An error reading or writing a cloud or depth-image file: the file (empty for readers
/// and writers over streams), where in it, and what is wrong.
///
/// It displays as `path, line 12: expected 6 values on the line, found 5`.
#[derive(Debug)]
pub struct CloudIoError {
    /// The file (empty when reading or writing a stream).
    pub path: PathBuf,
    /// Where in the file.
    pub location: Location,
    /// What is wrong.
    pub kind: CloudIoErrorKind,
}

impl CloudIoError {
    /// An error at `location` in a file whose path is not known yet.
    pub(crate) fn at(location: Location, kind: CloudIoErrorKind) -> Self {
        Self {
            path: PathBuf::new(),
            location,
            kind,
        }
    }

    /// An error about the file as a whole.
    pub(crate) fn file(kind: CloudIoErrorKind) -> Self {
        Self::at(Location::File, kind)
    }

    /// An I/O error.
    pub(crate) fn io(e: std::io::Error) -> Self {
        Self::file(CloudIoErrorKind::Io(e))
    }

    /// Sets the path if none is set yet.
    pub(crate) fn with_path(mut self, path: impl Into<PathBuf>) -> Self {
        if self.path.as_os_str().is_empty() {
            self.path = path.into();
        }
        self
    }
}

impl fmt::Display for CloudIoError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.path.as_os_str().is_empty() {
            write!(f, "<stream>")?;
        } else {
            write!(f, "{}", self.path.display())?;
        }
        write!(f, "{}: {}", self.location, self.kind)
    }
}

impl std::error::Error for CloudIoError {}

/// A token for an error message, shortened so that a garbage line cannot flood a log.
pub(crate) fn excerpt(token: &str) -> String {
    const MAX: usize = 40;
    if token.chars().count() <= MAX {
        token.to_owned()
    } else {
        let mut s: String = token.chars().take(MAX).collect();
        s.push('…');
        s
    }
}

impl From<std::io::Error> for CloudIoError {
    fn from(e: std::io::Error) -> Self {
        Self::io(e)
    }
}
