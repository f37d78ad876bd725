//! Phase-1 segmentation benchmarks on a synthetic table-top cloud of ~55K points (the
//! paper's mid-range cloud size): voxel downsampling, statistical outlier removal, RANSAC
//! table extraction and Euclidean clustering of what lies on the table.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::Point3;
use nbv_core::cloud::{
    EuclideanClustering, PlaneRansac, PointCloud, StatisticalOutlierFilter, VoxelFilter,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

/// Boxes on the table (min, max); the table top is z = 0.25.
const BOXES: [([f64; 3], [f64; 3]); 6] = [
    ([0.55, -0.40, 0.25], [0.70, -0.25, 0.45]),
    ([0.80, -0.10, 0.25], [0.90, 0.05, 0.55]),
    ([0.60, 0.20, 0.25], [0.75, 0.32, 0.35]),
    ([1.00, 0.35, 0.25], [1.12, 0.50, 0.40]),
    ([1.05, -0.45, 0.25], [1.20, -0.30, 0.33]),
    ([0.40, 0.45, 0.25], [0.48, 0.58, 0.50]),
];

/// ~55K points: 35K on the table, 3.3K per box (top and the four sides), 1% outliers,
/// 2 mm Gaussian noise.
fn scene() -> PointCloud {
    let mut rng = ChaCha8Rng::seed_from_u64(2014);
    let noise = Normal::new(0.0, 0.002).unwrap();
    let mut pts = Vec::new();
    let jitter = |p: Point3<f64>, rng: &mut ChaCha8Rng| {
        p + nalgebra::Vector3::new(noise.sample(rng), noise.sample(rng), noise.sample(rng))
    };
    for _ in 0..35_000 {
        let p = Point3::new(
            rng.random_range(0.3..1.5),
            rng.random_range(-0.7..0.7),
            0.25,
        );
        if !BOXES
            .iter()
            .any(|(lo, hi)| p.x >= lo[0] && p.x <= hi[0] && p.y >= lo[1] && p.y <= hi[1])
        {
            pts.push(jitter(p, &mut rng));
        }
    }
    for (lo, hi) in BOXES {
        for _ in 0..3_300 {
            let (u, v, w) = (
                rng.random_range(lo[0]..hi[0]),
                rng.random_range(lo[1]..hi[1]),
                rng.random_range(lo[2]..hi[2]),
            );
            let p = match rng.random_range(0..5) {
                0 => Point3::new(u, v, hi[2]),
                1 => Point3::new(lo[0], v, w),
                2 => Point3::new(hi[0], v, w),
                3 => Point3::new(u, lo[1], w),
                _ => Point3::new(u, hi[1], w),
            };
            pts.push(jitter(p, &mut rng));
        }
    }
    for _ in 0..550 {
        pts.push(Point3::new(
            rng.random_range(0.3..1.5),
            rng.random_range(-0.7..0.7),
            rng.random_range(0.25..0.85),
        ));
    }
    PointCloud::from_points(pts)
}

fn benches(c: &mut Criterion) {
    let cloud = scene();
    let voxel = VoxelFilter { leaf_size: 0.005 };
    let sor = StatisticalOutlierFilter {
        neighbours: 16,
        std_mul: 1.0,
    };
    let ransac = PlaneRansac {
        iterations: 300,
        max_tilt: Some(0.2),
        ..PlaneRansac::new(0.01, 7)
    };
    let clustering = EuclideanClustering {
        tolerance: 0.015,
        min_size: 50,
        max_size: 50_000,
    };
    let clean = sor.filter(&cloud).unwrap();
    let plane = ransac.fit(&clean).unwrap();
    let above: Vec<usize> = plane
        .outliers(clean.len())
        .into_iter()
        .filter(|&i| plane.signed_distance(&clean.points[i]) > 0.0)
        .collect();
    let objects = clean.select(&above);
    let clusters = clustering.clusters(&objects).unwrap();
    eprintln!(
        "scene {} pts; voxel 5 mm -> {}; SOR -> {}; table inliers {} (normal {:.4?}, rms {:.4}); \
         objects {} pts -> {} clusters of sizes {:?}",
        cloud.len(),
        voxel.filter(&cloud).unwrap().len(),
        clean.len(),
        plane.inliers.len(),
        plane.normal.as_ref(),
        plane.rms,
        objects.len(),
        clusters.len(),
        clusters.iter().map(|c| c.len()).collect::<Vec<_>>()
    );

    c.bench_function("segmentation/voxel_filter_5mm_55k", |b| {
        b.iter(|| black_box(voxel.filter(black_box(&cloud)).unwrap()))
    });
    c.bench_function("segmentation/outlier_filter_k16_55k", |b| {
        b.iter(|| black_box(sor.inliers(black_box(&cloud)).unwrap()))
    });
    c.bench_function("segmentation/plane_ransac_300it_55k", |b| {
        b.iter(|| black_box(ransac.fit(black_box(&clean)).unwrap()))
    });
    c.bench_function("segmentation/euclidean_clusters_objects", |b| {
        b.iter(|| black_box(clustering.clusters(black_box(&objects)).unwrap()))
    });
}

criterion_group! {
    name = segmentation;
    config = Criterion::default().sample_size(20);
    targets = benches
}
criterion_main!(segmentation);
