//! Occupancy benchmarks at the paper's scale: one 55K-ray mid-range sweep into the
//! 60×70×30 grid of 2 cm voxels (as one scan, and as 275 scans of one line each), the
//! reduced map of the result, raw DDA traversal, and the whole of phase 1 (segmentation,
//! grid, reduced map) on the same cloud.
//!
//! The scene is synthetic and analytic: a floor/table plane at z = 0.25 m with boxes on it,
//! swept by a line scanner (275 lines × 200 rays, 70° fan) moving along y about 1 m above.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::Point3;
use nbv_core::cloud::PointCloud;
use nbv_core::occupancy::{GridGeometry, OccupancyGrid, OccupancyParams, ReducedMap};
use nbv_core::perception::{PhaseOneConfig, phase_one};

use nbv_fixtures::SyntheticSweep;

fn paper_geometry() -> GridGeometry {
    GridGeometry::new(
        Point3::new(0.30, -0.70, 0.23),
        Point3::new(1.50, 0.70, 0.83),
        0.02,
    )
    .unwrap()
}

fn benches(c: &mut Criterion) {
    let geometry = paper_geometry();
    let (origins, points) = SyntheticSweep::paper_scale().scan();
    eprintln!(
        "grid {:?} = {} voxels, sweep of {} returns",
        geometry.dims(),
        geometry.len(),
        points.len()
    );
    let update = |pool: Option<&rayon::ThreadPool>| {
        let mut grid = OccupancyGrid::new(geometry, OccupancyParams::default()).unwrap();
        let mut run = || grid.insert_rays(&origins, &points, 3.0).unwrap();
        let up = match pool {
            Some(p) => p.install(run),
            None => run(),
        };
        (grid, up)
    };
    let (grid, up) = update(None);
    let reduced = ReducedMap::from_grid(&grid);
    let crossings: usize = origins
        .iter()
        .zip(&points)
        .map(|(o, p)| geometry.traverse_segment(o, p).unwrap().count())
        .sum();
    eprintln!(
        "scan: {up:?}\nvoxel crossings: {crossings} ({:.1} per ray)\nreduced map: {:?}",
        crossings as f64 / points.len() as f64,
        reduced.stats()
    );

    c.bench_function("grid_update/paper_55k_rays", |b| {
        b.iter(|| black_box(update(None)))
    });
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    c.bench_function("grid_update/paper_55k_rays_1_thread", |b| {
        b.iter(|| black_box(update(Some(&one))))
    });
    // OctoMap's way of feeding a sweep: one scan per scan line (275 calls of 200 rays).
    let lines = scan_lines(&origins);
    let per_line = |pool: Option<&rayon::ThreadPool>| {
        let mut grid = OccupancyGrid::new(geometry, OccupancyParams::default()).unwrap();
        let mut run = || {
            for r in &lines {
                grid.insert_rays(&origins[r.clone()], &points[r.clone()], 3.0)
                    .unwrap();
            }
        };
        match pool {
            Some(p) => p.install(run),
            None => run(),
        }
        grid
    };
    assert_eq!(lines.len(), 275);
    c.bench_function("grid_update/paper_275_lines", |b| {
        b.iter(|| black_box(per_line(None)))
    });
    c.bench_function("grid_update/paper_275_lines_1_thread", |b| {
        b.iter(|| black_box(per_line(Some(&one))))
    });
    c.bench_function("reduced_map/paper_126k_voxels", |b| {
        b.iter(|| black_box(ReducedMap::from_grid(black_box(&grid))))
    });
    c.bench_function("traversal/55k_rays_count_voxels", |b| {
        b.iter(|| {
            let mut n = 0usize;
            for (o, p) in origins.iter().zip(&points) {
                n += geometry.traverse_segment(o, p).unwrap().count();
            }
            black_box(n)
        })
    });
}

/// Index ranges of consecutive rays that share an origin (one per scan line).
fn scan_lines(origins: &[Point3<f64>]) -> Vec<std::ops::Range<usize>> {
    let mut out = Vec::new();
    let mut start = 0;
    for i in 1..=origins.len() {
        if i == origins.len() || origins[i] != origins[start] {
            out.push(start..i);
            start = i;
        }
    }
    out
}

/// The whole of phase 1 (segmentation with the default parameters, grid, reduced map) on
/// the same sweep.
fn phase_one_bench(c: &mut Criterion) {
    let (origins, points) = SyntheticSweep::paper_scale().scan();
    let mut cloud = PointCloud::from_points(points);
    cloud.origins = Some(origins);
    let config = PhaseOneConfig::new(paper_geometry());
    let out = phase_one(&cloud, &config).unwrap();
    eprintln!(
        "phase 1: {} clusters, counts {:?}",
        out.segmentation.clusters.len(),
        out.segmentation.counts
    );
    c.bench_function("phase_one/paper_55k_sweep", |b| {
        b.iter(|| black_box(phase_one(black_box(&cloud), &config).unwrap()))
    });
}

criterion_group! {
    name = phase;
    config = Criterion::default().sample_size(10);
    targets = phase_one_bench
}

criterion_group! {
    name = occupancy;
    config = Criterion::default().sample_size(30);
    targets = benches
}
criterion_main!(occupancy, phase);
