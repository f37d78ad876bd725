//! The random scene generator: deterministic per seed, valid, round-trips through TOML.

mod common;

use nbv_core::math::Pose;
use nbv_scenes::Scene;
use nbv_scenes::generator::{GeneratorConfig, generate_with};

fn config() -> GeneratorConfig {
    GeneratorConfig {
        urdf: common::fixture_urdf(),
        ..GeneratorConfig::default()
    }
}

#[test]
fn same_seed_same_scene_and_it_round_trips() {
    let all = |_: &Pose| true;
    let dir = tempfile::tempdir().unwrap();
    for (seed, n) in [(1u64, 3usize), (42, 5), (2014, 6), (7, 1)] {
        let a = generate_with(seed, n, &config(), &all).unwrap();
        let b = generate_with(seed, n, &config(), &all).unwrap();
        assert_eq!(a, b);
        assert_eq!(a.objects.len(), n);
        a.validate().unwrap_or_else(|e| panic!("seed {seed}: {e}"));
        let path = dir.path().join(format!("random-{seed}.toml"));
        a.save(&path).unwrap();
        let back = Scene::load(&path).unwrap();
        assert_eq!(back.objects, a.objects);
        assert_eq!(back.obstacles, a.obstacles);
        assert_eq!(back.robot, a.robot);
        assert_eq!(
            Scene {
                source: None,
                ..back
            },
            a
        );
        // The text refers to the meshes relative to its own directory.
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(
            !text.contains(&*dir.path().to_string_lossy()),
            "paths are relative"
        );
    }
    let a = generate_with(1, 3, &config(), &all).unwrap();
    let c = generate_with(2, 3, &config(), &all).unwrap();
    assert_ne!(a.objects, c.objects);
}

#[test]
fn reachability_filter_is_applied() {
    // Only viewpoints in front of x = 0.80 are "reachable", and at least 40 are needed.
    let front = |p: &Pose| p.translation.vector.x < 0.80;
    let cfg = GeneratorConfig {
        min_reachable_viewpoints: 40,
        ..config()
    };
    let s = generate_with(5, 3, &cfg, &front).unwrap();
    let nbv = nbv_scenes::schema::Nbv::preset(nbv_scenes::schema::NbvPreset::Paper);
    for (o, m) in s.objects.iter().zip(s.object_meshes().unwrap()) {
        let c = nbv_scenes::describe::solid_centroid(&m);
        let views = nbv_scenes::reachability::viewing_sphere(&c, &nbv);
        let n = nbv_scenes::reachability::count_reachable(&views, &front);
        assert!(n >= 40, "{}: {n}", o.name);
    }
    // Nothing reachable: a clear error, not a panic or an endless loop.
    let none = |_: &Pose| false;
    let err = generate_with(
        5,
        2,
        &GeneratorConfig {
            attempts: 20,
            ..config()
        },
        &none,
    )
    .unwrap_err();
    assert!(err.to_string().contains("no room"), "{err}");
}
