//! Every kind of bad scene gives a typed error naming the key and the problem — never a
//! panic, even on random or mutated input.

mod common;

use nbv_scenes::{Problem, Scene, SceneError};
use proptest::prelude::*;
use std::path::Path;

use common::{env1, load_as_bad as check};

fn invalid(text: &str) -> (String, Problem) {
    match check(text) {
        Err(SceneError::Invalid { key, problem, .. }) => (key, *problem),
        other => panic!("expected an invalid value, got {other:?}"),
    }
}

#[test]
fn unknown_key_is_a_parse_error_with_position() {
    let text = env1().replace("[table]\n", "[table]\ncolour = \"red\"\n");
    let err = check(&text).unwrap_err();
    let msg = err.to_string();
    assert!(matches!(err, SceneError::Parse { .. }));
    assert!(msg.starts_with("bad.toml: "), "{msg}");
    assert!(msg.contains("colour") && msg.contains("line"), "{msg}");
}

#[test]
fn missing_mesh_names_the_key_and_file() {
    let text = env1().replace("meshes/mallet.stl", "meshes/nothing.stl");
    let (key, problem) = invalid(&text);
    assert_eq!(key, "objects[1].mesh");
    assert!(matches!(problem, Problem::MissingFile(ref p) if p.ends_with("nothing.stl")));
}

#[test]
fn nan_and_infinity_are_rejected() {
    let text = env1().replace("xyz = [0.74, -0.20, 0.25]", "xyz = [nan, -0.20, 0.25]");
    let (key, problem) = invalid(&text);
    assert_eq!(key, "objects[1].pose.xyz");
    assert!(matches!(problem, Problem::NotFinite(_)));
    let text = env1().replace("p_hit = 0.7", "p_hit = inf");
    assert_eq!(invalid(&text).0, "mapping.p_hit");
}

#[test]
fn object_outside_workspace() {
    let text = env1().replace("xyz = [0.88, 0.02, 0.25]", "xyz = [0.88, 0.68, 0.25]");
    let (key, problem) = invalid(&text);
    assert_eq!(key, "objects[2].pose.xyz");
    assert!(
        matches!(problem, Problem::OutsideWorkspace { .. }),
        "{problem}"
    );
}

#[test]
fn object_floating_or_sunk() {
    let text = env1().replace("xyz = [0.88, 0.02, 0.25]", "xyz = [0.88, 0.02, 0.30]");
    let (key, problem) = invalid(&text);
    assert_eq!(key, "objects[2].pose.xyz");
    assert!(matches!(problem, Problem::NotOnTable { .. }));
    // Tilted by 20° about its base centre: the rim sinks into the table.
    let text = env1().replace(
        "xyz = [0.88, 0.02, 0.25], rpy_deg = [0.0, 0.0, 0.0]",
        "xyz = [0.88, 0.02, 0.25], rpy_deg = [20.0, 0.0, 0.0]",
    );
    assert!(matches!(invalid(&text).1, Problem::NotOnTable { .. }));
}

#[test]
fn overlapping_and_close_objects() {
    let text = env1().replace("xyz = [0.88, 0.02, 0.25]", "xyz = [0.70, 0.20, 0.25]");
    let (key, problem) = invalid(&text);
    assert_eq!(key, "objects[0].pose");
    match problem {
        Problem::TooClose { a, b, distance, .. } => {
            assert_eq!((a.as_str(), b.as_str()), ("jug", "bottle-a"));
            assert_eq!(distance, 0.0);
        }
        p => panic!("{p}"),
    }
    // 2 cm apart: not touching, but under the 3 cm minimum.
    let text = env1().replace(
        "pose = { xyz = [0.88, 0.02, 0.25], rpy_deg = [0.0, 0.0, 0.0] }",
        "pose = { xyz = [0.88, 0.02, 0.25] }\n[[objects]]\nname = \"bottle-2\"\nmesh = \"../assets/meshes/bottle-a.stl\"\npose = { xyz = [0.965, 0.02, 0.25] }",
    );
    match invalid(&text).1 {
        Problem::TooClose { distance, .. } => {
            assert!(distance > 0.015 && distance < 0.025, "{distance}")
        }
        p => panic!("{p}"),
    }
}

