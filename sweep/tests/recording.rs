//! `episode.rrd` read back with the Rerun decoder: a short episode on a generated
//! one-object scene (two views at most), recorded, then its entity paths, its timelines
//! and its views checked against the report.

use nbv_core::pipeline::{ExploreMode, NoObserver};
use nbv_sweep::episode::{Extras, run_episode};
use nbv_sweep::recording::entity;
use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// Per entity path of the recording, the rows logged; and every timeline seen.
fn read_back(path: &Path) -> (BTreeMap<String, usize>, BTreeSet<String>, bool) {
    let file = std::io::BufReader::new(std::fs::File::open(path).unwrap());
    let mut rows = BTreeMap::new();
    let mut timelines = BTreeSet::new();
    let mut blueprint = false;
    let messages = rerun::external::re_log_encoding::DecoderApp::decode_eager(file).unwrap();
    for msg in messages {
        let msg = msg.unwrap();
        // The file holds the viewer's layout (a blueprint store) beside the recording.
        blueprint |= msg.store_id().kind() == rerun::StoreKind::Blueprint;
        if let rerun::log::LogMsg::ArrowMsg(store, arrow) = msg
            && store.kind() == rerun::StoreKind::Recording
        {
            let chunk = rerun::log::Chunk::from_arrow_msg(&arrow).unwrap();
            *rows.entry(chunk.entity_path().to_string()).or_insert(0) += chunk.num_rows();
            timelines.extend(chunk.timelines().keys().map(|t| t.to_string()));
        }
    }
    (rows, timelines, blueprint)
}

#[test]
fn an_episode_recording_holds_the_robot_the_sweep_the_grid_each_view_and_the_models() {
    let base = nbv_scenes::generator::generate(3, 1).unwrap();
    let max_views = toml::Value::Integer(2);
    let scene = nbv_scenes::overrides::with_overrides(
        &base,
        &[("nbv.max_views_per_object".into(), max_views)],
        "test",
        "generated",
    )
    .unwrap();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("run");
    let extras = Extras {
        pictures: false,
        record: true,
        ..Default::default()
    };
    let report = run_episode(&scene, ExploreMode::Hybrid, &out, extras, &mut NoObserver).unwrap();
    let file = out.join("episode.rrd");
    assert!(file.is_file());
    // Written atomically: no temporary file is left.
    let names: Vec<_> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert!(names.iter().all(|n| !n.ends_with(".partial")), "{names:?}");

    let (rows, timelines, blueprint) = read_back(&file);
    let paths: Vec<&str> = rows.keys().map(String::as_str).collect();
    let has = |p: &str| rows.contains_key(&format!("/{p}"));
    let under = |prefix: &str| {
        paths
            .iter()
            .filter(|p| p.starts_with(&format!("/{prefix}")))
            .count()
    };
    assert!(
        timelines.contains(entity::SIM_TIME) && timelines.contains(entity::STEP),
        "{timelines:?}"
    );
    assert!(!timelines.contains("log_time"), "{timelines:?}");
    // The robot: link meshes and their poses along every motion.
    assert!(under("world/robot/") >= 6, "{paths:?}");
    assert!(paths.iter().any(|p| p.contains("/visual_")), "{paths:?}");
    // Phase 1: the scan lines, the growing cloud, the cluster.
    assert!(rows[&format!("/{}", entity::SWEEP_LINE)] > 10);
    assert!(under("world/sweep/cloud/") > 1, "{paths:?}");
    assert!(has(&format!("{}/0", entity::CLUSTERS)), "{paths:?}");
    // The reduced map after phase 1 and after each view.
    let views = report.objects[0].views.len();
    assert!(views >= 1, "the episode took no view");
    assert_eq!(rows[&format!("/{}", entity::GRID_OCCUPIED)], 1 + views);
    assert_eq!(rows[&format!("/{}", entity::GRID_UNKNOWN)], 1 + views);
    // Each view: its points, the camera, the path, the candidates, the gain.
    let view_entities = paths.iter().filter(|p| p.contains("/views/view_")).count();
    assert_eq!(view_entities, views);
    assert!(has(&entity::view(0, views)));
    for part in ["candidates", "path", "frame"] {
        assert!(has(&entity::object(0, part)), "{part}: {paths:?}");
    }
    assert_eq!(rows[&format!("/{}", entity::object(0, "path"))], views);
    assert!(rows[&format!("/{}", entity::object(0, "camera"))] >= views);
    assert_eq!(rows[&format!("/{}", entity::plot("gain", 0))], views);
    // The models before and after registration, the coverage (phase 1 and each view),
    // the step times, the decisions and the report.
    assert!(has(&entity::model(0, "before")) && has(&entity::model(0, "after")));
    // The fused surface beside the point model.
    assert!(has(&entity::model(0, "mesh")), "{paths:?}");
    assert_eq!(
        rows[&format!("/{}", entity::plot("coverage", 0))],
        1 + views
    );
    assert!(has(&entity::plot("times/planning", 0)));
    assert!(rows[&format!("/{}", entity::LOG)] > views);
    assert!(has("report"));
    // The viewer's layout is in the file too.
    assert!(blueprint, "no blueprint store");
    assert!(under("world/scene/") >= 2, "{paths:?}");
}
