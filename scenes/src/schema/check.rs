//! [`Check`]: the value checks every schema section's validation uses (finite, positive,
//! within a range, a non-empty interval or box, a name, a file, a watertight mesh), each
//! failing with a [`SceneError::Invalid`] that names the file, the key path and the problem.

use super::PoseSpec;
use crate::error::{Problem, SceneError};
use nbv_core::mesh::TriMesh;
use std::path::{Path, PathBuf};

/// Builds [`SceneError::Invalid`] errors for one scene file and checks common value shapes.
pub(crate) struct Check {
    /// The scene file the errors name.
    pub(crate) file: PathBuf,
}

impl Check {
    pub(crate) fn err(&self, key: impl Into<String>, problem: Problem) -> SceneError {
        SceneError::Invalid {
            file: self.file.clone(),
            key: key.into(),
            problem: Box::new(problem),
        }
    }

    pub(crate) fn finite(&self, key: &str, values: &[f64]) -> Result<(), SceneError> {
        match values.iter().find(|v| !v.is_finite()) {
            Some(v) => Err(self.err(key, Problem::NotFinite(v.to_string()))),
            None => Ok(()),
        }
    }

    pub(crate) fn positive(&self, key: &str, v: f64) -> Result<(), SceneError> {
        self.finite(key, &[v])?;
        if v > 0.0 {
            Ok(())
        } else {
            Err(self.err(key, Problem::NotPositive(v.to_string())))
        }
    }

    pub(crate) fn within(
        &self,
        key: &str,
        v: f64,
        lo: f64,
        hi: f64,
        expected: &str,
    ) -> Result<(), SceneError> {
        self.finite(key, &[v])?;
        if v >= lo && v <= hi {
            Ok(())
        } else {
            Err(self.err(
                key,
                Problem::OutOfRange {
                    value: v.to_string(),
                    expected: expected.to_owned(),
                },
            ))
        }
    }

    pub(crate) fn at_least(&self, key: &str, v: u64, lo: u64) -> Result<(), SceneError> {
        if v >= lo {
            Ok(())
        } else {
            Err(self.err(
                key,
                Problem::OutOfRange {
                    value: v.to_string(),
                    expected: format!("at least {lo}"),
                },
            ))
        }
    }

    pub(crate) fn interval(
        &self,
        key: &str,
        r: [f64; 2],
        positive: bool,
    ) -> Result<(), SceneError> {
        self.finite(key, &r)?;
        if positive && r[0] <= 0.0 {
            return Err(self.err(format!("{key}[0]"), Problem::NotPositive(r[0].to_string())));
        }
        if r[0] < r[1] {
            Ok(())
        } else {
            Err(self.err(key, Problem::EmptyRange(format!("[{}, {}]", r[0], r[1]))))
        }
    }

    pub(crate) fn boxed(&self, key: &str, min: [f64; 3], max: [f64; 3]) -> Result<(), SceneError> {
        self.finite(&format!("{key}.min"), &min)?;
        self.finite(&format!("{key}.max"), &max)?;
        for a in 0..3 {
            if min[a] >= max[a] {
                return Err(self.err(
                    format!("{key}.max"),
                    Problem::EmptyRange(format!(
                        "axis {}: min {} >= max {}",
                        ['x', 'y', 'z'][a],
                        min[a],
                        max[a]
                    )),
                ));
            }
        }
        Ok(())
    }

    pub(crate) fn pose(&self, key: &str, p: &PoseSpec) -> Result<(), SceneError> {
        self.finite(&format!("{key}.xyz"), &p.xyz)?;
        self.finite(&format!("{key}.rpy_deg"), &p.rpy_deg)
    }

    pub(crate) fn name(&self, key: &str, name: &str) -> Result<(), SceneError> {
        if name.trim().is_empty() {
            Err(self.err(key, Problem::Empty))
        } else {
            Ok(())
        }
    }

    pub(crate) fn file_exists(&self, key: &str, path: &Path) -> Result<(), SceneError> {
        if path.is_file() {
            Ok(())
        } else {
            Err(self.err(key, Problem::MissingFile(path.to_path_buf())))
        }
    }

    pub(crate) fn watertight(
        &self,
        key: &str,
        path: &Path,
        mesh: &TriMesh,
    ) -> Result<(), SceneError> {
        let detail = if !mesh.is_watertight() {
            Some("open, non-manifold or inconsistently oriented edges".to_owned())
        } else if mesh.volume().is_nan() || mesh.volume() <= 0.0 {
            Some(format!("volume {:.3e} m³", mesh.volume()))
        } else {
            None
        };
        match detail {
            Some(detail) => Err(self.err(
                key,
                Problem::NotWatertight {
                    path: path.to_path_buf(),
                    detail,
                },
            )),
            None => Ok(()),
        }
    }
}
