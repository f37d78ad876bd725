//! Scene overrides: a scene with some of its dotted keys set (`nbv explore --set
//! nbv.radius=0.45`, a sweep's `[params]`), checked by the scene's own validation; and
//! [`load`], a scene by path or by built-in name.

use crate::{Scene, SceneError};
use std::path::Path;

/// Why overriding or loading a scene failed.
#[derive(Debug, thiserror::Error)]
pub enum OverrideError {
    /// The scene (or its `[nbv]` section) could not be turned into TOML.
    #[error("{what} to TOML")]
    ToToml {
        /// `scene` or `[nbv]`.
        what: &'static str,
        /// The serialiser's error.
        #[source]
        source: toml::ser::Error,
    },
    /// `nbv.preset` names no preset.
    #[error("{origin}: `{key}` = {value}")]
    Preset {
        /// Where the overrides came from (`--set`, a grid file).
        origin: String,
        /// The key.
        key: String,
        /// The value given.
        value: String,
        /// The parser's error (boxed to keep the error small).
        #[source]
        source: Box<toml::de::Error>,
    },
    /// A dotted key the scene does not have.
    #[error("{origin}: `{key}`")]
    Key {
        /// Where the overrides came from.
        origin: String,
        /// The key.
        key: String,
        /// What is wrong with it.
        #[source]
        source: KeyError,
    },
    /// The overridden scene is not valid, or a scene file failed to load.
    #[error(transparent)]
    Scene(Box<SceneError>),
    /// A built-in scene failed to load.
    #[error("built-in scene {name}")]
    Builtin {
        /// Its name.
        name: String,
        /// Why.
        #[source]
        source: Box<SceneError>,
    },
    /// Neither a file nor a built-in scene.
    #[error("{name}: no such file, and no built-in scene of that name (built-in: {available})")]
    NotFound {
        /// What was asked for.
        name: String,
        /// The built-in names, comma separated.
        available: String,
    },
}

impl From<SceneError> for OverrideError {
    fn from(e: SceneError) -> Self {
        Self::Scene(Box::new(e))
    }
}

/// What is wrong with a dotted key ([`set_dotted`]).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum KeyError {
    /// A part on the way is a value, not a table.
    #[error("`{0}` is not a table")]
    NotATable(String),
    /// The last part names no key of its table.
    #[error("the scene has no key `{0}`")]
    NoKey(String),
    /// A part on the way names no table.
    #[error("the scene has no table `{0}`")]
    NoTable(String),
}

/// `base` with each dotted key set to its value (`nbv explore --set`, a sweep's
/// `[params]`), in order, checked by the scene's own validation so a bad key or value names
/// itself; `nbv.preset`, wherever it stands, first resets every `[nbv]` value to the
/// preset's, and the other keys apply on top (a sweep orders its keys alphabetically);
/// `origin` says where the overrides came from, `name` names the result in errors.
pub fn with_overrides(
    base: &Scene,
    overrides: &[(String, toml::Value)],
    origin: &str,
    name: &str,
) -> Result<Scene, OverrideError> {
    if overrides.is_empty() {
        return Ok(base.clone());
    }
    let to_toml = |what| move |source| OverrideError::ToToml { what, source };
    let mut value = toml::Value::try_from(base).map_err(to_toml("scene"))?;
    let presets_first = overrides
        .iter()
        .filter(|(k, _)| k == "nbv.preset")
        .chain(overrides.iter().filter(|(k, _)| k != "nbv.preset"));
    for (key, v) in presets_first {
        if key == "nbv.preset" {
            // A preset replaces every `[nbv]` value (the other keys apply on top).
            let preset: crate::schema::NbvPreset =
                v.clone()
                    .try_into()
                    .map_err(|source| OverrideError::Preset {
                        origin: origin.to_string(),
                        key: key.clone(),
                        value: v.to_string(),
                        source: Box::new(source),
                    })?;
            let values = toml::Value::try_from(crate::schema::Nbv::preset(preset))
                .map_err(to_toml("[nbv]"))?;
            if let Some(table) = value.as_table_mut() {
                table.insert("nbv".into(), values);
            }
            continue;
        }
        set_dotted(&mut value, key, v.clone()).map_err(|source| OverrideError::Key {
            origin: origin.to_string(),
            key: key.clone(),
            source,
        })?;
    }
    let text = toml::to_string(&value).map_err(to_toml("scene"))?;
    // The base scene's file paths are already resolved (absolute, or relative to the
    // working directory), so they are read back against the working directory.
    Ok(Scene::from_toml_str(
        &text,
        Path::new("."),
        Path::new(name),
    )?)
}

