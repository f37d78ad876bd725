//! [`Scene`]: a whole scene file — parsing, path resolution, validation and saving.

use crate::error::SceneError;
use crate::paths::{normalize, relative_to};
use crate::schema::*;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// A scene: the world, the rig and every parameter of an episode.
///
/// After [`Scene::load`] (or [`Scene::from_toml_str`]) every file path in the scene is
/// resolved against the scene file's directory, and the scene is validated.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// Scene name. Required.
    pub name: String,
    /// Free text. Default empty.
    #[serde(default)]
    pub description: String,
    /// Master seed of the episode (sensor noise, pose errors, planner); ≤ 2^63 − 1.
    /// Default 2014.
    #[serde(default = "default_seed")]
    pub seed: u64,
    /// The occupancy-grid box. Required.
    pub workspace: Workspace,
    /// The robot. Required.
    pub robot: RobotSpec,
    /// The table. Required.
    pub table: Table,
    /// Objects to explore (`[[objects]]`), at least one. Required.
    pub objects: Vec<ObjectSpec>,
    /// Obstacles (`[[obstacles]]`). Default none.
    #[serde(default)]
    pub obstacles: Vec<ObstacleSpec>,
    /// Placement tolerances checked on load.
    #[serde(default)]
    pub layout: Layout,
    /// Sensor models.
    #[serde(default)]
    pub sensors: Sensors,
    /// Phase-1 laser sweep.
    #[serde(default)]
    pub sweep: Sweep,
    /// Occupancy grid updates.
    #[serde(default)]
    pub mapping: Mapping,
    /// Phase-1 segmentation.
    #[serde(default)]
    pub segmentation: Segmentation,
    /// Next-best-view search.
    #[serde(default)]
    pub nbv: Nbv,
    /// Motion planner.
    #[serde(default)]
    pub planner: Planner,
    /// Global registration.
    #[serde(default)]
    pub registration: Registration,
    /// Errors injected into reported poses.
    #[serde(default)]
    pub errors: ErrorModel,
    /// The fused surface of each object.
    #[serde(default)]
    pub model: Model,
    /// The file the scene came from (`None` for a scene built in memory). Not serialised.
    #[serde(skip)]
    pub source: Option<PathBuf>,
}

fn default_seed() -> u64 {
    2014
}

impl Scene {
    /// Reads, parses and validates a scene file; relative paths are resolved against the
    /// file's directory.
    pub fn load(path: &Path) -> Result<Scene, SceneError> {
        let text = std::fs::read_to_string(path).map_err(|source| SceneError::Io {
            file: path.to_path_buf(),
            source,
        })?;
        let base = match path.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        let mut scene = Self::parse(&text, path)?;
        scene.resolve_paths(&base);
        scene.source = Some(path.to_path_buf());
        scene.validate()?;
        Ok(scene)
    }

    /// Parses and validates scene text; `base_dir` resolves relative paths and `name`
    /// names the text in errors.
    ///
    /// ```
    /// use nbv_scenes::{Problem, Scene, SceneError};
    /// let text = nbv_scenes::builtin::text("paper-env1").unwrap().replace("0.02\n", "0.03\n");
    /// let dir = nbv_scenes::builtin::base_dir();
    /// let err = Scene::from_toml_str(&text, &dir, "env.toml".as_ref()).unwrap_err();
    /// match &err {
    ///     SceneError::Invalid { problem, .. } => {
    ///         assert!(matches!(**problem, Problem::ResolutionNotDividing { axis: 'y', .. }))
    ///     }
    ///     other => panic!("{other}"),
    /// }
    /// assert!(err.to_string().starts_with("env.toml: `workspace.resolution`"));
    /// ```
    pub fn from_toml_str(text: &str, base_dir: &Path, name: &Path) -> Result<Scene, SceneError> {
        let mut scene = Self::parse(text, name)?;
        scene.resolve_paths(base_dir);
        scene.source = Some(name.to_path_buf());
        scene.validate()?;
        Ok(scene)
    }

    /// Parses without resolving or validating (for tools that fix scenes up).
    pub fn parse(text: &str, name: &Path) -> Result<Scene, SceneError> {
        toml::from_str(text).map_err(|e| SceneError::Parse {
            file: name.to_path_buf(),
            message: e.to_string().trim_end().to_owned(),
        })
    }

    /// Makes every relative path absolute-ish: `base_dir/path`, lexically normalised.
    pub fn resolve_paths(&mut self, base_dir: &Path) {
        let fix = |p: &mut PathBuf| {
            if p.is_relative() {
                *p = normalize(&base_dir.join(&*p));
            }
        };
        fix(&mut self.robot.urdf);
        self.objects.iter_mut().for_each(|o| fix(&mut o.mesh));
        self.obstacles
            .iter_mut()
            .filter_map(|o| o.mesh.as_mut())
            .for_each(fix);
    }

    /// Checks every value (see [`crate::validate`]).
    pub fn validate(&self) -> Result<(), SceneError> {
        crate::validate::validate(self)
    }

    /// The scene as TOML, with file paths written relative to `dir` (the directory the
    /// text will be saved in) where possible.
    pub fn to_toml_string(&self, dir: &Path) -> Result<String, SceneError> {
        let mut copy = self.clone();
        let rel = |p: &mut PathBuf| *p = relative_to(p, dir);
        rel(&mut copy.robot.urdf);
        copy.objects.iter_mut().for_each(|o| rel(&mut o.mesh));
        copy.obstacles
            .iter_mut()
            .filter_map(|o| o.mesh.as_mut())
            .for_each(rel);
        toml::to_string(&copy).map_err(|e| SceneError::Serialize {
            file: dir.to_path_buf(),
            message: e.to_string(),
        })
    }

    /// Writes the scene as TOML to `path`, atomically (temporary file, then rename), with
    /// paths relative to the file's directory.
    pub fn save(&self, path: &Path) -> Result<(), SceneError> {
        let dir = match path.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        let text = self.to_toml_string(&dir).map_err(|e| match e {
            SceneError::Serialize { message, .. } => SceneError::Serialize {
                file: path.to_path_buf(),
                message,
            },
            other => other,
        })?;
        crate::paths::write_atomic(path, text.as_bytes()).map_err(|source| SceneError::Io {
            file: path.to_path_buf(),
            source,
        })
    }

    /// Display name of the scene's file for messages.
    pub(crate) fn file(&self) -> PathBuf {
        self.source
            .clone()
            .unwrap_or_else(|| PathBuf::from("<scene>"))
    }
}
