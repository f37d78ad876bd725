//! Writes a user's scans of a mesh, as a range scanner outside the twin would take them, for
//! `nbv register` and for peer tools (benches/peers/): no laser anchor, no sensor origins in
//! the files, the reported poses off by a few degrees and millimetres.
//!
//! - `--path ring`: a turntable — the object turns under a fixed scanner, which is the
//!   scanner going round it at one elevation, views evenly spaced over 360°;
//! - `--path handheld`: a hand-held scanner walked once round the object: the azimuth steps,
//!   the elevation (10–55°), the distance, the point looked at and the roll about the
//!   optical axis all wander from view to view.
//!
//! The object is the mesh (STL or OBJ, e.g. `assets/meshes/horse.stl`) standing as it is
//! in its file; the scanner is a pinhole with a 50° field of view at a distance that fits
//! the object, keeping the hits whose incidence is under 75°, with Gaussian noise along
//! each ray. The output is the layout of the `registration_views` example:
//! `view_<k>.ply` (each view in its own sensor frame), `truth.json`, `initial.json` (the
//! truth with a random error of `--rotation-error-deg` about a random axis and
//! `--translation-error` in a random direction on every view but view 0, the reference)
//! and `spec.json`.
//!
//! ```text
//! cargo run --release -p nbv-core --example user_scans -- OUTDIR --mesh assets/meshes/horse.stl \
//!     [--path ring|handheld] [--views 12] [--points-per-view 4000] [--noise 0.0003] \
//!     [--rotation-error-deg 2] [--translation-error 0.005] [--seed 7]
//! ```

use std::path::PathBuf;
use std::process::ExitCode;

use nalgebra::{Isometry3, Point3, Rotation3, Translation3, UnitQuaternion, Vector3};
use nbv_core::cloud::PointCloud;
use nbv_core::cloud::io::{WriteOptions, write_cloud};
use nbv_core::math::Pose;
use nbv_core::mesh::io::read_mesh;
use parry3d::query::{Ray, RayCast};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

#[path = "../tests/registration_data/mod.rs"]
mod registration_data;
#[path = "support/views_dir.rs"]
mod views_dir;

use registration_data::{pixel_grid_hits, random_error};
use views_dir::{write_json, write_poses};

/// Half the field of view (degrees).
const HALF_FOV_DEG: f64 = 25.0;
/// Hits seen at a larger angle from the surface normal are dropped (degrees).
const MAX_INCIDENCE_DEG: f64 = 75.0;

#[derive(Debug, Clone, Copy, PartialEq)]
enum Path {
    Ring,
    Handheld,
}

struct Spec {
    mesh: PathBuf,
    path: Path,
    views: usize,
    points_per_view: usize,
    noise: f64,
    rotation_error_deg: f64,
    translation_error: f64,
    seed: u64,
}

