//! The crate's errors: [`CdrError`] (bytes that are not a message), [`CloudError`] (a
//! `PointCloud2` whose layout cannot be read as xyz), [`TfError`] (a lookup the tf buffer
//! cannot answer), [`DecodeError`] (either of the first two) and [`BagError`] (files,
//! MCAP records, topics; it names the file, the topic and the message index).

use std::path::PathBuf;

/// Why bytes could not be decoded as CDR.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum CdrError {
    /// The buffer ends before a field does.
    #[error("CDR truncated: {need} bytes needed at offset {offset} of a {len}-byte buffer")]
    Truncated {
        /// Buffer offset of the field (header included).
        offset: usize,
        /// Bytes the field needs.
        need: usize,
        /// Length of the buffer.
        len: usize,
    },
    /// Big-endian CDR (encapsulation `00 00`), which this crate does not read.
    #[error("big-endian CDR (encapsulation 00 00) is not supported, only little-endian (00 01)")]
    BigEndian,
    /// An encapsulation id other than CDR_LE/CDR_BE.
    #[error("unknown CDR encapsulation id {:02x} {:02x} (expected 00 01)", id[0], id[1])]
    Encapsulation {
        /// The first two bytes.
        id: [u8; 2],
    },
    /// A string without its NUL, of length 0 or not UTF-8.
    #[error("bad CDR string at offset {offset}: {why}")]
    BadString {
        /// Buffer offset of the string's length.
        offset: usize,
        /// What is wrong.
        why: &'static str,
    },
    /// More than 3 bytes left after the last field.
    #[error("CDR message size mismatch: {extra} bytes after the last field (at most 3 allowed)")]
    TrailingBytes {
        /// Bytes left over.
        extra: usize,
    },
}

/// Why a `PointCloud2` could not be read as xyz points.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum CloudError {
    /// `is_bigendian` is set.
    #[error("big-endian point clouds are not supported")]
    BigEndian,
    /// No field named `x`, `y` or `z`.
    #[error("point cloud has no '{0}' field")]
    MissingField(&'static str),
    /// An x/y/z field that is neither FLOAT32 (7) nor FLOAT64 (8).
    #[error(
        "point cloud field '{field}' has datatype {datatype}; only FLOAT32 (7) and FLOAT64 (8) are read"
    )]
    Datatype {
        /// The field.
        field: &'static str,
        /// Its datatype code.
        datatype: u8,
    },
    /// A field that does not fit in `point_step`.
    #[error(
        "point cloud field '{field}' at offset {offset} ({size} bytes) overruns point_step {point_step}"
    )]
    FieldOutOfBounds {
        /// The field.
        field: &'static str,
        /// Its offset.
        offset: u32,
        /// Its size in bytes.
        size: u32,
        /// The point step.
        point_step: u32,
    },
    /// `row_step < width·point_step`.
    #[error("point cloud row_step {row_step} is less than width {width} × point_step {point_step}")]
    RowStep {
        /// The row step.
        row_step: u32,
        /// The width.
        width: u32,
        /// The point step.
        point_step: u32,
    },
    /// `data.len() != row_step·height`.
    #[error("point cloud data is {len} bytes, row_step×height says {expected}")]
    DataSize {
        /// Bytes of data.
        len: usize,
        /// `row_step·height`.
        expected: u64,
    },
}

