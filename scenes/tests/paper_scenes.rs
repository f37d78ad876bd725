//! The built-in paper scenes validate, place their objects as the paper describes, and the
//! stored object meshes are exactly what the generator produces.

mod common;

use nbv_core::mesh::io::{read_mesh, stl_to_bytes};
use nbv_scenes::describe::describe;
use nbv_scenes::meshgen::ObjectKind;

#[test]
fn paper_scenes_validate_and_match_the_brief() {
    for name in nbv_scenes::builtin::names() {
        let scene = common::builtin_with_fixture(name).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(scene.workspace.dims(), [60, 70, 30]);
        assert_eq!(scene.workspace.voxel_count(), 126_000);
        assert_eq!(scene.objects.len(), 3);
        assert!(scene.obstacles.len() >= 2);
        let summary = describe(&scene, None).unwrap();
        for o in &summary.objects {
            // Objects stand in the object region, at least 0.10 m from anything else.
            assert!((0.55..=0.95).contains(&o.position[0]), "{} x", o.name);
            assert!(o.position[1].abs() <= 0.45, "{} y", o.name);
            assert!(
                o.clearance.unwrap_or(1.0) >= 0.10,
                "{} clearance {:?}",
                o.name,
                o.clearance
            );
            assert!(o.triangles <= 20_000);
        }
        for o in &summary.obstacles {
            let (lo, hi) = o.bounds;
            assert!(lo[0] >= 1.05 && hi[0] <= 1.35, "{} at the back", o.name);
            let height = hi[2] - lo[2];
            assert!(
                (0.30..=0.45).contains(&height),
                "{} height {height}",
                o.name
            );
        }
    }
}

#[test]
fn the_six_paper_objects_are_used_once() {
    let mut used: Vec<String> = nbv_scenes::builtin::names()
        .into_iter()
        .flat_map(|n| common::builtin_with_fixture(n).unwrap().objects)
        .map(|o| o.name)
        .collect();
    used.sort();
    let mut all: Vec<String> = ObjectKind::PAPER
        .iter()
        .map(|k| k.name().to_owned())
        .collect();
    all.sort();
    assert_eq!(used, all);
}

#[test]
fn stored_meshes_are_the_generated_ones_and_watertight() {
    let dir = nbv_scenes::builtin::assets_dir().join("meshes");
    for kind in ObjectKind::ALL {
        let mesh = kind.mesh();
        assert!(mesh.is_watertight(), "{}", kind.name());
        assert!(mesh.volume() > 0.0, "{}", kind.name());
        let path = dir.join(format!("{}.stl", kind.name()));
        let stored = std::fs::read(&path).unwrap();
        assert!(
            stored == stl_to_bytes(&mesh),
            "{} differs from a fresh generation: run `nbv scene meshes -o assets/meshes`",
            path.display()
        );
        let back = read_mesh(&path).unwrap();
        assert!(back.is_watertight(), "{} after f32 rounding", kind.name());
        assert!((back.volume() - mesh.volume()).abs() < 1e-3 * mesh.volume());
    }
}
