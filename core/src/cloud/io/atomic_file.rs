//! [`write_atomically`]: [`crate::atomic_file::write_atomically`] with the cloud I/O's
//! error type, naming the file.

use std::io::Write;
use std::path::Path;

use super::error::CloudIoError;

/// Creates `path` atomically: `write` fills a temporary file in the same directory, which
/// is renamed to `path` only if `write` succeeds; on any error the temporary file is
/// removed and an existing `path` is left untouched. Errors carry `path`.
///
/// ```
/// use std::io::Write;
/// let dir = std::env::temp_dir().join(format!("nbv-atomic-doc-{}", std::process::id()));
/// std::fs::create_dir_all(&dir).unwrap();
/// let path = dir.join("hello.txt");
/// nbv_core::cloud::io::write_atomically(&path, |w| {
///     w.write_all(b"hi").map_err(nbv_core::cloud::io::CloudIoError::from)
/// }).unwrap();
/// assert_eq!(std::fs::read(&path).unwrap(), b"hi");
/// std::fs::remove_dir_all(&dir).unwrap();
/// ```
pub fn write_atomically(
    path: &Path,
    write: impl FnOnce(&mut dyn Write) -> Result<(), CloudIoError>,
) -> Result<(), CloudIoError> {
    crate::atomic_file::write_atomically(path, write).map_err(|e| e.with_path(path))
}