/// The scene a single run uses: `scene` (path or built-in name) with the `--set` overrides
/// and, if given, the `--seed`.
pub fn load_for_run(
    scene: &str,
    set: &[(String, toml::Value)],
    seed: Option<u64>,
) -> Result<Scene, OverrideError> {
    let mut s = with_overrides(&load(scene)?, set, "--set", &format!("{scene} with --set"))?;
    if let Some(seed) = seed {
        s.seed = seed;
    }
    Ok(s)
}

/// Parses `KEY=VALUE` of `--set`: a dotted scene key and a TOML value (`0.45`, `16`,
/// `"kl"`, `[1, 2]`; a bare word is taken as a string).
pub fn parse_override(text: &str) -> Result<(String, toml::Value), String> {
    let (key, value) = text
        .split_once('=')
        .ok_or_else(|| format!("`{text}`: expected KEY=VALUE (e.g. nbv.radius=0.45)"))?;
    let key = key.trim();
    if key.is_empty() || !key.contains('.') {
        return Err(format!(
            "`{key}` is not a dotted scene key (e.g. nbv.radius)"
        ));
    }
    let value = value.trim();
    let parsed = toml::from_str::<toml::Table>(&format!("v = {value}"))
        .ok()
        .and_then(|mut t| t.remove("v"))
        .unwrap_or_else(|| toml::Value::String(value.to_string()));
    Ok((key.to_string(), parsed))
}

/// A scene from a path, or a built-in one by name when no such file exists.
pub fn load(scene: &str) -> Result<Scene, OverrideError> {
    let path = Path::new(scene);
    if !path.exists() && crate::builtin::text(scene).is_some() {
        return crate::builtin::load(scene).map_err(|source| OverrideError::Builtin {
            name: scene.to_string(),
            source: Box::new(source),
        });
    }
    if !path.exists() {
        return Err(OverrideError::NotFound {
            name: scene.to_string(),
            available: crate::builtin::names().join(", "),
        });
    }
    Ok(Scene::load(path)?)
}

