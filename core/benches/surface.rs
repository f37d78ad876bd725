//! The fused surface: eight 320×240 views of a 5 cm sphere from 0.35 m (the Dinast at the
//! exploration's stand-off), integrated into the TSDF at the default 2 mm voxels and 16 mm
//! truncation, and the mesh extracted.

use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::{Isometry3, Matrix3, Point3, Rotation3, Translation3, UnitQuaternion, Vector3};
use nbv_core::rig::DepthCameraSpec;
use nbv_core::surface::{DepthView, PinholeIntrinsics, RgbdDataset, TsdfParams};
use std::hint::black_box;

fn sphere_views() -> RgbdDataset {
    let k = PinholeIntrinsics::of_camera(&DepthCameraSpec::ipa1110());
    let centre = Point3::new(0.8, 0.0, 0.3);
    let views = (0..8)
        .map(|i| {
            let a = i as f64 * std::f64::consts::TAU / 8.0;
            let eye = centre + Vector3::new(a.cos(), a.sin(), 0.5).normalize() * 0.35;
            let z = (centre - eye).normalize();
            let x = Vector3::z().cross(&z).normalize();
            let r = Rotation3::from_matrix_unchecked(Matrix3::from_columns(&[x, z.cross(&x), z]));
            let pose = Isometry3::from_parts(
                Translation3::from(eye.coords),
                UnitQuaternion::from_rotation_matrix(&r),
            );
            let c = pose.inverse() * centre;
            let mut depth = vec![f32::NAN; k.width * k.height];
            for v in 0..k.height {
                for u in 0..k.width {
                    let d = k.ray(u as f64, v as f64).normalize();
                    let b = d.dot(&c.coords);
                    let disc = b * b - (c.coords.norm_squared() - 0.0025);
                    if disc >= 0.0 {
                        depth[v * k.width + u] = ((b - disc.sqrt()) * d.z) as f32;
                    }
                }
            }
            DepthView {
                intrinsics: k,
                depth,
                pose,
            }
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