#[test]
fn object_touching_an_obstacle() {
    let text = env1().replace("xyz = [1.15, -0.48, 0.25]", "xyz = [0.75, -0.20, 0.25]");
    match invalid(&text).1 {
        Problem::TooClose { a, b, .. } => assert_eq!((a.as_str(), b.as_str()), ("mallet", "crate")),
        p => panic!("{p}"),
    }
}

#[test]
fn structural_errors() {
    let dup = env1().replace("name = \"crate\"", "name = \"jug\"");
    assert_eq!(
        invalid(&dup),
        ("obstacles[1].name".into(), Problem::Duplicate("jug".into()))
    );
    let res = env1().replace("resolution = 0.02", "resolution = 0.03");
    assert!(matches!(
        invalid(&res).1,
        Problem::ResolutionNotDividing { axis: 'y', .. }
    ));
    let range = env1().replace("range = [0.7, 3.0]", "range = [3.0, 0.7]");
    assert_eq!(invalid(&range).0, "sensors.mid_range.range");
    let size = env1().replace("box = [0.14, 0.22, 0.32]", "box = [0.14, 0.0, 0.32]");
    assert_eq!(
        invalid(&size),
        (
            "obstacles[1].box[1]".into(),
            Problem::NotPositive("0".into())
        )
    );
    let both = env1().replace(
        "box = [0.14, 0.22, 0.32]",
        "box = [0.1, 0.1, 0.1]\nmesh = \"x.stl\"",
    );
    assert_eq!(invalid(&both).1, Problem::ShapeChoice);
    let ws = env1().replace("max = [1.50, 0.70, 0.83]", "max = [0.20, 0.70, 0.83]");
    assert_eq!(invalid(&ws).0, "workspace.max");
    let eps = env1().replace("epsilon_o = 0.4", "epsilon_o = 0.9");
    assert_eq!(invalid(&eps).0, "mapping.epsilon_o");
    // Free space beyond the camera's far limit (0.8 m) cannot come from a missing return.
    let far = env1().replace(
        "epsilon_o = 0.4",
        "epsilon_o = 0.4\nno_return_clearing = 0.9",
    );
    let (key, problem) = invalid(&far);
    assert_eq!(key, "mapping.no_return_clearing");
    assert!(
        matches!(problem, Problem::OutOfRange { ref expected, .. } if expected.contains("0.8"))
    );
    let negative = env1().replace(
        "epsilon_o = 0.4",
        "epsilon_o = 0.4\nno_return_clearing = -0.1",
    );
    assert_eq!(invalid(&negative).0, "mapping.no_return_clearing");
    let sweep = env1().replace(", [0.0, -40.0, -90.0, 0.0, 84.0, 0.0]]", "]");
    assert_eq!(invalid(&sweep).0, "sweep.waypoints_deg");
    let asset = std::path::Path::new(nbv_core::kinematics::COMAU_URDF);
    let file = asset.file_name().unwrap().to_str().unwrap();
    let urdf = env1().replace(file, "missing.urdf");
    assert!(matches!(invalid(&urdf), (k, Problem::MissingFile(_)) if k == "robot.urdf"));
}

#[test]
fn broken_mesh_files() {
    let dir = tempfile::tempdir().unwrap();
    let open = dir.path().join("open.stl");
    let mut m = nbv_core::mesh::TriMesh::cuboid([0.05; 3]);
    m.triangles.pop();
    nbv_core::mesh::io::write_stl_file(&m, &open).unwrap();
    let text = env1().replace(
        "\"../assets/meshes/bottle-a.stl\"",
        &format!("{:?}", open.display().to_string()),
    );
    let (key, problem) = invalid(&text);
    assert_eq!(key, "objects[2].mesh");
    assert!(matches!(problem, Problem::NotWatertight { .. }));
    let garbage = dir.path().join("garbage.stl");
    std::fs::write(&garbage, b"solid x\nfacet normal oops\n").unwrap();
    let text = env1().replace(
        "\"../assets/meshes/bottle-a.stl\"",
        &format!("{:?}", garbage.display().to_string()),
    );
    let err = check(&text).unwrap_err();
    assert!(
        matches!(err, SceneError::Mesh { ref key, .. } if key == "objects[2].mesh"),
        "{err}"
    );
}