/// Sets `a.b.c` in a TOML table; every table on the way must exist (a typo is an error
/// rather than a new, ignored key).
pub fn set_dotted(root: &mut toml::Value, key: &str, value: toml::Value) -> Result<(), KeyError> {
    let parts: Vec<&str> = key.split('.').collect();
    let mut at = root;
    for (k, part) in parts.iter().enumerate() {
        let table = at
            .as_table_mut()
            .ok_or_else(|| KeyError::NotATable(parts[..k].join(".")))?;
        if k + 1 == parts.len() {
            if !table.contains_key(*part) {
                return Err(KeyError::NoKey(key.to_string()));
            }
            table.insert((*part).to_string(), value);
            return Ok(());
        }
        at = table
            .get_mut(*part)
            .ok_or_else(|| KeyError::NoTable(parts[..=k].join(".")))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The chain of an error's messages, as a front end prints it.
    fn chain(e: &dyn std::error::Error) -> String {
        let mut s = e.to_string();
        let mut at = e.source();
        while let Some(c) = at {
            s += &format!(": {c}");
            at = c.source();
        }
        s
    }

    #[test]
    fn dotted_keys_must_exist() {
        let mut v: toml::Value = toml::from_str("[nbv]\nalpha_u = 4.0").unwrap();
        set_dotted(&mut v, "nbv.alpha_u", toml::Value::Float(2.0)).unwrap();
        assert_eq!(v["nbv"]["alpha_u"], toml::Value::Float(2.0));
        let e = set_dotted(&mut v, "nbv.alpha_x", toml::Value::Float(2.0)).unwrap_err();
        assert!(e.to_string().contains("no key `nbv.alpha_x`"));
        let e = set_dotted(&mut v, "nvb.alpha_u", toml::Value::Float(2.0)).unwrap_err();
        assert!(e.to_string().contains("no table `nvb`"));
        let e = set_dotted(&mut v, "nbv.alpha_u.x", toml::Value::Float(2.0)).unwrap_err();
        assert_eq!(e, KeyError::NotATable("nbv.alpha_u".into()));
    }

    #[test]
    fn overrides_keep_the_paths_of_a_scene_file_given_relative() {
        // Tests run in the package root (scenes/), where the scene files are.
        let base = load("paper-env1.toml").unwrap();
        let set = [parse_override("nbv.radius=0.45").unwrap()];
        let s = with_overrides(&base, &set, "--set", "env1 with --set").unwrap();
        assert_eq!(s.nbv.radius, 0.45);
        assert_eq!(s.robot.urdf, base.robot.urdf);
        assert!(s.robot.urdf.exists(), "{}", s.robot.urdf.display());
        for (a, b) in s.objects.iter().zip(&base.objects) {
            assert_eq!(a.mesh, b.mesh);
        }
    }

    #[test]
    fn a_preset_replaces_the_nbv_section_and_the_other_keys_apply_on_top() {
        use crate::schema::{Nbv, NbvPreset};
        let base = load("paper-env1").unwrap();
        let set = [
            parse_override("nbv.alpha_u=2").unwrap(),
            parse_override("nbv.preset=paper").unwrap(),
            parse_override("nbv.alpha_o=3").unwrap(),
        ];
        let s = with_overrides(&base, &set, "--set", "env1").unwrap();
        // alpha_u=2 came before the preset and still applies: a sweep's keys are in
        // alphabetical order, where `nbv.alpha_u` precedes `nbv.preset`.
        let expected = Nbv {
            alpha_u: 2.0,
            alpha_o: 3.0,
            ..Nbv::preset(NbvPreset::Paper)
        };
        assert_eq!(s.nbv, expected);
        let e = with_overrides(
            &base,
            &[parse_override("nbv.preset=papr").unwrap()],
            "--set",
            "e",
        )
        .unwrap_err();
        assert!(
            chain(&e).contains("unknown variant `papr`"),
            "{}",
            chain(&e)
        );
        let e = with_overrides(
            &base,
            &[parse_override("nbv.radious=1").unwrap()],
            "grid.toml",
            "e",
        )
        .unwrap_err();
        assert_eq!(
            chain(&e),
            "grid.toml: `nbv.radious`: the scene has no key `nbv.radious`"
        );
    }

    #[test]
    fn unknown_names_list_the_built_in_scenes() {
        let e = load("no-such-scene").unwrap_err();
        assert!(chain(&e).starts_with("no-such-scene: no such file"));
        assert!(chain(&e).contains("paper-env1"));
    }

    #[test]
    fn overrides_parse_as_toml_values_or_words() {
        let p = |t: &str| parse_override(t).unwrap();
        assert_eq!(
            p("nbv.radius=0.45"),
            ("nbv.radius".into(), toml::Value::Float(0.45))
        );
        assert_eq!(p("nbv.rolls = 4").1, toml::Value::Integer(4));
        assert_eq!(
            p("nbv.gain_measure=eq5").1,
            toml::Value::String("eq5".into())
        );
        assert_eq!(
            p("nbv.gain_measure=\"kl\"").1,
            toml::Value::String("kl".into())
        );
        assert!(parse_override("radius=1").unwrap_err().contains("dotted"));
        assert!(
            parse_override("nbv.radius")
                .unwrap_err()
                .contains("KEY=VALUE")
        );
    }
}
