//! Frame time of the headless renderer at 1280x960: ~100K points and ~5K voxel cubes plus
//! a few meshes and lines, as in an occupancy-map picture with the clouds on top.

use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::{Isometry3, Point3};
use nbv_sim::render::{
    Camera, Color, LineSet, MeshItem, PointSet, RenderScene, Renderer, VoxelSet, tessellate,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn scene() -> RenderScene {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let (lo, hi) = (
        Point3::new(0.30, -0.70, 0.23),
        Point3::new(1.50, 0.70, 0.83),
    );
    let mut scene = RenderScene::new();
    scene.add_mesh(MeshItem::flat(
        tessellate::cuboid([1.4, 1.6, 0.05]),
        Isometry3::translation(0.9, 0.0, 0.205),
        Color::rgb(0.75, 0.62, 0.45),
    ));
    // ~100K points on the surfaces of ten spheres, coloured by view.
    let mut points = Vec::with_capacity(100_000);
    let mut colors = Vec::with_capacity(100_000);
    for k in 0..10 {
        let c = Point3::new(
            rng.random_range(0.5..1.3),
            rng.random_range(-0.5..0.5),
            rng.random_range(0.35..0.6),
        );
        for _ in 0..10_000 {
            let d = nalgebra::Vector3::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
            )
            .try_normalize(1e-9)
            .unwrap_or_else(nalgebra::Vector3::z);
            points.push(c + d * 0.08);
            colors.push(Color::categorical(k));
        }
    }
    scene.add_points(PointSet {
        points,
        colors,
        size: 3.0,
    });
    // ~5K voxels of 2 cm: a slab of occupied and a slab of unknown cells.
    let mut occupied = Vec::new();
    let mut unknown = Vec::new();
    for i in 0..50 {
        for j in 0..50 {
            let x = 1.2 + 0.02 * f64::from(i % 10);
            let y = -0.5 + 0.02 * f64::from(j);
            let z = 0.25 + 0.02 * f64::from(i / 10);
            if (i + j) % 3 == 0 {
                occupied.push(Point3::new(x, y, z));
            } else {
                unknown.push(Point3::new(x, y, z));
            }
        }
    }
    scene.add_voxels(VoxelSet::uniform(occupied, 0.02, Color::OCCUPIED));
    scene.add_voxels(VoxelSet::uniform(unknown, 0.02, Color::UNKNOWN));
    scene.add_lines(LineSet::aabb(lo, hi, Color::BLACK, 2.0));
    scene
}

fn bench(c: &mut Criterion) {
    let renderer = match Renderer::new() {
        Ok(r) => r,
        Err(e) => {
            eprintln!("render bench skipped: {e}");
            return;
        }
    };
    eprintln!("render bench on {}", renderer.adapter_summary());
    let scene = scene();
    let (lo, hi) = (
        Point3::new(0.30, -0.70, 0.23),
        Point3::new(1.50, 0.70, 0.83),
    );
    let camera = Camera::front_of(lo, hi, 4.0 / 3.0);
    let mut group = c.benchmark_group("render");
    group.sample_size(10);
    group.bench_function("1280x960_100k_points_5k_voxels", |b| {
        b.iter(|| renderer.render(&scene, &camera, 1280, 960).unwrap())
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
