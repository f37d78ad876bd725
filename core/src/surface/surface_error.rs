//! [`SurfaceError`]: what fusing views into a surface, or reading and writing them, can
//! refuse.

use std::path::PathBuf;

/// Errors of the [`surface`](super) module.
#[derive(Debug, thiserror::Error)]
pub enum SurfaceError {
    /// A fusion parameter out of range.
    #[error("surface parameter {key} = {value}: {why}")]
    Parameter {
        /// The parameter's key.
        key: &'static str,
        /// Its value.
        value: f64,
        /// What it must be.
        why: &'static str,
    },
    /// A depth image whose size is not its camera's.
    #[error("a depth image of {pixels} pixels for a camera of {width}x{height}")]
    ImageSize {
        /// Pixels in the image.
        pixels: usize,
        /// The camera's width.
        width: usize,
        /// The camera's height.
        height: usize,
    },
    /// A file of a dataset that is missing, unreadable or malformed.
    #[error("{}{}: {message}", path.display(), line.map(|l| format!(" line {l}")).unwrap_or_default())]
    File {
        /// The file.
        path: PathBuf,
        /// The line, where one is at fault.
        line: Option<usize>,
        /// What is wrong.
        message: String,
    },
}

impl SurfaceError {
    /// An error of `path` (at `line`, if given).
    pub(super) fn file(
        path: impl Into<PathBuf>,
        line: Option<usize>,
        message: impl Into<String>,
    ) -> Self {
        Self::File {
            path: path.into(),
            line,
            message: message.into(),
        }
    }
}
