//! A burst of depth frames at one standstill: the rays are cast once and every frame
//! draws its own noise from that cast. The per-pixel spread of a burst matches the model's
//! σ (so the noise is neither shared across frames nor scaled), a cached frame is
//! bit-identical to casting it anew, and any motion or teleport invalidates the cast.

use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};
use nbv_core::kinematics::Joints;
use nbv_core::rig::{Arm, DepthCamera, DepthFrame, JointPath, TruthLabel};
use nbv_sim::rig::SimRig;
use nbv_sim::sensors::{AcquisitionId, CameraModel};
use nbv_sim::world::TwinWorld;

fn scene() -> nbv_scenes::Scene {
    nbv_scenes::builtin::load("paper-env1").unwrap()
}

/// Looking straight down from `origin`.
fn looking_down(origin: Point3<f64>) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::from(origin.coords),
        UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::PI),
    )
}

/// Per-pixel statistics of 64 frames of the table (a flat surface) 0.3 m below the
/// camera, over the pixels valid in every frame, in units of the model's σ at the pixel's
/// true range: `(pixels, mean of s²/σ², mean of z, mean of z²)` with `s²` the sample
/// variance of a pixel's 64 ranges and `z = (mean range − d)/(σ/8)`.
///
/// For independent N(d, σ²) draws, `63·s²/σ²` is χ²(63) per pixel: over ~60K pixels its
/// mean ratio is 1 ± 0.0007 (one standard deviation), z is N(0, 1), and the seeded
/// streams make the figures fixed numbers. Noise shared by the frames gives s² = 0; σ
/// doubled gives a ratio of 4.
fn burst_statistics(model: &CameraModel, draw_sigma_scale: f64) -> (usize, f64, f64, f64) {
    const FRAMES: u64 = 64;
    let scene = scene();
    let world = TwinWorld::from_scene(&scene).unwrap();
    let pose = looking_down(Point3::new(0.55, -0.45, scene.table.max[2] + 0.3));
    let mut truth = model.cast(&world, &pose, None);
    for p in truth.pixels.iter_mut().flatten() {
        p.sigma *= draw_sigma_scale;
    }
    let frames: Vec<DepthFrame> = (0..FRAMES)
        .map(|index| {
            model.draw(
                &truth,
                index as f64 / 30.0,
                AcquisitionId { seed: 11, index },
            )
        })
        .collect();
    let (mut pixels, mut ratio, mut z1, mut z2) = (0usize, 0.0, 0.0, 0.0);
    for (i, p) in truth.pixels.iter().enumerate() {
        let Some(p) = p else { continue };
        if p.truth.label != TruthLabel::Table {
            continue;
        }
        let r: Vec<f64> = frames
            .iter()
            .map(|f| f64::from(f.depth[i]) * p.norm)
            .collect();
        if r.iter().any(|x| !x.is_finite()) {
            continue;
        }
        let n = r.len() as f64;
        let mean = r.iter().sum::<f64>() / n;
        let s2 = r.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0);
        let sigma = model.sigma(p.distance);
        let z = (mean - p.distance) / (sigma / n.sqrt());
        pixels += 1;
        ratio += s2 / sigma.powi(2);
        z1 += z;
        z2 += z * z;
    }
    let n = pixels as f64;
    (pixels, ratio / n, z1 / n, z2 / n)
}

#[test]
fn the_per_pixel_spread_of_a_burst_is_the_models_sigma() {
    let model = CameraModel::from_scene(&scene().sensors.short_range);
    let (pixels, ratio, z, z2) = burst_statistics(&model, 1.0);
    eprintln!("{pixels} pixels: s²/σ² {ratio:.4}, mean z {z:.4}, mean z² {z2:.4}");
    // 76,800 table pixels, 1 % dropouts each: 0.99⁶⁴ ≈ 53 % valid in all 64 frames.
    assert!(pixels > 30_000, "{pixels} pixels valid in every frame");
    // Bounds many standard deviations wide (±0.0007 and ±0.004), yet far from a shared
    // noise (ratio 0), a doubled σ (4) or a halved one (0.25).
    assert!((ratio - 1.0).abs() < 0.05, "s²/σ² = {ratio}");
    assert!(z.abs() < 0.1, "mean z = {z}");
    assert!((z2 - 1.0).abs() < 0.1, "mean z² = {z2}");
}

#[test]
fn the_burst_test_sees_a_doubled_sigma() {
    // The same statistic with the draw's σ doubled: the bound above must reject it.
    let model = CameraModel::from_scene(&scene().sensors.short_range);
    let (_, ratio, _, z2) = burst_statistics(&model, 2.0);
    assert!((ratio - 4.0).abs() < 0.2, "s²/σ² = {ratio}");
    assert!((z2 - 4.0).abs() < 0.4, "mean z² = {z2}");
}

