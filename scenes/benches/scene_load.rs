//! Benchmarks of scene loading: full validation of a paper scene (meshes, layout
//! distances), the mesh-to-mesh distance alone, and generating one library mesh.

use criterion::{Criterion, criterion_group, criterion_main};
use nbv_scenes::Scene;
use nbv_scenes::meshgen::ObjectKind;
use std::hint::black_box;
use std::path::Path;

fn env1_text() -> String {
    nbv_scenes::builtin::text("paper-env1")
        .expect("built-in scene")
        .to_string()
}

fn benches(c: &mut Criterion) {
    let text = env1_text();
    let base = nbv_scenes::builtin::base_dir();
    c.bench_function("validate paper-env1", |b| {
        b.iter(|| Scene::from_toml_str(black_box(&text), &base, Path::new("env1")).unwrap())
    });
    let scene = Scene::from_toml_str(&text, &base, Path::new("env1")).unwrap();
    let meshes = scene.object_meshes().unwrap();
    c.bench_function("surface distance jug-bottle (16K x 16K triangles)", |b| {
        b.iter(|| nbv_scenes::mesh_distance::surface_distance_below(&meshes[0], &meshes[2], 1.0))
    });
    let mut g = c.benchmark_group("mesh generation");
    g.sample_size(10);
    g.bench_function("horse (SDF + marching tetrahedra + decimation)", |b| {
        b.iter(|| ObjectKind::Horse.mesh())
    });
    g.finish();
}

criterion_group!(scene_benches, benches);
criterion_main!(scene_benches);