#[test]
fn defaults_fill_omitted_sections() {
    let env2 = Scene::parse(
        nbv_scenes::builtin::text("paper-env2").unwrap(),
        Path::new("e2"),
    )
    .unwrap();
    assert_eq!(env2.planner, nbv_scenes::schema::Planner::default());
    assert_eq!(env2.mapping.p_hit, 0.7);
    assert_eq!((env2.nbv.alpha_u, env2.nbv.alpha_o), (4.0, 1.0));
    // [nbv] is tuned for the twin; the keys it omits keep their defaults.
    let defaults = nbv_scenes::schema::Nbv::default();
    assert_eq!(env2.nbv.radius, 0.45);
    assert_eq!(defaults.radius, 0.45);
    assert_eq!(
        nbv_scenes::schema::Nbv::preset(nbv_scenes::schema::NbvPreset::Paper).radius,
        0.3
    );
    assert_eq!(env2.nbv.rolls, defaults.rolls);
    assert_eq!(env2.sensors.short_range.width, 320);
    // env1 spells every default out: same values.
    let env1 = Scene::parse(&env1(), Path::new("e1")).unwrap();
    assert_eq!(env1.sensors, env2.sensors);
    assert_eq!(env1.planner, env2.planner);
    assert_eq!(env1.errors, env2.errors);
    assert_eq!(env1.segmentation, env2.segmentation);
    assert_eq!(env1.nbv, env2.nbv);
}

const TOKENS: [&str; 12] = [
    "nan",
    "-inf",
    "1e309",
    "-1",
    "0",
    "\"x\"",
    "[]",
    "{}",
    "[[objects]]",
    "=",
    "\n",
    "true",
];

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    #[test]
    fn mutated_scenes_never_panic(
        edits in prop::collection::vec((0usize..5000, 0usize..40, 0usize..TOKENS.len()), 1..4)
    ) {
        let mut text = env1();
        for (at, len, tok) in edits {
            let mut start = at.min(text.len());
            while !text.is_char_boundary(start) { start -= 1; }
            let mut end = (start + len).min(text.len());
            while !text.is_char_boundary(end) { end -= 1; }
            text.replace_range(start..end, TOKENS[tok]);
        }
        let _ = check(&text).map_err(|e| e.to_string());
    }

    #[test]
    fn random_text_never_panics(text in "\\PC{0,400}") {
        let _ = check(&text).map_err(|e| e.to_string());
    }

    #[test]
    fn number_swaps_never_panic(pick in 0usize..200, value in prop::num::f64::ANY) {
        // Replace the pick-th number of the scene with an arbitrary float.
        let text = env1();
        let mut count = 0;
        let mut out = String::new();
        let mut replaced = false;
        for tok in text.split_inclusive([' ', ',', '[', ']', '\n']) {
            let trimmed = tok.trim_end_matches([' ', ',', '[', ']', '\n']);
            if !replaced && trimmed.parse::<f64>().is_ok() {
                if count == pick {
                    out.push_str(&tok.replacen(trimmed, &format!("{value:?}").replace("NaN", "nan"), 1));
                    replaced = true;
                    continue;
                }
                count += 1;
            }
            out.push_str(tok);
        }
        let _ = check(&out).map_err(|e| e.to_string());
    }
}

#[test]
fn malformed_urdf_and_home_outside_limits_are_robot_errors() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.urdf");
    std::fs::write(&bad, "<robot name=\"r\"><link name=\"a\"/>").unwrap();
    let text = env1().replace(
        &format!("{:?}", common::fixture_urdf().display().to_string()),
        &format!("{:?}", bad.display().to_string()),
    );
    let (key, problem) = invalid(&text);
    assert_eq!(key, "robot.urdf");
    assert!(
        matches!(problem, Problem::Robot(ref m) if m.contains("bad.urdf")),
        "{problem}"
    );

    let text = env1().replace("home_deg = [0.0, 0.0, -90.0", "home_deg = [0.0, 0.0, 10.0");
    let (key, problem) = invalid(&text);
    assert_eq!(key, "robot.home_deg[2]");
    assert!(
        matches!(problem, Problem::Robot(ref m) if m.contains("outside its limits")),
        "{problem}"
    );
}

