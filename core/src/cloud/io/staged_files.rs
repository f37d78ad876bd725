//! Output files that appear together or not at all ([`StagedFiles`]): each is written whole
//! under a temporary name beside its final path, then all are renamed into place; on any
//! failure the temporary files are removed.

use super::{CloudIoError, write_atomically};
use std::io::Write;
use std::path::{Path, PathBuf};

/// An error of [`StagedFiles`]; the message names the final path.
#[derive(Debug, thiserror::Error)]
pub enum StagedFileError {
    /// The path names no file.
    #[error("{}: not a file name", .0.display())]
    NotAFile(PathBuf),
    /// A file could not be written under its temporary name.
    #[error("cannot write {}", path.display())]
    Write {
        /// The final path.
        path: PathBuf,
        /// Why.
        #[source]
        source: Box<CloudIoError>,
    },
    /// A written file could not be moved into place.
    #[error("cannot write {}", path.display())]
    Move {
        /// The final path.
        path: PathBuf,
        /// Why.
        #[source]
        source: std::io::Error,
    },
}

/// Output files written under temporary names (`.<name>.<pid>.staged` in the same
/// directory) and moved into place together by [`commit`](Self::commit); dropped
/// uncommitted (an error on the way), it removes the files not yet moved.
///
/// ```
/// use nbv_core::cloud::io::StagedFiles;
/// use std::io::Write;
/// let dir = std::env::temp_dir().join(format!("nbv-staged-doc-{}", std::process::id()));
/// std::fs::create_dir_all(&dir).unwrap();
/// let mut staged = StagedFiles::default();
/// staged.write(&dir.join("a.txt"), |w| Ok(w.write_all(b"a")?)).unwrap();
/// staged.write(&dir.join("b.txt"), |w| Ok(w.write_all(b"b")?)).unwrap();
/// assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 2); // under temporary names
/// assert!(!dir.join("a.txt").exists());
/// staged.commit().unwrap();
/// assert_eq!(std::fs::read(dir.join("b.txt")).unwrap(), b"b");
/// // Dropped before the commit: nothing is left.
/// let mut staged = StagedFiles::default();
/// staged.write(&dir.join("c.txt"), |w| Ok(w.write_all(b"c")?)).unwrap();
/// drop(staged);
/// assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 2);
/// std::fs::remove_dir_all(&dir).unwrap();
/// ```
#[derive(Debug, Default)]
pub struct StagedFiles {
    /// (temporary path, final path), not yet moved.
    files: Vec<(PathBuf, PathBuf)>,
}

impl StagedFiles {
    /// Writes `path`'s content under a temporary name in the same directory
    /// ([`write_atomically`]).
    pub fn write(
        &mut self,
        path: &Path,
        write: impl FnOnce(&mut dyn Write) -> Result<(), CloudIoError>,
    ) -> Result<(), StagedFileError> {
        let name = path
            .file_name()
            .ok_or_else(|| StagedFileError::NotAFile(path.to_path_buf()))?;
        let temp = path.with_file_name(format!(
            ".{}.{}.staged",
            name.to_string_lossy(),
            std::process::id()
        ));
        write_atomically(&temp, write).map_err(|source| StagedFileError::Write {
            path: path.to_path_buf(),
            source: Box::new(source),
        })?;
        self.files.push((temp, path.to_path_buf()));
        Ok(())
    }

    /// Moves every staged file into place, in the order written; on a failure the rest
    /// are removed.
    pub fn commit(mut self) -> Result<(), StagedFileError> {
        while let Some((temp, path)) = self.files.first().cloned() {
            std::fs::rename(&temp, &path)
                .map_err(|source| StagedFileError::Move { path, source })?;
            self.files.remove(0);
        }
        Ok(())
    }

    /// Removes the staged files not yet moved.
    fn discard(&mut self) {
        for (temp, _) in self.files.drain(..) {
            let _ = std::fs::remove_file(temp);
        }
    }
}

impl Drop for StagedFiles {
    fn drop(&mut self) {
        self.discard();
    }
}
