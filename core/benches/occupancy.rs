//! Occupancy benchmarks at the paper's scale: one 55K-ray mid-range sweep into the
//! 60×70×30 grid of 2 cm voxels, the reduced map of the result, and raw DDA traversal.
//!
//! The scene is synthetic and analytic: a floor/table plane at z = 0.25 m with boxes on it,
//! swept by a line scanner (275 lines × 200 rays, 70° fan) moving along y about 1 m above.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::{Point3, Vector3};
use nbv_core::occupancy::{GridGeometry, OccupancyGrid, OccupancyParams, ReducedMap};

/// Axis-aligned boxes standing on the table: (min, max).
const BOXES: [([f64; 3], [f64; 3]); 5] = [
    ([0.55, -0.40, 0.25], [0.70, -0.25, 0.45]),
    ([0.80, -0.10, 0.25], [0.90, 0.05, 0.55]),
    ([0.60, 0.20, 0.25], [0.75, 0.32, 0.35]),
    ([1.00, 0.35, 0.25], [1.12, 0.50, 0.40]),
    ([1.30, -0.60, 0.25], [1.40, 0.60, 0.70]),
];
const TABLE_Z: f64 = 0.25;

fn paper_geometry() -> GridGeometry {
    GridGeometry::new(
        Point3::new(0.30, -0.70, 0.23),
        Point3::new(1.50, 0.70, 0.83),
        0.02,
    )
    .unwrap()
}

/// Nearest hit of a ray with the table plane and the boxes.
fn cast(o: &Point3<f64>, d: &Vector3<f64>) -> Option<f64> {
    let mut best = if d.z < 0.0 {
        Some((TABLE_Z - o.z) / d.z)
    } else {
        None
    };
    for (lo, hi) in BOXES {
        let (mut t0, mut t1) = (0.0f64, f64::INFINITY);
        for a in 0..3 {
            if d[a] == 0.0 {
                if o[a] < lo[a] || o[a] > hi[a] {
                    t0 = f64::INFINITY;
                }
                continue;
            }
            let (ta, tb) = ((lo[a] - o[a]) / d[a], (hi[a] - o[a]) / d[a]);
            t0 = t0.max(ta.min(tb));
            t1 = t1.min(ta.max(tb));
        }
        if t0 <= t1 && best.is_none_or(|b| t0 < b) {
            best = Some(t0);
        }
    }
    best
}

/// The sweep: (origins, points) of every return within the LMS400's 0.7–3.0 m.
fn sweep() -> (Vec<Point3<f64>>, Vec<Point3<f64>>) {
    let (lines, rays) = (275, 200);
    let fov = 70f64.to_radians();
    let mut origins = Vec::new();
    let mut points = Vec::new();
    for l in 0..lines {
        let o = Point3::new(0.10, -0.55 + 1.1 * l as f64 / (lines - 1) as f64, 1.20);
        for r in 0..rays {
            // Angle from the vertical, in the x–z plane: 0° (straight down) to 70° (forward).
            let a = fov * r as f64 / (rays - 1) as f64;
            let d = Vector3::new(a.sin(), 0.0, -a.cos());
            if let Some(t) = cast(&o, &d).filter(|t| (0.7..=3.0).contains(t)) {
                origins.push(o);
                points.push(o + d * t);
            }
        }
    }
    (origins, points)
}

fn benches(c: &mut Criterion) {
    let geometry = paper_geometry();
    let (origins, points) = sweep();
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

criterion_group! {
    name = occupancy;
    config = Criterion::default().sample_size(30);
    targets = benches
}
criterion_main!(occupancy);
