//! Output files that appear whole or not at all: [`write_atomically`] fills a temporary
//! file in the target's directory and renames it over the target only once it is complete
//! and synced. Every writer of the project (clouds, meshes, grids, scenes, reports,
//! pictures) goes through it.

use std::io::Write;
use std::path::Path;

/// Creates `path` atomically: `write` fills a temporary file in the same directory, which
/// is synced and renamed to `path` only if `write` succeeds; on any error the temporary
/// file is removed and an existing `path` is left untouched. The file gets the usual
/// permissions of a new file (0666 less the umask), not a temporary file's 0600.
///
/// ```
/// use std::io::Write;
/// let dir = std::env::temp_dir().join(format!("nbv-atomic-doc-{}", std::process::id()));
/// std::fs::create_dir_all(&dir).unwrap();
/// let path = dir.join("hello.txt");
/// nbv_core::atomic_file::write_atomically(&path, |w| w.write_all(b"hi")).unwrap();
/// assert_eq!(std::fs::read(&path).unwrap(), b"hi");
/// // A failed write leaves the old content and no temporary file.
/// let failed: std::io::Result<()> = nbv_core::atomic_file::write_atomically(&path, |w| {
///     w.write_all(b"half")?;
///     Err(std::io::Error::other("disk on fire"))
/// });
/// assert!(failed.is_err());
/// assert_eq!(std::fs::read(&path).unwrap(), b"hi");
/// assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1);
/// std::fs::remove_dir_all(&dir).unwrap();
/// ```
pub fn write_atomically<E: From<std::io::Error>>(
    path: &Path,
    write: impl FnOnce(&mut dyn Write) -> Result<(), E>,
) -> Result<(), E> {
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
        builder.permissions(std::fs::Permissions::from_mode(0o666));
    }
    let mut tmp = builder.tempfile_in(dir)?;
    {
        let mut out = std::io::BufWriter::new(tmp.as_file_mut());
        write(&mut out)?;
        out.flush()?;
    }
    tmp.as_file().sync_all()?;
    tmp.persist(path).map_err(|e| e.error)?;
    Ok(())
}

/// [`write_atomically`] of a byte buffer.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    write_atomically(path, |w| w.write_all(bytes))
}