#[test]
fn bad_objective_and_cost_weight() {
    let with = |line: &str| env1().replace("objective = \"paper\"\n", &format!("{line}\n"));
    // An unknown objective: a parse error naming the file, the key and the names allowed.
    let err = check(&with("objective = \"rear-side\"")).unwrap_err();
    let msg = err.to_string();
    assert!(matches!(err, SceneError::Parse { .. }), "{msg}");
    assert!(msg.starts_with("bad.toml: "), "{msg}");
    assert!(
        msg.contains("objective") && msg.contains("rear-side-entropy"),
        "{msg}"
    );
    // A negative movement-cost weight, a relative-gain ratio of 1.
    let text = env1().replace("cost_weight = 0.0", "cost_weight = -0.5");
    let (key, problem) = invalid(&text);
    assert_eq!(key, "nbv.cost_weight");
    assert!(matches!(problem, Problem::OutOfRange { .. }), "{problem}");
    let text = env1().replace("relative_gain = 0.0", "relative_gain = 1.0");
    assert_eq!(invalid(&text).0, "nbv.relative_gain");
    // The near radius lies in [0, radius): the radius itself is no nearer sphere.
    let near = |r: &str| {
        env1().replace(
            "radius = 0.45\n",
            &format!("radius = 0.45\nnear_radius = {r}\n"),
        )
    };
    assert_eq!(invalid(&near("0.45")).0, "nbv.near_radius");
    assert_eq!(invalid(&near("-0.1")).0, "nbv.near_radius");
    assert_eq!(check(&near("0.4499")).unwrap().nbv.near_radius, 0.4499);
    // Every objective's name loads.
    for o in nbv_core::nbv::Objective::ALL {
        let scene = check(&with(&format!("objective = \"{}\"", o.name()))).unwrap();
        assert_eq!(scene.nbv.objective, o);
    }
    // When the hull scores: four names; a bool is a parse error naming them.
    use nbv_core::nbv::HullScore;
    assert_eq!(check(&env1()).unwrap().nbv.hull_score, HullScore::First);
    for (name, mode) in [
        ("off", HullScore::Off),
        ("after-stall", HullScore::AfterStall),
        ("always", HullScore::Always),
        ("first", HullScore::First),
    ] {
        let scene = check(&with(&format!("hull_score = \"{name}\""))).unwrap();
        assert_eq!(scene.nbv.hull_score, mode);
    }
    let err = check(&with("hull_score = true")).unwrap_err();
    let msg = err.to_string();
    assert!(matches!(err, SceneError::Parse { .. }), "{msg}");
    assert!(
        msg.contains("hull_score = true") && msg.contains("line"),
        "{msg}"
    );
}

/// `[registration]` has three on/off keys; a switch folded into the method is an unknown
/// key, named with its line, not silently ignored.
#[test]
fn registration_keys_folded_into_the_method_are_rejected_by_name() {
    let with = |line: &str| {
        env1().replace(
            "points_per_view = 2000\n",
            &format!("points_per_view = 2000\n{line}\n"),
        )
    };
    let scene = check(&env1()).unwrap();
    let r = &scene.registration;
    assert!(r.align_to_workcell && r.calibrate_hand_eye && r.baselines);
    for key in [
        "along_rays",
        "refine_along_rays",
        "measured_reference",
        "free_space",
        "camera_free_space",
        "table_evidence",
        "smoothing",
    ] {
        let err = check(&with(&format!("{key} = false"))).unwrap_err();
        let msg = err.to_string();
        assert!(matches!(err, SceneError::Parse { .. }), "{key}: {msg}");
        assert!(msg.contains(key) && msg.contains("line"), "{key}: {msg}");
    }
    let err = check(&with("baselines = 1")).unwrap_err();
    assert!(matches!(err, SceneError::Parse { .. }), "{err}");
}
