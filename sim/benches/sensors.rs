//! Simulated sensors on paper-env1: one Dinast frame (320×240 rays) 0.3 m above the jug,
//! cast (the first frame of a burst), drawn from the cast (the burst's other frames) and
//! smoothed as the pipeline smooths an averaged frame; one LMS400 line, and the whole
//! phase-1 sweep through the simulated rig (arm motion with collision checks, 237 lines of
//! 281 rays, the cloud). Throughput is in rays; the real
//! devices cast 190 × 281 = 53,390 rays/s (LMS400) and 76,800 per frame (Dinast).

use criterion::{BatchSize, Criterion, Throughput, criterion_group, criterion_main};
use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};
use nbv_core::rig::{LineScanner, acquire_sweep, lines_to_cloud, smooth_frame};
use nbv_sim::rig::SimRig;
use nbv_sim::sensors::{AcquisitionId, CameraModel, LaserModel};
use nbv_sim::world::TwinWorld;
use std::hint::black_box;

fn scene() -> nbv_scenes::Scene {
    nbv_scenes::builtin::load("paper-env1").expect("built-in scene")
}

fn sensors(c: &mut Criterion) {
    let scene = scene();
    let world = TwinWorld::from_scene(&scene).expect("twin world");
    let id = AcquisitionId { seed: 1, index: 0 };

    let camera = CameraModel::from_scene(&scene.sensors.short_range);
    let [x, y, _] = scene.objects[0].pose.xyz;
    let top = world
        .ray_caster()
        .cast(&Point3::new(x, y, 2.0), &-Vector3::z(), 3.0, None)
        .expect("the jug below")
        .point;
    let view = Isometry3::from_parts(
        Translation3::from(top.coords + Vector3::new(0.0, 0.0, 0.3)),
        UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::PI),
    );
    let mut group = c.benchmark_group("sensors");
    group.sample_size(20);
    group.throughput(Throughput::Elements(
        (camera.spec.width * camera.spec.height) as u64,
    ));
    // Cold: the rays cast, then the noise drawn (the first frame of a burst).
    group.bench_function("dinast_frame_320x240", |b| {
        b.iter(|| black_box(camera.capture(&world, &view, None, 0.0, id)))
    });
    // Cached: the noise of one more frame of the burst drawn from the standstill's cast.
    let truth = camera.cast(&world, &view, None);
    let mut index = 0;
    group.bench_function("dinast_frame_cached", |b| {
        b.iter(|| {
            index += 1;
            black_box(camera.draw(&truth, 0.0, AcquisitionId { seed: 1, index }))
        })
    });
    // The pipeline's smoothing of an averaged frame ([nbv] depth_smoothing = 2: the
    // edge-gated plane fit over 5 × 5 pixels at eight frames' noise).
    let frame = camera.draw(&truth, 0.0, id);
    group.bench_function("dinast_frame_smoothed_5x5", |b| {
        b.iter_batched(
            || frame.clone(),
            |frame| black_box(smooth_frame(frame, 2, |z| camera.sigma(z) / 8f64.sqrt())),
            BatchSize::LargeInput,
        )
    });

    let laser = LaserModel::from_scene(&scene.sensors.mid_range);
    let pose = world.frame_pose("lms400").expect("laser frame");
    let own = world.robot().frame_index("lms400");
    group.throughput(Throughput::Elements(laser.spec.beams() as u64));
    group.bench_function("lms400_line_281", |b| {
        b.iter(|| black_box(laser.cast_line(&world, &pose, own, 0.0, id, 0)))
    });

    // The phase-1 sweep: 237 lines × 281 beams.
    let rays = 237 * laser.spec.beams() as u64;
    group.throughput(Throughput::Elements(rays));
    group.sample_size(10);
    let waypoints = scene.sweep.joint_waypoints();
    group.bench_function("lms400_sweep_paper_env1", |b| {
        b.iter_batched(
            || SimRig::from_scene(&scene),
            |rig| {
                let mut rig = rig.expect("rig");
                let sweep = acquire_sweep(
                    &mut rig.arm,
                    &mut rig.scanner,
                    &waypoints,
                    scene.sweep.joint_speed_fraction,
                )
                .expect("sweep");
                assert_eq!(sweep.lines.len(), 237);
                let state = rig.state();
                let cloud = lines_to_cloud(
                    &sweep.lines,
                    &sweep.motion,
                    state.world().robot(),
                    state.world().base(),
                    rig.scanner.spec(),
                )
                .expect("cloud");
                black_box(cloud.len())
            },
            BatchSize::LargeInput,
        )
    });
    group.finish();
}

criterion_group!(benches, sensors);
criterion_main!(benches);
