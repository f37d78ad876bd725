//! The simulated Dinast IPA-1110: a frame 0.3 m from an object (organised, ranges within
//! 0.1–0.8 m, the configured noise), dropouts at grazing incidence and near the range
//! limits, and determinism whatever the rayon thread count.

use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};
use nbv_core::rig::{Arm, DepthCamera, DepthFrame, TruthLabel};
use nbv_sim::rig::{RigConfig, SimRig};
use nbv_sim::sensors::{AcquisitionId, CameraModel};
use nbv_sim::world::TwinWorld;

fn scene() -> nbv_scenes::Scene {
    nbv_scenes::builtin::load("paper-env1").unwrap()
}

/// Looking straight down from `origin` (image x along world −y).
fn looking_down(origin: Point3<f64>) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::from(origin.coords),
        UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::PI),
    )
}

/// The top of the first object (the jug), found by a ray from above.
fn jug_top(world: &TwinWorld, scene: &nbv_scenes::Scene) -> Point3<f64> {
    let [x, y, _] = scene.objects[0].pose.xyz;
    let hit = world
        .ray_caster()
        .cast(&Point3::new(x, y, 2.0), &-Vector3::z(), 3.0, None)
        .unwrap();
    assert_eq!(hit.label, TruthLabel::Object(0));
    hit.point
}

/// `(true range along the ray, reported range along the ray)` of every valid pixel, from
/// the true camera pose `pose`.
fn ranges(model: &CameraModel, frame: &DepthFrame, pose: &Isometry3<f64>) -> Vec<(f64, f64)> {
    let origin = Point3::from(pose.translation.vector);
    let truth = frame.truth.as_ref().unwrap();
    let mut out = Vec::new();
    for v in 0..frame.height {
        for u in 0..frame.width {
            let i = v * frame.width + u;
            match (frame.point(&model.spec, u, v), truth[i]) {
                (Some(p), Some(t)) => {
                    let d = (t.point - origin).norm();
                    // The truth lies on the pixel's true ray.
                    let ray = pose.rotation * model.spec.pixel_ray(u, v).normalize();
                    assert!(((t.point - origin) / d - ray).norm() < 1e-5);
                    out.push((d, p.coords.norm()));
                }
                (None, None) => {}
                other => panic!("pixel {u},{v}: depth and truth disagree: {other:?}"),
            }
        }
    }
    out
}

