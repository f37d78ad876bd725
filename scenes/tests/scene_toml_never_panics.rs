//! The scene TOML reader on stable Rust (CI cannot run the cargo-fuzz target
//! `fuzz/fuzz_targets/scene_toml.rs`): arbitrary bytes and damaged scene files (dropped
//! lines, i.e. missing keys; repeated lines; numbers replaced by NaN, infinities, negative,
//! huge or wrongly typed values; truncations and inserted garbage) never panic, errors name
//! the file and the key or line, and a scene that parses writes back to TOML that parses
//! to the same scene.

mod common;

use std::path::Path;

use nbv_scenes::{Problem, Scene, SceneError};
use proptest::prelude::*;
use proptest::sample::Index;

use common::{env1, load_as_bad as load};

/// Texts a number is replaced with: non-finite, negative, zero, huge and wrong types.
const REPLACEMENTS: &[&str] = &[
    "nan",
    "inf",
    "-inf",
    "-1",
    "0",
    "1e308",
    "4294967296",
    "9223372036854775807",
    "99999999999999999999",
    "\"x\"",
    "true",
    "[]",
    "{}",
    "",
];

/// One edit of the scene text.
#[derive(Debug, Clone)]
enum Edit {
    /// Remove one line (a missing key or section header).
    DropLine(Index),
    /// Repeat one line (a duplicate key).
    RepeatLine(Index),
    /// Replace one number with one of [`REPLACEMENTS`].
    Number(Index, usize),
    /// Insert printable garbage.
    Insert(Index, String),
    /// Cut the text.
    Truncate(Index),
}

fn edits() -> impl Strategy<Value = Vec<Edit>> {
    let edit = prop_oneof![
        any::<Index>().prop_map(Edit::DropLine),
        any::<Index>().prop_map(Edit::RepeatLine),
        (any::<Index>(), 0..REPLACEMENTS.len()).prop_map(|(i, r)| Edit::Number(i, r)),
        (any::<Index>(), "[ -~\n]{1,16}").prop_map(|(i, s)| Edit::Insert(i, s)),
        any::<Index>().prop_map(Edit::Truncate),
    ];
    proptest::collection::vec(edit, 1..4)
}

fn floor_boundary(text: &str, mut i: usize) -> usize {
    while !text.is_char_boundary(i) {
        i -= 1;
    }
    i
}

fn apply(text: &mut String, edit: &Edit) {
    let lines: Vec<(usize, usize)> = text
        .split_inclusive('\n')
        .scan(0, |at, l| {
            let r = (*at, *at + l.len());
            *at += l.len();
            Some(r)
        })
        .collect();
    match edit {
        Edit::DropLine(i) | Edit::RepeatLine(i) if !lines.is_empty() => {
            let (a, b) = lines[i.index(lines.len())];
            if matches!(edit, Edit::DropLine(_)) {
                text.replace_range(a..b, "");
            } else {
                let line = text[a..b].to_owned();
                text.insert_str(a, &line);
            }
        }
        Edit::Number(i, k) => {
            let b = text.as_bytes();
            let mut spans = Vec::new();
            let mut p = 0;
            while p < b.len() {
                let starts = (b[p].is_ascii_digit() || b[p] == b'-')
                    && (p == 0 || matches!(b[p - 1], b' ' | b'[' | b','));
                if starts {
                    let mut q = p + 1;
                    while q < b.len() && matches!(b[q], b'0'..=b'9' | b'.' | b'e' | b'-' | b'+') {
                        q += 1;
                    }
                    spans.push(p..q);
                    p = q;
                } else {
                    p += 1;
                }
            }
            if !spans.is_empty() {
                let r = spans[i.index(spans.len())].clone();
                text.replace_range(r, REPLACEMENTS[*k]);
            }
        }
        Edit::Insert(i, s) => {
            let at = floor_boundary(text, i.index(text.len() + 1));
            text.insert_str(at, s);
        }
        Edit::Truncate(i) => {
            let at = floor_boundary(text, i.index(text.len() + 1));
            text.truncate(at);
        }
        _ => {}
    }
}

