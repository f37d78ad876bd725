//! The rig-file reader on stable Rust (CI cannot run the cargo-fuzz target
//! `fuzz/fuzz_targets/rig_file.rs`): arbitrary bytes and damaged rig files (dropped lines,
//! i.e. missing keys; repeated lines; numbers replaced by NaN, infinities, negative, huge
//! or wrongly typed values; truncations and inserted garbage) never panic in
//! `RigFile::parse` nor in `mount_sensors`, and every error names the file and the key or
//! line.
#![cfg(feature = "hw")]

use std::path::Path;

use nbv_core::kinematics::Robot;
use nbv_hw::rig_file::{RigFile, RigFileError};
use proptest::prelude::*;
use proptest::sample::Index;

/// A rig file with every key set.
const FULL: &str = r#"# full rig
[arm]
address = "192.168.1.10:12345"
timeout_s = 2.0
sample_timeout_s = 0.5
connect_attempts = 3
joint_sign = [1, 1, -1, 1, 1, 1]
joint_offset_deg = [0, 0, 0.5, 0, 0, 0]

[laser]
address = "192.168.0.1:2111"
timeout_s = 1.0
connect_attempts = 2
clock_offset_s = 0.001
hand_eye = { parent = "tool0", xyz = [0.0, -0.09, 0.06], rpy = [0.0, 0.0, 0.1] }

[camera]
usb = "2:5"
timeout_s = 1.0
clock_offset_s = -0.002
hand_eye = { parent = "tool0", xyz = [0.0, 0.07, 0.05], rpy = [0.0, 0.1, 0.0] }
"#;

fn parse(text: &str) -> Result<RigFile, RigFileError> {
    RigFile::parse(text, Path::new("rig.toml"))
}

fn robot() -> Robot {
    nbv_core::kinematics::comau_smart_six().unwrap()
}

/// Parses and, if that works, mounts the sensors; every error must name the file.
fn use_rig(text: &str, robot: &Robot) {
    match parse(text) {
        Ok(rig) => {
            let mut robot = robot.clone();
            if let Err(e) = rig.mount_sensors(&mut robot, "lms400", "dinast") {
                let msg = e.to_string();
                assert!(msg.starts_with("rig.toml: "), "{msg}");
                assert!(msg.contains(".hand_eye"), "{msg}");
            }
        }
        Err(e) => {
            let msg = e.to_string();
            assert!(msg.starts_with("rig.toml: "), "{msg}");
        }
    }
}

#[test]
fn the_full_rig_file_parses_and_mounts() {
    let rig = parse(FULL).unwrap();
    rig.mount_sensors(&mut robot(), "lms400", "dinast").unwrap();
}

#[test]
fn errors_name_the_file_and_the_key_or_line() {
    let cases: [(&str, &str, &[&str]); 9] = [
        // Missing keys.
        (
            "address = \"192.168.0.1:2111\"\n",
            "",
            &["missing field `address`", "laser"],
        ),
        ("[laser]\n", "", &["line"]),
        // Wrong types, with the key and its line.
        (
            "timeout_s = 2.0",
            "timeout_s = \"2\"",
            &["timeout_s", "line 4", "string"],
        ),
        (
            "connect_attempts = 3",
            "connect_attempts = -3",
            &["connect_attempts", "line 6"],
        ),
        (
            "joint_sign = [1, 1, -1, 1, 1, 1]",
            "joint_sign = [1, 1]",
            &["joint_sign", "line 7"],
        ),
        // Bad values, with the dotted key.
        (
            "clock_offset_s = 0.001",
            "clock_offset_s = nan",
            &["laser.clock_offset_s", "finite"],
        ),
        (
            "timeout_s = 1.0\nclock_offset_s = -0.002",
            "timeout_s = inf\nclock_offset_s = -0.002",
            &["camera.timeout_s", "inf"],
        ),
        (
            "rpy = [0.0, 0.1, 0.0]",
            "rpy = [0.0, -inf, 0.0]",
            &["camera.hand_eye", "finite"],
        ),
        (
            "usb = \"2:5\"",
            "usb = \"2:99999\"",
            &["usb", "BUS:ADDRESS"],
        ),
    ];
    for (from, to, wanted) in cases {
        let text = FULL.replacen(from, to, 1);
        assert_ne!(text, FULL, "{from}: the edit did not apply");
        let msg = parse(&text).unwrap_err().to_string();
        assert!(msg.starts_with("rig.toml: "), "{msg}");
        for w in wanted {
            assert!(
                msg.contains(w),
                "{from} → {to}: `{msg}` does not mention {w}"
            );
        }
    }
    // A hand-eye frame the robot cannot mount on.
    let text = FULL.replacen("parent = \"tool0\"", "parent = \"nowhere\"", 1);
    let e = parse(&text)
        .unwrap()
        .mount_sensors(&mut robot(), "lms400", "dinast")
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("rig.toml: laser.hand_eye: "), "{e}");
    // Through a file: the error names its path.
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("cut.toml");
    std::fs::write(&path, &FULL[..FULL.len() / 2]).unwrap();
    let e = RigFile::load(&path).unwrap_err().to_string();
    assert!(e.starts_with(&path.display().to_string()), "{e}");
}

/// Texts a number is replaced with: non-finite, negative, zero, huge and wrong types.
const REPLACEMENTS: &[&str] = &[
    "nan",
    "inf",
    "-inf",
    "-1",
    "0",
    "1e308",
    "4294967296",
    "99999999999999999999",
    "\"x\"",
    "true",
    "[]",
    "{}",
    "",
];

#[derive(Debug, Clone)]
enum Edit {
    DropLine(Index),
    RepeatLine(Index),
    Number(Index, usize),
    Insert(Index, String),
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

fn apply(text: &mut String, edit: &Edit) {
    let lines: Vec<(usize, usize)> = text
        .split_inclusive('\n')
        .scan(0, |at, l| {
            let r = (*at, *at + l.len());
            *at += l.len();
            Some(r)
        })
        .collect();
    let boundary = |t: &str, mut i: usize| {
        while !t.is_char_boundary(i) {
            i -= 1;
        }
        i
    };
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
                if (b[p].is_ascii_digit() || b[p] == b'-')
                    && (p == 0 || matches!(b[p - 1], b' ' | b'[' | b','))
                {
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
            let at = boundary(text, i.index(text.len() + 1));
            text.insert_str(at, s);
        }
        Edit::Truncate(i) => {
            let at = boundary(text, i.index(text.len() + 1));
            text.truncate(at);
        }
        _ => {}
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn arbitrary_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..512)) {
        use_rig(&String::from_utf8_lossy(&bytes), &robot());
    }

    #[test]
    fn damaged_rig_files_never_panic(edits in edits()) {
        let mut text = FULL.to_owned();
        for e in &edits {
            apply(&mut text, e);
        }
        use_rig(&text, &robot());
    }
}
