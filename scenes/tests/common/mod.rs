//! Helpers shared by the integration tests of nbv-scenes.

#![allow(dead_code)]

use nbv_scenes::Scene;
use std::path::{Path, PathBuf};

/// The robot's URDF (validation loads it as a kinematic model).
pub fn fixture_urdf() -> PathBuf {
    nbv_scenes::paths::normalize(&std::path::PathBuf::from(nbv_core::kinematics::COMAU_URDF))
}

/// A built-in scene's text with its robot URDF pointed at the fixture.
pub fn builtin_text_with_fixture(name: &str) -> String {
    nbv_scenes::builtin::text(name).unwrap().replace(
        "\"../assets/urdf/comau_smart_six.urdf\"",
        &format!("{:?}", fixture_urdf().display().to_string()),
    )
}

/// Loads a built-in scene with the fixture URDF.
pub fn builtin_with_fixture(name: &str) -> Result<Scene, nbv_scenes::SceneError> {
    Scene::from_toml_str(
        &builtin_text_with_fixture(name),
        &nbv_scenes::builtin::base_dir(),
        Path::new(&format!("{name}.toml")),
    )
}

/// Loads scene text as the file `bad.toml` beside the built-in scenes (the bad-input tests).
pub fn load_as_bad(text: &str) -> Result<Scene, nbv_scenes::SceneError> {
    Scene::from_toml_str(
        text,
        &nbv_scenes::builtin::base_dir(),
        Path::new("bad.toml"),
    )
}

/// paper-env1's text with the fixture URDF.
pub fn env1() -> String {
    builtin_text_with_fixture("paper-env1")
}
