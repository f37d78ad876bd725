//! `Scene::from_toml_str` on arbitrary text (relative paths resolve against the built-in
//! scenes' directory, so the repository's meshes and URDF load): parsing and validation
//! never panic, errors name the file; a scene that parses writes back to TOML that parses
//! and writes to the same text.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;
use nbv_scenes::Scene;

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    let dir = nbv_scenes::builtin::base_dir();
    if let Err(e) = Scene::from_toml_str(&text, &dir, Path::new("fuzz.toml")) {
        assert!(e.to_string().starts_with("fuzz.toml: "), "{e}");
    }
    let Ok(mut scene) = Scene::parse(&text, Path::new("fuzz.toml")) else {
        return;
    };
    scene.resolve_paths(&dir);
    let first = scene
        .to_toml_string(&dir)
        .expect("a parsed scene serialises");
    let mut again = Scene::parse(&first, Path::new("again.toml")).expect("a written scene parses");
    again.resolve_paths(&dir);
    let second = again.to_toml_string(&dir).unwrap();
    assert_eq!(
        first, second,
        "parse → write → parse → write changed the text"
    );
});