/// A scene that parses must serialise, and its TOML must parse to the same TOML again
/// (compared as text so that NaN, which `validate` would reject, compares equal).
fn round_trips(text: &str) {
    let Ok(mut scene) = Scene::parse(text, Path::new("s.toml")) else {
        return;
    };
    let dir = nbv_scenes::builtin::base_dir();
    scene.resolve_paths(&dir);
    let first = scene
        .to_toml_string(&dir)
        .unwrap_or_else(|e| panic!("a parsed scene serialises: {e}"));
    let mut again = Scene::parse(&first, Path::new("s.toml"))
        .unwrap_or_else(|e| panic!("a written scene parses: {e}\n{first}"));
    again.resolve_paths(&dir);
    let second = again.to_toml_string(&dir).unwrap();
    assert_eq!(
        first, second,
        "parse → write → parse → write changed the text"
    );
}

/// Checks an error's text starts with the file name.
fn names_the_file(e: &SceneError) {
    let msg = e.to_string();
    assert!(msg.starts_with("bad.toml: "), "{msg}");
}

#[test]
fn missing_keys_and_wrong_types_name_the_key_and_line() {
    let cases: [(&str, &str, &[&str]); 6] = [
        // A missing key: the section and the key.
        (
            "min = [0.30, -0.70, 0.23]\n",
            "",
            &["missing field `min`", "workspace"],
        ),
        ("name = \"jug\"\n", "", &["missing field `name`", "line"]),
        // Wrong types: the key and its line.
        (
            "seed = 2014",
            "seed = \"x\"",
            &["seed", "line 12", "string"],
        ),
        (
            "fov_deg = 80.0",
            "fov_deg = [80.0]",
            &["fov_deg", "line", "sequence"],
        ),
        // Out of the type's range.
        ("width = 320", "width = 4294967296", &["width", "line"]),
        ("seed = 2014", "seed = -1", &["seed", "line 12"]),
    ];
    for (from, to, wanted) in cases {
        let text = env1().replacen(from, to, 1);
        assert_ne!(text, env1(), "{from}: the edit did not apply");
        let e = load(&text).unwrap_err();
        assert!(matches!(e, SceneError::Parse { .. }), "{from}: {e}");
        names_the_file(&e);
        let msg = e.to_string();
        for w in wanted {
            assert!(
                msg.contains(w),
                "{from} → {to}: `{msg}` does not mention {w}"
            );
        }
    }
}

#[test]
fn bad_values_name_the_key() {
    let cases: [(&str, &str, &str); 4] = [
        (
            "resolution = 0.02",
            "resolution = nan",
            "workspace.resolution",
        ),
        (
            "fov_deg = 80.0",
            "fov_deg = inf",
            "sensors.short_range.fov_deg",
        ),
        ("width = 320", "width = 0", "sensors.short_range.width"),
        (
            "rest_tolerance = 0.002",
            "rest_tolerance = -1e308",
            "layout.rest_tolerance",
        ),
    ];
    for (from, to, key) in cases {
        let text = env1().replacen(from, to, 1);
        assert_ne!(text, env1(), "{from}: the edit did not apply");
        let e = load(&text).unwrap_err();
        names_the_file(&e);
        assert!(
            matches!(&e, SceneError::Invalid { key: k, .. } if k == key),
            "{to}: {e}"
        );
    }
}

#[test]
fn a_huge_grid_is_refused_before_anything_is_allocated() {
    // 1.2 × 1.4 × 0.6 m at 1 nm: about 10^24 voxels.
    let text = env1().replacen("resolution = 0.02", "resolution = 0.000000001", 1);
    // (Were it allocated, the test binary would abort.)
    let e = load(&text).unwrap_err();
    assert!(
        matches!(&e, SceneError::Invalid { key, problem, .. }
            if key == "workspace" && matches!(**problem, Problem::GridTooLarge(_))),
        "{e}"
    );
}

#[test]
fn builtin_scenes_round_trip() {
    for name in nbv_scenes::builtin::names() {
        round_trips(&common::builtin_text_with_fixture(name));
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn arbitrary_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..512)) {
        let text = String::from_utf8_lossy(&bytes);
        if let Err(e) = load(&text) {
            names_the_file(&e);
        }
        round_trips(&text);
    }

    #[test]
    fn damaged_scenes_never_panic(edits in edits()) {
        let mut text = env1();
        for e in &edits {
            apply(&mut text, e);
        }
        if let Err(e) = load(&text) {
            names_the_file(&e);
        }
        round_trips(&text);
    }
}