#[test]
fn a_frame_0_3_m_from_the_jug_is_organised_in_range_with_the_configured_noise() {
    let scene = scene();
    let mut rig = SimRig::from_scene(&scene).unwrap();
    let top = jug_top(rig.state().world(), &scene);
    let view = looking_down(top + Vector3::new(0.0, 0.0, 0.3));
    let (q, home) = {
        let state = rig.state();
        let robot = state.world().robot();
        let home = state.reported_joints();
        (
            robot.ik_nearest("dinast", &view, &home).unwrap().joints,
            home,
        )
    };
    assert_ne!(q, home);
    rig.arm.teleport(q).unwrap();
    assert_eq!(rig.arm.joints().unwrap(), q);
    let frame = rig.camera.capture().unwrap();
    assert_eq!((frame.width, frame.height), (320, 240));
    assert_eq!(frame.depth.len(), 320 * 240);
    assert_eq!(frame.truth.as_ref().unwrap().len(), 320 * 240);

    let state = rig.state();
    let acq = &state.acquisitions()[0];
    let pose = acq.poses[0].1;
    // The true pose is the commanded view up to the error model (millimetres).
    assert!((pose.translation.vector - view.translation.vector).norm() < 0.02);
    let model = &state.config().camera;
    let r = ranges(model, &frame, &pose);
    assert!(r.len() > 40_000, "{} valid pixels", r.len());
    assert!(r.iter().all(|&(_, m)| (0.1..=0.8).contains(&m)));
    let labels: Vec<u32> = frame
        .truth
        .as_ref()
        .unwrap()
        .iter()
        .flatten()
        .map(|t| t.label.code())
        .collect();
    let jug = labels
        .iter()
        .filter(|&&c| c == TruthLabel::Object(0).code())
        .count();
    assert!(jug > 3_000, "{jug} jug pixels");
    // The jug's top at 0.3 m: the nearest returns are 0.3 m away (± noise).
    let nearest = r.iter().map(|x| x.0).fold(f64::INFINITY, f64::min);
    assert!((nearest - 0.3).abs() < 0.01, "{nearest}");

    // Normalised residuals (m − d)/σ(d): N(0, 1), σ(d) = 0.04·d (12 mm at 0.3 m, ten
    // times the laser's and more). Pixels far from the range limits (no gate bias).
    let z: Vec<f64> = r
        .iter()
        .filter(|(d, _)| (0.2..=0.7).contains(d))
        .map(|&(d, m)| (m - d) / model.sigma(d))
        .collect();
    let n = z.len() as f64;
    let mean = z.iter().sum::<f64>() / n;
    let std = (z.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
    assert!(mean.abs() < 0.03, "{mean}");
    assert!((std - 1.0).abs() < 0.03, "{std}");
    assert!((model.sigma(0.3) - 0.012).abs() < 1e-12);
    assert!(model.sigma(0.3) > 5.0 * state.config().laser.range_sigma);
}

/// Counts `[total, valid]` table pixels of `frame` (taken at `pose`) per bin; `bin` maps
/// (noise-free range, incidence in degrees) to a bin or `None`.
fn table_bins<const N: usize>(
    world: &TwinWorld,
    model: &CameraModel,
    pose: &Isometry3<f64>,
    frame: &DepthFrame,
    bin: impl Fn(f64, f64) -> Option<usize>,
) -> [[usize; 2]; N] {
    let origin = Point3::from(pose.translation.vector);
    let caster = world.ray_caster();
    let mut bins = [[0usize; 2]; N];
    for v in 0..frame.height {
        for u in 0..frame.width {
            let dir = pose.rotation * model.spec.pixel_ray(u, v).normalize();
            let Some(hit) = caster.cast(&origin, &dir, 1.0, None) else {
                continue;
            };
            if hit.label != TruthLabel::Table {
                continue;
            }
            let incidence = (-dir.dot(&hit.normal)).acos().to_degrees();
            if let Some(b) = bin(hit.distance, incidence) {
                bins[b][0] += 1;
                bins[b][1] += frame.depth[v * frame.width + u].is_finite() as usize;
            }
        }
    }
    bins
}

fn rate(b: [usize; 2]) -> f64 {
    assert!(b[0] > 200, "only {} pixels in a bin", b[0]);
    b[1] as f64 / b[0] as f64
}

#[test]
fn dropouts_at_grazing_incidence_and_near_the_range_limits() {
    let scene = scene();
    let world = TwinWorld::from_scene(&scene).unwrap();
    let model = CameraModel::from_scene(&scene.sensors.short_range);
    let id = |index| AcquisitionId { seed: 3, index };
    let table = scene.table.max[2];
    // Straight down over the empty right part of the table: near-normal incidence. At
    // 0.45 m every pixel is far from the limits; at 0.77 m all are within 5 cm of 0.8 m.
    for (height, index) in [(0.45, 0), (0.77, 1)] {
        let pose = looking_down(Point3::new(0.55, -0.45, table + height));
        let frame = model.capture(&world, &pose, None, 0.0, id(index));
        let bins: [[usize; 2]; 2] = table_bins(&world, &model, &pose, &frame, |d, a| {
            (a < 55.0).then_some(if (0.76..0.8).contains(&d) { 1 } else { 0 })
        });
        if index == 0 {
            // Only the 1 % random dropouts.
            assert!((rate(bins[0]) - 0.99).abs() < 0.005, "{bins:?}");
        } else {
            // The ramp over the last 5 cm drops 60 % on average, the gate a few more.
            assert!(rate(bins[1]) < 0.45, "{bins:?}");
        }
    }
    // 8 cm over the table looking 25° down: incidence from 60° to grazing.
    let forward = Vector3::new(0.0, -25f64.to_radians().cos(), -25f64.to_radians().sin());
    let right = Vector3::x();
    let m = nalgebra::Matrix3::from_columns(&[right, forward.cross(&right), forward]);
    let rot = UnitQuaternion::from_rotation_matrix(&nalgebra::Rotation3::from_matrix_unchecked(m));
    let pose = Isometry3::from_parts(Translation3::new(0.55, -0.25, table + 0.08), rot);
    let frame = model.capture(&world, &pose, None, 0.0, id(2));
    let bins: [[usize; 2]; 2] = table_bins(&world, &model, &pose, &frame, |d, a| {
        if !(0.16..0.74).contains(&d) {
            None
        } else if (65.0..75.0).contains(&a) {
            Some(0)
        } else {
            (a > 80.0).then_some(1)
        }
    });
    // The grazing ramp 60°→80° drops half the pixels at 65–75° on average; beyond 80°,
    // all of them.
    assert!((rate(bins[0]) - 0.5).abs() < 0.1, "{bins:?}");
    assert_eq!(rate(bins[1]), 0.0, "{bins:?}");
}

#[test]
fn dropout_probability_follows_the_configured_ramps() {
    let model = CameraModel::from_scene(&scene().sensors.short_range);
    let p = |d: f64, a: f64| model.dropout_probability(d, a.to_radians());
    assert_eq!(p(0.4, 0.0), 0.01);
    assert_eq!(p(0.4, 59.0), 0.01);
    assert!((p(0.4, 70.0) - 0.5).abs() < 1e-12);
    assert_eq!(p(0.4, 85.0), 1.0);
    assert!((p(0.775, 0.0) - 0.5).abs() < 1e-9);
    assert!((p(0.125, 0.0) - 0.5).abs() < 1e-9);
    assert_eq!(p(0.1, 0.0), 1.0);
}

#[test]
fn same_seed_same_frame_whatever_the_thread_count() {
    let scene = scene();
    let world = TwinWorld::from_scene(&scene).unwrap();
    let model = CameraModel::from_scene(&scene.sensors.short_range);
    let pose = looking_down(Point3::new(0.75, 0.0, 0.75));
    let capture = |threads: usize, seed: u64| -> Vec<u32> {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let frame = pool
            .install(|| model.capture(&world, &pose, None, 0.0, AcquisitionId { seed, index: 2 }));
        frame.depth.iter().map(|d| d.to_bits()).collect()
    };
    let one = capture(1, 5);
    assert!(
        one.iter()
            .filter(|b| f32::from_bits(**b).is_finite())
            .count()
            > 10_000
    );
    assert_eq!(one, capture(2, 5));
    assert_eq!(one, capture(4, 5));
    assert_ne!(one, capture(1, 6));
}

#[test]
fn rig_config_of_the_scene_uses_its_sensors() {
    let scene = scene();
    let config = RigConfig::from_scene(&scene);
    assert_eq!(config.camera.spec.width, 320);
    assert!((config.camera.spec.hfov - 80f64.to_radians()).abs() < 1e-12);
    assert_eq!(config.camera.spec.range, [0.1, 0.8]);
    assert_eq!(config.laser.spec.beams(), 281);
    assert_eq!(config.seed, scene.seed);
}