/// Reported joints placing the camera at `view`, nearest `from`.
fn joints_for(rig: &SimRig, view: &Isometry3<f64>, from: &Joints) -> Joints {
    rig.state()
        .world()
        .robot()
        .ik_nearest("dinast", view, from)
        .unwrap()
        .joints
}

/// Checks the rig's last frame against a fresh cast at the true pose recorded for it.
fn check_last_frame(rig: &SimRig, frame: &DepthFrame) {
    let state = rig.state();
    let acq = state.acquisitions().last().unwrap();
    let (time, pose) = acq.poses[0];
    let model = &state.config().camera;
    let own = state.world().robot().frame_index(&model.spec.frame);
    let fresh = model.capture(state.world(), &pose, own, time, acq.id);
    assert!(
        fresh
            .depth
            .iter()
            .map(|d| d.to_bits())
            .eq(frame.depth.iter().map(|d| d.to_bits())),
        "a cached frame differs from a cast one"
    );
    assert_eq!(fresh.truth, frame.truth);
    let cached = state.standstill_frame().unwrap();
    assert_eq!(cached.pose, pose);
    assert_eq!(*cached, model.cast(state.world(), &pose, own));
}

fn truth_points(frame: &DepthFrame) -> Vec<Option<Point3<f64>>> {
    frame
        .truth
        .as_ref()
        .unwrap()
        .iter()
        .map(|t| t.map(|t| t.point))
        .collect()
}

#[test]
fn frames_at_a_standstill_share_the_cast_and_a_motion_invalidates_it() {
    let scene = scene();
    let mut rig = SimRig::from_scene(&scene).unwrap();
    let home = rig.arm.joints().unwrap();
    let table = scene.table.max[2];
    let [x, y, _] = scene.objects[0].pose.xyz;
    let q_jug = joints_for(&rig, &looking_down(Point3::new(x, y, table + 0.45)), &home);
    let q_table = joints_for(
        &rig,
        &looking_down(Point3::new(0.55, -0.45, table + 0.3)),
        &q_jug,
    );

    rig.arm.teleport(q_jug).unwrap();
    assert!(rig.state().standstill_frame().is_none());
    let burst: Vec<DepthFrame> = (0..3)
        .map(|_| {
            let frame = rig.camera.capture().unwrap();
            check_last_frame(&rig, &frame);
            frame
        })
        .collect();
    // One cast, three draws: same truth where valid, different noise.
    assert_ne!(burst[0].depth, burst[1].depth);
    let jug = pixels_of(&burst[2], TruthLabel::Object(0));
    assert!(jug > 1_000, "{jug} jug pixels");

    // A teleport: the next frame sees the empty part of the table, no jug.
    rig.arm.teleport(q_table).unwrap();
    assert!(rig.state().standstill_frame().is_none());
    let after_teleport = rig.camera.capture().unwrap();
    check_last_frame(&rig, &after_teleport);
    let labels = after_teleport.truth.as_ref().unwrap();
    assert!(
        labels
            .iter()
            .flatten()
            .all(|t| t.label != TruthLabel::Object(0))
    );
    let table = pixels_of(&after_teleport, TruthLabel::Table);
    assert!(table > 30_000, "{table} table pixels");
    assert_ne!(truth_points(&after_teleport), truth_points(&burst[2]));

    // An executed path back to the jug view: the jug again, from the new cast.
    rig.arm
        .execute(&JointPath {
            waypoints: vec![q_table, q_jug],
            speed_fraction: 0.5,
        })
        .unwrap();
    assert!(rig.state().standstill_frame().is_none());
    let after_move = rig.camera.capture().unwrap();
    check_last_frame(&rig, &after_move);
    let jug_again = pixels_of(&after_move, TruthLabel::Object(0));
    assert!(jug_again > 1_000, "{jug_again} jug pixels");

    // A refused motion (outside the limits) also ends the standstill.
    let mut bad = q_jug;
    bad[0] = 100.0;
    assert!(rig.arm.teleport(bad).is_err());
    assert!(rig.state().standstill_frame().is_none());
}

/// Pixels of `frame` whose true hit is `label`.
fn pixels_of(frame: &DepthFrame, label: TruthLabel) -> usize {
    frame
        .truth
        .as_ref()
        .unwrap()
        .iter()
        .flatten()
        .filter(|t| t.label == label)
        .count()
}
