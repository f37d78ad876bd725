//! Write + read of a 55K-point cloud (the paper's raw mid-range cloud size) with origins and
//! labels: binary PLY, binary PCD, compressed PCD and ASCII PLY, in memory.

use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::Point3;
use nbv_core::cloud::PointCloud;
use nbv_core::cloud::io::{
    Encoding, FloatType, ReadOptions, WriteOptions, read_pcd, read_ply, write_pcd, write_ply,
};
use std::hint::black_box;

fn cloud(n: usize) -> PointCloud {
    // A deterministic table-top-like sweep: a grid of points at varying heights.
    let points: Vec<Point3<f64>> = (0..n)
        .map(|i| {
            let (u, v) = ((i % 250) as f64, (i / 250) as f64);
            Point3::new(
                0.4 + u * 0.004,
                -0.5 + v * 0.004,
                0.02 * (u * 0.1).sin() + 0.75,
            )
        })
        .collect();
    let mut c = PointCloud::from_points(points);
    c.origins = Some(vec![Point3::new(0.0, 0.0, 1.6); n]);
    c.labels = Some((0..n as u32).map(|i| i % 7).collect());
    c
}

fn bench(c: &mut Criterion) {
    let cloud = cloud(55_000);
    let read = ReadOptions::default();
    let mut group = c.benchmark_group("cloud_io_55k");
    group.sample_size(20);
    let cases = [
        ("ply_binary_f32", true, Encoding::Binary, FloatType::F32),
        ("ply_binary_f64", true, Encoding::Binary, FloatType::F64),
        ("pcd_binary_f32", false, Encoding::Binary, FloatType::F32),
        (
            "pcd_compressed_f32",
            false,
            Encoding::BinaryCompressed,
            FloatType::F32,
        ),
        ("ply_ascii_f32", true, Encoding::Ascii, FloatType::F32),
    ];
    for (name, ply, encoding, float) in cases {
        let opts = WriteOptions { encoding, float };
        let mut bytes = Vec::new();
        if ply {
            write_ply(&mut bytes, &cloud, &opts).unwrap();
        } else {
            write_pcd(&mut bytes, &cloud, &opts).unwrap();
        }
        println!("{name}: {} bytes", bytes.len());
        group.bench_function(format!("{name}/write"), |b| {
            b.iter(|| {
                let mut out = Vec::with_capacity(bytes.len());
                if ply {
                    write_ply(&mut out, black_box(&cloud), &opts).unwrap();
                } else {
                    write_pcd(&mut out, black_box(&cloud), &opts).unwrap();
                }
                out
            })
        });
        group.bench_function(format!("{name}/read"), |b| {
            b.iter(|| {
                if ply {
                    read_ply(black_box(&bytes[..]), &read).unwrap()
                } else {
                    read_pcd(black_box(&bytes[..]), &read).unwrap()
                }
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
