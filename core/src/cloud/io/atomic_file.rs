//! [`write_atomically`]: output files appear whole or not at all (a temporary file in the
//! target's directory, renamed over the target once it is complete).

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
    let run = || -> Result<(), CloudIoError> {
        let dir = match path.parent() {
            Some(p) if !p.as_os_str().is_empty() => p,
            _ => Path::new("."),
        };
        let name = path
            .file_name()
            .map_or_else(|| "out".into(), |n| n.to_string_lossy());
        let prefix = format!(".{name}.");
        let mut builder = tempfile::Builder::new();
        builder.prefix(&prefix).suffix(".tmp");
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            // Like a plain `File::create` (the umask still applies), not tempfile's 0600.
            builder.permissions(std::fs::Permissions::from_mode(0o666));
        }
        let mut tmp = builder.tempfile_in(dir).map_err(CloudIoError::io)?;
        write(tmp.as_file_mut())?;
        tmp.as_file_mut().flush().map_err(CloudIoError::io)?;
        tmp.persist(path).map_err(|e| CloudIoError::io(e.error))?;
        Ok(())
    };
    run().map_err(|e| e.with_path(path))
}