/// Why a message could not be turned into what was asked for.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum DecodeError {
    /// Not valid CDR for the type.
    #[error(transparent)]
    Cdr(#[from] CdrError),
    /// A cloud whose layout is unreadable.
    #[error(transparent)]
    Cloud(#[from] CloudError),
}

/// Why a tf lookup failed; each names the frames and the time (ns).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TfError {
    /// A frame that no transform mentions.
    #[error(
        "frame '{frame}' does not exist (looking up '{source_frame}' in '{target}' at t={t_ns} ns)"
    )]
    UnknownFrame {
        /// The missing frame.
        frame: String,
        /// The lookup's target frame.
        target: String,
        /// The lookup's source frame.
        source_frame: String,
        /// The lookup time.
        t_ns: i64,
    },
    /// Both frames exist but share no ancestor.
    #[error("frames '{target}' and '{source_frame}' are not connected (t={t_ns} ns)")]
    NotConnected {
        /// Target frame.
        target: String,
        /// Source frame.
        source_frame: String,
        /// The lookup time.
        t_ns: i64,
    },
    /// The time is before the first sample of an edge.
    #[error(
        "lookup of '{child}' in '{parent}' at t={t_ns} ns would require extrapolation into the past: earliest data is at {earliest_ns} ns"
    )]
    ExtrapolationPast {
        /// Parent frame of the edge.
        parent: String,
        /// Child frame of the edge.
        child: String,
        /// The lookup time.
        t_ns: i64,
        /// The edge's first sample.
        earliest_ns: i64,
    },
    /// The time is after the last sample of an edge.
    #[error(
        "lookup of '{child}' in '{parent}' at t={t_ns} ns would require extrapolation into the future: latest data is at {latest_ns} ns"
    )]
    ExtrapolationFuture {
        /// Parent frame of the edge.
        parent: String,
        /// Child frame of the edge.
        child: String,
        /// The lookup time.
        t_ns: i64,
        /// The edge's last sample.
        latest_ns: i64,
    },
    /// A parent chain longer than tf2's limit (a loop in the tree).
    #[error("frame '{frame}' has a parent chain longer than {limit} (a loop?) at t={t_ns} ns")]
    TooDeep {
        /// Where the walk started.
        frame: String,
        /// The depth limit.
        limit: usize,
        /// The lookup time.
        t_ns: i64,
    },
}

/// Errors reading or writing a bag; each names the file.
#[derive(Debug, thiserror::Error)]
pub enum BagError {
    /// A file or directory operation failed.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file or directory.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// The bag directory exists and overwriting was not asked for.
    #[error("{}: already exists (use BagWriter::create_overwrite to replace it)", path.display())]
    Exists {
        /// The directory.
        path: PathBuf,
    },
    /// The MCAP layer refused the file.
    #[error("{}: MCAP: {source}", path.display())]
    Mcap {
        /// The file.
        path: PathBuf,
        /// The MCAP error.
        source: mcap::McapError,
    },
    /// Not a rosbag2 MCAP file: the header's profile is not `ros2`.
    #[error("{}: MCAP profile is '{profile}', expected 'ros2'", path.display())]
    Profile {
        /// The file.
        path: PathBuf,
        /// The profile found.
        profile: String,
    },
    /// A topic whose messages are not CDR.
    #[error("{}: topic {topic}: message encoding is '{encoding}', expected 'cdr'", path.display())]
    Encoding {
        /// The file.
        path: PathBuf,
        /// The topic.
        topic: String,
        /// The encoding found.
        encoding: String,
    },
    /// A topic that is not in the bag (reading) or was not added (writing).
    #[error("{}: no topic {topic}", path.display())]
    UnknownTopic {
        /// The bag.
        path: PathBuf,
        /// The topic.
        topic: String,
    },
    /// A topic read or written as another type than its own.
    #[error("{}: topic {topic} has type {actual}, not {requested}", path.display())]
    TopicType {
        /// The bag.
        path: PathBuf,
        /// The topic.
        topic: String,
        /// Its type.
        actual: String,
        /// The type asked for.
        requested: String,
    },
    /// `metadata.yaml` is missing what the reader needs, or the directory holds no MCAP.
    #[error("{}: {message}", path.display())]
    Layout {
        /// The file or directory.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// One message could not be decoded.
    #[error("{}: topic {topic} message {index}: {source}", path.display())]
    Message {
        /// The file.
        path: PathBuf,
        /// The topic.
        topic: String,
        /// The message's index in the topic (log-time order, from 0).
        index: usize,
        /// Why.
        source: DecodeError,
    },
}
