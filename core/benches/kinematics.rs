//! Kinematics of the Comau SMART SiX model (`nbv_core::kinematics::COMAU_URDF`): forward
//! kinematics to the flange, to every link at once, and closed-form IK (all solutions).
//!
//! Run with `cargo bench -p nbv-core --bench kinematics`.

use criterion::{Criterion, criterion_group, criterion_main};
use nbv_core::kinematics::{Joints, Robot};
use std::hint::black_box;

const ASSET: &str = nbv_core::kinematics::COMAU_URDF;

fn kinematics(c: &mut Criterion) {
    let robot = Robot::from_urdf_file(ASSET).expect("the asset URDF loads");
    let q = Joints::new(0.3, 0.4, -1.6, 0.5, 0.9, -0.7);
    let flange = robot.fk(&q, "tool0").expect("tool0 exists");
    let camera = robot.fk(&q, "dinast").expect("dinast exists");

    c.bench_function("fk_flange", |b| b.iter(|| robot.fk(black_box(&q), "tool0")));
    c.bench_function("fk_all_links", |b| {
        b.iter(|| robot.link_poses(black_box(&q)))
    });
    c.bench_function("ik_all_solutions_flange", |b| {
        b.iter(|| robot.ik("tool0", black_box(&flange)))
    });
    c.bench_function("ik_all_solutions_dinast", |b| {
        b.iter(|| robot.ik("dinast", black_box(&camera)))
    });
    c.bench_function("ik_nearest_dinast", |b| {
        b.iter(|| robot.ik_nearest("dinast", black_box(&camera), &q))
    });
    let n = robot.ik("tool0", &flange).map(|s| s.len()).unwrap_or(0);
    println!("ik solutions for the benchmark pose: {n}");
}

criterion_group!(benches, kinematics);
criterion_main!(benches);
