//! Writes the phase-1 mid-range cloud of a scene as PLY with per-point sensor origins and
//! truth labels: the arm follows the scene's `[sweep]` waypoints at
//! `joint_speed_fraction` of the URDF speed limits while an LMS400-like fan (the scene's
//! `[sensors.mid_range]`: field of view, angular step, line rate, range, Gaussian range
//! noise seeded by the scene seed) is cast through the twin world. A plain stand-in for
//! the simulated line scanner, to feed `nbv map` and the pictures.
//!
//! Run: `cargo run --release -p nbv-sim --example laser_sweep_cloud -- paper-env1 cloud.ply`

use nalgebra::{Point3, Vector3};
use nbv_core::cloud::PointCloud;
use nbv_core::cloud::io::{WriteOptions, write_cloud};
use nbv_core::kinematics::Joints;
use nbv_sim::world::TwinWorld;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let (Some(scene_arg), Some(out)) = (args.next(), args.next()) else {
        return Err("usage: laser_sweep_cloud SCENE OUT.ply".into());
    };
    let path = std::path::Path::new(&scene_arg);
    let scene = if path.exists() {
        nbv_scenes::Scene::load(path)?
    } else {
        nbv_scenes::builtin::load(&scene_arg)?
    };
    let mut world = TwinWorld::from_scene(&scene)?;
    let sensor = &scene.sensors.mid_range;
    let frame = world
        .robot()
        .frame_index(&sensor.frame)
        .ok_or_else(|| format!("no frame `{}` in the robot", sensor.frame))?;
    let limits = *world.robot().limits();
    let fov = sensor.fov_deg.to_radians();
    let step = sensor.resolution_deg.to_radians();
    let rays = (fov / step).round() as usize + 1;
    let [r_min, r_max] = sensor.range;
    let mut rng = ChaCha8Rng::seed_from_u64(scene.seed);
    let mut gauss = move || {
        // Box–Muller.
        let u1: f64 = rng.random_range(f64::EPSILON..1.0);
        let u2: f64 = rng.random_range(0.0..1.0);
        (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
    };
    let mut points = Vec::new();
    let mut origins = Vec::new();
    let mut labels = Vec::new();
    let waypoints: Vec<Joints> = scene
        .sweep
        .waypoints_deg
        .iter()
        .map(|w| Joints::from(w.map(f64::to_radians)))
        .collect();
    for pair in waypoints.windows(2) {
        let (a, b) = (pair[0], pair[1]);
        let duration = (0..6)
            .map(|j| (b[j] - a[j]).abs() / (scene.sweep.joint_speed_fraction * limits[j].velocity))
            .fold(0.0f64, f64::max);
        let lines = ((duration * sensor.line_rate_hz).round() as usize).max(1);
        for l in 0..=lines {
            let q = a + (b - a) * (l as f64 / lines as f64);
            world.set_configuration(q);
            let Some(pose) = world.frame_pose(&sensor.frame) else {
                continue;
            };
            let origin = pose * Point3::origin();
            let caster = world.ray_caster();
            for r in 0..rays {
                let angle = -fov / 2.0 + step * r as f64;
                let dir = pose.rotation * Vector3::new(angle.sin(), 0.0, angle.cos());
                let Some(hit) = caster.cast(&origin, &dir, r_max, Some(frame)) else {
                    continue;
                };
                let range = hit.distance + sensor.noise.range_sigma * gauss();
                if !(r_min..=r_max).contains(&range) {
                    continue;
                }
                points.push(origin + dir * range);
                origins.push(origin);
                labels.push(hit.label.code());
            }
        }
    }
    let mut cloud = PointCloud::from_points(points);
    cloud.origins = Some(origins);
    cloud.labels = Some(labels);
    write_cloud(&out, &cloud, &WriteOptions::default())?;
    println!("{}: {} points -> {out}", scene.name, cloud.len());
    Ok(())
}
