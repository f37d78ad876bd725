//! The fused surface: eight 320×240 views of a 5 cm sphere from 0.35 m (the Dinast at the
//! exploration's stand-off), integrated into the TSDF at the default 2 mm voxels and 16 mm
//! truncation, and the mesh extracted.

use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::Point3;
use nbv_core::rig::DepthCameraSpec;
use nbv_core::surface::{DepthView, PinholeIntrinsics, RgbdDataset, TsdfParams};
use nbv_fixtures::sphere_views::{around, sphere_depth};
use std::hint::black_box;

fn sphere_views() -> RgbdDataset {
    let k = PinholeIntrinsics::of_camera(&DepthCameraSpec::ipa1110());
    let centre = Point3::new(0.8, 0.0, 0.3);
    let views = around(centre, 8, 0.35, 0.5)
        .into_iter()
        .map(|pose| DepthView {
            intrinsics: k,
            depth: sphere_depth(k.width, k.height, k.fx, &pose, centre, 0.05),
            pose,
        })
        .collect();
    RgbdDataset::new(k, views, Some((0.01, 1.5)))
}

fn bench(c: &mut Criterion) {
    let data = sphere_views();
    c.bench_function("tsdf_fuse_8_views_sphere", |b| {
        b.iter(|| black_box(data.fuse(TsdfParams::default()).unwrap()))
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
