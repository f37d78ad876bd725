//! A sweep directory on disk: `sweep.json` ([`SweepInfo`]), the row files of finished
//! episodes, atomic JSON writes, and the clean-up of what an interrupted run left.
//!
//! ```text
//! DIR/sweep.json               the grid (file, text, episode count) and the shard
//! DIR/episodes/<id>.row.json   one finished episode (written atomically, last)
//! DIR/episodes/<id>/           its episode outputs (report.json, models, map)
//! DIR/episodes/<id>.failed.json an episode that failed or panicked, and why (no row: a
//!                              resumed sweep runs it again)
//! DIR/results.csv              one row per finished episode, by index
//! DIR/summary.json             aggregates, best settings, registration table, gates
//! DIR/plots/*.svg              heatmap of coverage, coverage against views
//! ```

use crate::error::{Context, Result, bail};
use crate::grid::Episode;
use crate::rows::EpisodeRow;
use crate::shard::Shard;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// `DIR/sweep.json`: what a sweep directory holds.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SweepInfo {
    /// The grid file as given.
    pub grid: PathBuf,
    /// Its text (so a merge can check the shards come from the same grid).
    pub grid_text: String,
    /// Episodes in the whole grid.
    pub episodes: usize,
    /// The shard this directory ran (none: all).
    pub shard: Option<Shard>,
}

/// Whether `name` is the temporary file of an atomic write (`.NAME.<random>.tmp`, see
/// `nbv_core::atomic_file`).
fn is_temporary(name: &str) -> bool {
    name.len() > ".x..tmp".len() && name.starts_with('.') && name.ends_with(".tmp")
}

/// Removes the temporary files an interrupted run left in the sweep directory `out`, its
/// `episodes/` and its `plots/` (the episodes' own directories are emptied when they run
/// again); how many.
pub fn remove_stale_temporaries(out: &Path) -> Result<usize> {
    let mut removed = 0;
    for dir in [out.to_path_buf(), out.join("episodes"), out.join("plots")] {
        let Ok(entries) = std::fs::read_dir(&dir) else {
            continue;
        };
        for entry in entries {
            let entry = entry.with_context(|| format!("reading {}", dir.display()))?;
            let stale = entry.file_type().is_ok_and(|t| t.is_file())
                && is_temporary(&entry.file_name().to_string_lossy());
            if stale {
                std::fs::remove_file(entry.path())
                    .with_context(|| format!("removing {}", entry.path().display()))?;
                removed += 1;
            }
        }
    }
    if removed > 0 {
        tracing::info!(
            "{}: removed {removed} temporary file(s) of an interrupted run",
            out.display()
        );
    }
    Ok(removed)
}

/// `DIR/episodes/<id>.row.json`.
pub fn row_path(out: &Path, e: &Episode) -> PathBuf {
    out.join("episodes").join(format!("{}.row.json", e.id))
}

/// `value` as pretty JSON, written atomically to `path`.
pub fn write_json<T: Serialize>(path: &Path, value: &T) -> Result<()> {
    let text = serde_json::to_string_pretty(value)?;
    nbv_core::atomic_file::write_atomic(path, text.as_bytes())
        .with_context(|| format!("writing {}", path.display()))
}

/// Every row file of the directories, by index; the same id twice must be the same row.
pub fn load_rows(dirs: &[PathBuf]) -> Result<Vec<EpisodeRow>> {
    let mut rows: Vec<EpisodeRow> = Vec::new();
    for dir in dirs {
        let episodes = dir.join("episodes");
        let entries = std::fs::read_dir(&episodes)
            .with_context(|| format!("reading {}", episodes.display()))?;
        let mut paths: Vec<PathBuf> = entries
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.to_string_lossy().ends_with(".row.json"))
            .collect();
        paths.sort();
        for p in paths {
            let row = EpisodeRow::load(&p)?;
            if let Some(old) = rows.iter().find(|r| r.id == row.id) {
                let same = EpisodeRow {
                    time_s: old.time_s,
                    nbv_time_per_view: old.nbv_time_per_view,
                    ..row.clone()
                } == *old;
                if !same {
                    bail!(
                        "{}: episode {} differs from the same episode in another input",
                        p.display(),
                        row.id
                    );
                }
                continue;
            }
            rows.push(row);
        }
    }
    rows.sort_by_key(|r| r.index);
    Ok(rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stale_temporaries_are_removed_and_nothing_else() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path();
        std::fs::create_dir_all(out.join("episodes/0000-x")).unwrap();
        let stale = [
            ".results.csv.a1B2c3.tmp",
            "episodes/.0000-x.row.json.Zz9yY8.tmp",
        ];
        let kept = [
            "results.csv",
            "episodes/0000-x.row.json",
            ".hidden",
            "notes.tmp",
            // Inside an episode directory: that directory is emptied when the episode
            // runs again, and left alone when it finished.
            "episodes/0000-x/.report.json.q1w2e3.tmp",
        ];
        for f in stale.iter().chain(&kept) {
            std::fs::write(out.join(f), "x").unwrap();
        }
        // A real temporary file of the atomic writer, kept by a writer that never finished.
        let real = tempfile::Builder::new()
            .prefix(".summary.json.")
            .suffix(".tmp")
            .tempfile_in(out)
            .unwrap()
            .keep()
            .unwrap()
            .1;
        assert_eq!(remove_stale_temporaries(out).unwrap(), 3);
        assert!(!real.exists());
        for f in stale {
            assert!(!out.join(f).exists(), "{f}");
        }
        for f in kept {
            assert!(out.join(f).exists(), "{f}");
        }
        assert_eq!(remove_stale_temporaries(&out.join("missing")).unwrap(), 0);
    }
}