fn main() -> ExitCode {
    match run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

fn run() -> Result<(), String> {
    let mut args = std::env::args().skip(1);
    let mut out: Option<PathBuf> = None;
    let mut mesh: Option<PathBuf> = None;
    let mut spec = Spec {
        mesh: PathBuf::new(),
        path: Path::Ring,
        views: 12,
        points_per_view: 4000,
        noise: 0.0003,
        rotation_error_deg: 2.0,
        translation_error: 0.005,
        seed: 7,
    };
    while let Some(arg) = args.next() {
        let mut value = |name: &str| args.next().ok_or_else(|| format!("{name} needs a value"));
        let number =
            |name: &str, v: String| v.parse::<f64>().map_err(|e| format!("{name} {v}: {e}"));
        match arg.as_str() {
            "--mesh" => mesh = Some(PathBuf::from(value(&arg)?)),
            "--path" => {
                spec.path = match value(&arg)?.as_str() {
                    "ring" => Path::Ring,
                    "handheld" => Path::Handheld,
                    other => return Err(format!("--path {other}: expected ring or handheld")),
                }
            }
            "--views" => spec.views = number(&arg, value(&arg)?)? as usize,
            "--points-per-view" => spec.points_per_view = number(&arg, value(&arg)?)? as usize,
            "--noise" => spec.noise = number(&arg, value(&arg)?)?,
            "--rotation-error-deg" => spec.rotation_error_deg = number(&arg, value(&arg)?)?,
            "--translation-error" => spec.translation_error = number(&arg, value(&arg)?)?,
            "--seed" => spec.seed = number(&arg, value(&arg)?)? as u64,
            other if other.starts_with("--") => return Err(format!("unknown option {other}")),
            other => out = Some(PathBuf::from(other)),
        }
    }
    let out = out.ok_or("usage: user_scans OUTDIR --mesh MESH [options]")?;
    spec.mesh = mesh.ok_or("--mesh MESH is missing")?;
    if spec.views < 3 || spec.points_per_view == 0 {
        return Err("need at least 3 views and 1 point per view".into());
    }
    if !(spec.noise >= 0.0 && spec.noise.is_finite()) {
        return Err(format!("--noise {}: must be a length >= 0", spec.noise));
    }
    let object = read_mesh(&spec.mesh).map_err(|e| e.to_string())?;
    let vertices: Vec<parry3d::math::Vector> = object
        .vertices
        .iter()
        .map(|p| parry3d::math::Vector::new(p.x as f32, p.y as f32, p.z as f32))
        .collect();
    let shape = parry3d::shape::TriMesh::new(vertices, object.triangles.clone())
        .map_err(|e| format!("{}: {e:?}", spec.mesh.display()))?;
    let (lo, hi) = object.vertices.iter().fold(
        (Vector3::repeat(f64::MAX), Vector3::repeat(f64::MIN)),
        |(lo, hi), p| (lo.inf(&p.coords), hi.sup(&p.coords)),
    );
    let centre = Point3::from((lo + hi) / 2.0);
    let radius = (hi - lo).norm() / 2.0;
    let distance = radius / (0.8 * HALF_FOV_DEG.to_radians().tan());

    std::fs::create_dir_all(&out).map_err(|e| format!("{}: {e}", out.display()))?;
    let mut path_rng = ChaCha8Rng::seed_from_u64(spec.seed);
    let noise = Normal::new(0.0, spec.noise).map_err(|e| e.to_string())?;
    let (mut names, mut truth, mut initial) = (Vec::new(), Vec::new(), Vec::new());
    for k in 0..spec.views {
        let pose = scanner_pose(&spec, k, &centre, distance, &mut path_rng);
        let mut rng =
            ChaCha8Rng::seed_from_u64(spec.seed.wrapping_mul(1000).wrapping_add(k as u64));
        let hits = scan(&shape, &pose, spec.points_per_view);
        if hits.is_empty() {
            return Err(format!("view {k} sees nothing of the mesh"));
        }
        let to_view = pose.inverse();
        let points: Vec<Point3<f64>> = hits
            .iter()
            .map(|(p, dir)| to_view * (p + dir * noise.sample(&mut rng)))
            .collect();
        let name = format!("view_{k}.ply");
        write_cloud(
            out.join(&name),
            &PointCloud::from_points(points),
            &WriteOptions::default(),
        )
        .map_err(|e| e.to_string())?;
        let error = if k == 0 {
            Pose::identity()
        } else {
            random_error(&mut rng, spec.rotation_error_deg, spec.translation_error)
        };
        names.push(name);
        truth.push(pose);
        initial.push(pose * error);
    }
    write_poses(&out.join("truth.json"), &names, &truth)?;
    write_poses(&out.join("initial.json"), &names, &initial)?;
    let spec_json = serde_json::json!({
        "mesh": spec.mesh,
        "path": match spec.path { Path::Ring => "ring", Path::Handheld => "handheld" },
        "views": spec.views,
        "points_per_view": spec.points_per_view,
        "noise": spec.noise,
        "rotation_error_deg": spec.rotation_error_deg,
        "translation_error": spec.translation_error,
        "distance": distance,
        "seed": spec.seed,
        "files": names,
    });
    write_json(&out.join("spec.json"), &spec_json)?;
    println!(
        "wrote {} {} views of {} from {:.2} m, truth.json, initial.json and spec.json to {}",
        spec.views,
        spec_json["path"].as_str().unwrap_or_default(),
        spec.mesh.display(),
        distance,
        out.display()
    );
    Ok(())
}

/// View `k`'s scanner pose (view frame → world; z along the optical axis, looking at the
/// object).
fn scanner_pose(
    spec: &Spec,
    k: usize,
    centre: &Point3<f64>,
    distance: f64,
    rng: &mut ChaCha8Rng,
) -> Pose {
    let step = 360.0 / spec.views as f64;
    let (azimuth, elevation, distance, target, roll) = match spec.path {
        Path::Ring => (k as f64 * step, 25.0, distance, *centre, 0.0),
        Path::Handheld => {
            let phase = k as f64 / spec.views as f64 * std::f64::consts::TAU;
            let jitter = |rng: &mut ChaCha8Rng, half: f64| rng.random_range(-half..=half);
            (
                k as f64 * step + jitter(rng, 0.3 * step),
                32.5 + 17.5 * (2.0 * phase).sin() + jitter(rng, 5.0),
                distance * (1.0 + jitter(rng, 0.15)),
                centre + Vector3::new(jitter(rng, 0.01), jitter(rng, 0.01), jitter(rng, 0.01)),
                jitter(rng, 30.0),
            )
        }
    };
    let (az, el) = (azimuth.to_radians(), elevation.to_radians());
    let towards_eye = Vector3::new(el.cos() * az.cos(), el.cos() * az.sin(), el.sin());
    let eye = target + towards_eye * distance;
    let z = -towards_eye;
    let x = Vector3::z().cross(&z).normalize();
    let y = z.cross(&x);
    let look = Rotation3::from_basis_unchecked(&[x, y, z]);
    let rotation = UnitQuaternion::from_rotation_matrix(&look)
        * UnitQuaternion::from_axis_angle(&Vector3::z_axis(), roll.to_radians());
    Isometry3::from_parts(Translation3::from(eye.coords), rotation)
}

/// `points` hits of a square pixel grid over the field of view from `pose` (the grid made
/// fine enough, then every n-th hit kept): (world point, unit ray direction).
fn scan(
    shape: &parry3d::shape::TriMesh,
    pose: &Pose,
    points: usize,
) -> Vec<(Point3<f64>, Vector3<f64>)> {
    let cast = |o: &Vector3<f64>, d: &Vector3<f64>| {
        let ray = Ray::new(
            parry3d::math::Vector::new(o.x as f32, o.y as f32, o.z as f32),
            parry3d::math::Vector::new(d.x as f32, d.y as f32, d.z as f32),
        );
        let hit = shape.cast_local_ray_and_get_normal(&ray, 10.0, true)?;
        let n = Vector3::new(
            f64::from(hit.normal.x),
            f64::from(hit.normal.y),
            f64::from(hit.normal.z),
        );
        // The face's normal, turned to face the scanner.
        let n = if n.dot(d) > 0.0 { -n } else { n };
        Some((o + d * f64::from(hit.time_of_impact), n))
    };
    let render = |n: usize| {
        pixel_grid_hits(pose, n, HALF_FOV_DEG, MAX_INCIDENCE_DEG, cast)
            .into_iter()
            .map(|(p, d)| (Point3::from(p), d))
            .collect::<Vec<_>>()
    };
    let mut n = 64;
    loop {
        let hits = render(n);
        if hits.len() >= points || n > 2048 {
            let keep = points.min(hits.len());
            return (0..keep).map(|i| hits[i * hits.len() / keep]).collect();
        }
        let share = hits.len().max(1) as f64 / (n * n) as f64;
        n = (((points as f64 / share).sqrt() * 1.05).ceil() as usize).max(n + n / 10 + 1);
    }
}
