//! Next-best-view benchmarks at the paper's scale: Algorithm 2 for one object on the
//! reduced map of a synthetic table-top scene in the paper's 60×70×30 grid of 2 cm voxels
//! (126K voxels), with the paper's r = 0.3 m and (α_u, α_o) = (4, 1), Δθ = 15°,
//! θ_max = 75°, Δφ = 30° and every 8th Dinast pixel (1200 rays); and the predicted
//! visibility of one view by DDA against the paper's literal every-ray-every-voxel loop.

#[path = "../tests/support/scene.rs"]
mod scene;

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use nbv_core::nbv::{
    NextBestView, SensorRays, VisitedViews, visible_voxels, visible_voxels_literal,
};

fn bench(c: &mut Criterion) {
    let (_, map, object) = scene::mapped_scene(1);
    let centroid = scene::centroid(&object);
    let robot = scene::robot();
    let nbv = NextBestView::new(scene::paper_nbv(), &scene::dinast()).unwrap();
    let visited = VisitedViews::default();
    let list = nbv
        .candidates_around(&robot, &map, &centroid, &visited)
        .unwrap();
    let best = list.candidates[0].viewpoint.pose;
    let rays = SensorRays::from_camera(&scene::dinast(), 8).unwrap();
    eprintln!(
        "grid {} voxels, M̄ {} voxels ({} occupied, {} unknown crust); {} samples, {} candidates, \
         {} unreachable, {} rays per candidate; best O_v {} ({} unknown, {} occupied)",
        map.geometry().len(),
        map.len(),
        map.occupied().len(),
        map.unknown().len(),
        list.samples,
        list.candidates.len(),
        list.unreachable,
        list.rays_per_view,
        list.candidates[0].visible.len(),
        list.candidates[0].visible.unknown.len(),
        list.candidates[0].visible.occupied.len(),
    );

    c.bench_function("nbv/candidate_list_one_object", |b| {
        b.iter(|| {
            black_box(
                nbv.candidates_around(&robot, &map, &centroid, &visited)
                    .unwrap(),
            )
        })
    });
    c.bench_function("nbv/viewpoints_ik_only", |b| {
        b.iter(|| black_box(nbv.viewpoints(&robot, &centroid, &visited).unwrap()))
    });
    c.bench_function("nbv/visibility_one_view_dda", |b| {
        b.iter(|| black_box(visible_voxels(&map, &best, &rays).unwrap()))
    });
    let mut slow = c.benchmark_group("nbv_literal");
    slow.sample_size(10);
    slow.bench_function("visibility_one_view_literal", |b| {
        b.iter(|| black_box(visible_voxels_literal(&map, &best, &rays).unwrap()))
    });
    slow.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
