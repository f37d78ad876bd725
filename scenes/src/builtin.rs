//! The built-in scenes: the paper's two environments, embedded in the crate.
//!
//! Their relative paths (`../assets/...`) resolve against [`base_dir`], the directory the
//! scene files live in within the nbv-twin source tree (this crate's directory, fixed at
//! compile time), so built-in scenes load from a checkout without copying files around.

use crate::error::SceneError;
use crate::scene::Scene;
use std::path::PathBuf;

/// `(name, text)` of every built-in scene.
pub const SCENES: [(&str, &str); 2] = [
    ("paper-env1", include_str!("../paper-env1.toml")),
    ("paper-env2", include_str!("../paper-env2.toml")),
];

/// Names of the built-in scenes.
pub fn names() -> Vec<&'static str> {
    SCENES.iter().map(|(n, _)| *n).collect()
}

/// The TOML text of a built-in scene.
pub fn text(name: &str) -> Option<&'static str> {
    SCENES.iter().find(|(n, _)| *n == name).map(|(_, t)| *t)
}

/// The directory the built-in scenes' relative paths resolve against.
pub fn base_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The repository's `assets/` directory (meshes and URDF), as seen from [`base_dir`].
pub fn assets_dir() -> PathBuf {
    crate::paths::normalize(&base_dir().join("../assets"))
}

/// Loads and validates a built-in scene.
pub fn load(name: &str) -> Result<Scene, SceneError> {
    let text = text(name).ok_or_else(|| SceneError::UnknownBuiltin {
        name: name.to_owned(),
        available: names().join(", "),
    })?;
    Scene::from_toml_str(text, &base_dir(), &base_dir().join(format!("{name}.toml")))
}
