//! A user's scans of a mesh, as a range scanner outside the twin takes them: a pinhole with
//! a 50° field of view at a distance that fits the object, keeping the hits whose incidence
//! is under 75°, with Gaussian noise along each ray, each view in its own sensor frame and
//! its reported pose off by a random error (none on view 0, the reference).
//!
//! - [`ScanPath::Ring`]: a turntable — the object turns under a fixed scanner, which is
//!   the scanner going round it at one elevation, views evenly spaced over 360°;
//! - [`ScanPath::Handheld`]: a hand-held scanner walked once round the object: the azimuth
//!   steps, the elevation (10–55°), the distance, the point looked at and the roll about
//!   the optical axis all wander from view to view.
//!
//! Included beside `registration_data` (`#[path]`, as a sibling module), whose
//! generators it shares.

#![allow(dead_code)]

use nalgebra::{Isometry3, Point3, Rotation3, Translation3, UnitQuaternion, Vector3};
use nbv_core::cloud::PointCloud;
use nbv_core::math::Pose;
use nbv_core::mesh::TriMesh;
use parry3d::query::{Ray, RayCast};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

use crate::registration_data::{Scenario, pixel_grid_hits, random_error};

/// Half the field of view (degrees).
const HALF_FOV_DEG: f64 = 25.0;
/// Hits seen at a larger angle from the surface normal are dropped (degrees).
const MAX_INCIDENCE_DEG: f64 = 75.0;

/// How the scanner goes round the object.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ScanPath {
    Ring,
    Handheld,
}

impl ScanPath {
    /// The path's name on the command line and in `spec.json`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Ring => "ring",
            Self::Handheld => "handheld",
        }
    }
}

/// What to scan.
#[derive(Debug, Clone)]
pub struct MeshScanSpec {
    pub path: ScanPath,
    pub views: usize,
    pub points_per_view: usize,
    /// σ of the range noise along each ray (m).
    pub noise: f64,
    pub rotation_error_deg: f64,
    /// Length of the translation error (m).
    pub translation_error: f64,
    pub seed: u64,
}

impl Default for MeshScanSpec {
    fn default() -> Self {
        Self {
            path: ScanPath::Ring,
            views: 12,
            points_per_view: 4000,
            noise: 0.0003,
            rotation_error_deg: 2.0,
            translation_error: 0.005,
            seed: 7,
        }
    }
}

/// The scans of `object` (standing as it is in its file) by `spec`, and the scanner's
/// distance from the object's centre (m).
pub fn scan_mesh(object: &TriMesh, spec: &MeshScanSpec) -> Result<(Scenario, f64), String> {
    if spec.views < 3 || spec.points_per_view == 0 {
        return Err("need at least 3 views and 1 point per view".into());
    }
    if !(spec.noise >= 0.0 && spec.noise.is_finite()) {
        return Err(format!("noise {}: must be a length >= 0", spec.noise));
    }
    let noise = Normal::new(0.0, spec.noise).map_err(|e| e.to_string())?;
    let vertices: Vec<parry3d::math::Vector> = object
        .vertices
        .iter()
        .map(|p| parry3d::math::Vector::new(p.x as f32, p.y as f32, p.z as f32))
        .collect();
    let shape = parry3d::shape::TriMesh::new(vertices, object.triangles.clone())
        .map_err(|e| format!("{e:?}"))?;
    let (lo, hi) = object.vertices.iter().fold(
        (Vector3::repeat(f64::MAX), Vector3::repeat(f64::MIN)),
        |(lo, hi), p| (lo.inf(&p.coords), hi.sup(&p.coords)),
    );
    let centre = Point3::from((lo + hi) / 2.0);
    let radius = (hi - lo).norm() / 2.0;
    let distance = radius / (0.8 * HALF_FOV_DEG.to_radians().tan());

    let mut path_rng = ChaCha8Rng::seed_from_u64(spec.seed);
    let mut scenario = Scenario {
        views: Vec::new(),
        truth: Vec::new(),
        initial: Vec::new(),
    };
    for k in 0..spec.views {
        let pose = scanner_pose(spec, k, &centre, distance, &mut path_rng);
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
        let error = if k == 0 {
            Pose::identity()
        } else {
            random_error(&mut rng, spec.rotation_error_deg, spec.translation_error)
        };
        scenario.views.push(PointCloud::from_points(points));
        scenario.truth.push(pose);
        scenario.initial.push(pose * error);
    }
    Ok((scenario, distance))
}

/// View `k`'s scanner pose (view frame → world; z along the optical axis, looking at the
/// object).
fn scanner_pose(
    spec: &MeshScanSpec,
    k: usize,
    centre: &Point3<f64>,
    distance: f64,
    rng: &mut ChaCha8Rng,
) -> Pose {
    let step = 360.0 / spec.views as f64;
    let (azimuth, elevation, distance, target, roll) = match spec.path {
        ScanPath::Ring => (k as f64 * step, 25.0, distance, *centre, 0.0),
        ScanPath::Handheld => {
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
