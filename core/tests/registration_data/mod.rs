//! Synthetic multi-view data for registration tests and benches: a smooth, bumpy closed
//! surface (a rounded box with non-symmetric bumps, star-shaped about its centre) seen by
//! depth sensors on a ring around it. Each view casts a pixel grid of rays from its
//! sensor (first hit, grazing hits beyond `max_incidence_deg` dropped), thins the hits to
//! the requested count by a regular stride, adds Gaussian range noise (seeded ChaCha8),
//! and is expressed in the sensor's own frame (z forward). Initial poses are the true
//! sensor poses with a known random error (none on view 0).

#![allow(dead_code)]

use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};
use nbv_core::cloud::PointCloud;
use nbv_core::math::Pose;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal, StandardNormal};

/// Centre of the object (world frame, metres).
pub const CENTRE: [f64; 3] = [0.6, 0.0, 0.12];

/// What to generate.
#[derive(Debug, Clone)]
pub struct Spec {
    /// Number of views.
    pub views: usize,
    /// Points per view.
    pub points_per_view: usize,
    /// Standard deviation of the Gaussian noise per coordinate (metres).
    pub noise: f64,
    /// Angle of the rotation error of every initial pose but view 0 (degrees).
    pub rotation_error_deg: f64,
    /// Length of the translation error of every initial pose but view 0 (metres).
    pub translation_error: f64,
    /// Azimuth step between consecutive sensors (degrees).
    pub azimuth_step_deg: f64,
    /// Hits whose ray meets the surface normal at more than this angle are dropped
    /// (degrees).
    pub max_incidence_deg: f64,
    /// View 0 looks down on the object from above (65° elevation, 0.45 m away) and
    /// overlaps every other view, like the paper's mid-range view; the others are on the
    /// ring, starting at azimuth 0.
    pub top_view: bool,
    /// Seed.
    pub seed: u64,
}

impl Default for Spec {
    fn default() -> Self {
        Self {
            views: 5,
            points_per_view: 2000,
            noise: 0.0005,
            rotation_error_deg: 3.0,
            translation_error: 0.02,
            azimuth_step_deg: 36.0,
            max_incidence_deg: 75.0,
            top_view: false,
            seed: 7,
        }
    }
}

/// Generated views with their true and initial poses.
pub struct Scenario {
    /// Views in their own sensor frames.
    pub views: Vec<PointCloud>,
    /// True sensor poses (view → world).
    pub truth: Vec<Pose>,
    /// Initial (erroneous) sensor poses (view → world).
    pub initial: Vec<Pose>,
}

/// Surface radius along unit direction `u` (metres): an ellipsoid (half-axes 9 × 6 × 7
/// cm) with smooth, non-symmetric bumps: broad ones of 5–7 mm and finer ones of 2–3 mm
/// a few centimetres across.
pub fn radius(u: &Vector3<f64>) -> f64 {
    let theta = u.z.clamp(-1.0, 1.0).acos();
    let phi = u.y.atan2(u.x);
    let base = 1.0 / ((u.x / 0.09).powi(2) + (u.y / 0.06).powi(2) + (u.z / 0.07).powi(2)).sqrt();
    base * (1.0
        + 0.10 * (5.0 * theta).sin() * (3.0 * phi).cos()
        + 0.07 * (7.0 * phi + 1.0).sin() * theta.sin()
        + 0.05 * (6.0 * theta + 0.5).cos() * (4.0 * phi).sin()
        + 0.04 * (11.0 * phi + 2.0).sin() * (9.0 * theta).sin())
}

/// Sensor pose of view `k`: on a ring 0.35 m from the centre, 20° above it, or for the
/// top view 0.45 m away at 65° elevation; z axis looking at the centre.
pub fn sensor_pose(k: usize, spec: &Spec) -> Pose {
    let (ring_index, elevation, distance) = match (spec.top_view, k) {
        (true, 0) => (0.5 * (spec.views as f64 - 2.0), 65.0, 0.45),
        (true, k) => (k as f64 - 1.0, 20.0, 0.35),
        (false, k) => (k as f64, 20.0, 0.35),
    };
    let az = (ring_index * spec.azimuth_step_deg).to_radians();
    let el = f64::to_radians(elevation);
    let dir = Vector3::new(el.cos() * az.cos(), el.cos() * az.sin(), el.sin());
    let centre = Vector3::from(CENTRE);
    let eye = centre + distance * dir;
    let z = -dir;
    let x = Vector3::z().cross(&z).normalize();
    let y = z.cross(&x);
    let rot = nalgebra::Rotation3::from_basis_unchecked(&[x, y, z]);
    Isometry3::from_parts(
        Translation3::from(eye),
        UnitQuaternion::from_rotation_matrix(&rot),
    )
}

/// A random rigid error: rotation of `deg` about a random axis, translation of `len` in a
/// random direction.
pub fn random_error(rng: &mut ChaCha8Rng, deg: f64, len: f64) -> Pose {
    let axis = random_unit(rng);
    let dir = random_unit(rng);
    Isometry3::new(dir * len, axis * deg.to_radians())
}

fn random_unit(rng: &mut ChaCha8Rng) -> Vector3<f64> {
    loop {
        let v = Vector3::new(
            StandardNormal.sample(rng),
            StandardNormal.sample(rng),
            StandardNormal.sample(rng),
        );
        let n: f64 = v.norm();
        if n > 1e-6 {
            return v / n;
        }
    }
}

/// Signed distance-like function of the surface: negative inside.
fn level(x: &Vector3<f64>) -> f64 {
    let d = x - Vector3::from(CENTRE);
    let n = d.norm();
    if n < 1e-9 {
        return -1.0;
    }
    n - radius(&(d / n))
}

/// First hit of the ray `origin + t·dir` (unit `dir`) with the surface, and the unit
/// outward normal there.
fn cast(origin: &Vector3<f64>, dir: &Vector3<f64>) -> Option<(Vector3<f64>, Vector3<f64>)> {
    // March through the bounding sphere in 1 mm steps, then bisect the sign change.
    let bound = 0.16;
    let oc = origin - Vector3::from(CENTRE);
    let b = oc.dot(dir);
    let disc = b * b - (oc.norm_squared() - bound * bound);
    if disc <= 0.0 {
        return None;
    }
    let (t_in, t_out) = (-b - disc.sqrt(), -b + disc.sqrt());
    let step = 0.001;
    let mut t = t_in.max(0.0);
    let mut prev = t;
    while t <= t_out {
        if level(&(origin + t * dir)) < 0.0 {
            let (mut lo, mut hi) = (prev, t);
            for _ in 0..40 {
                let mid = 0.5 * (lo + hi);
                if level(&(origin + mid * dir)) < 0.0 {
                    hi = mid;
                } else {
                    lo = mid;
                }
            }
            let x = origin + hi * dir;
            let h = 1e-6;
            let grad = Vector3::new(
                level(&(x + Vector3::x() * h)) - level(&(x - Vector3::x() * h)),
                level(&(x + Vector3::y() * h)) - level(&(x - Vector3::y() * h)),
                level(&(x + Vector3::z() * h)) - level(&(x - Vector3::z() * h)),
            );
            return Some((x, grad.normalize()));
        }
        prev = t;
        t += step;
    }
    None
}

/// Hits of an n × n pixel grid over a 52° field of view from `pose`, in raster order:
/// (world point, ray direction in world).
fn render(pose: &Pose, n: usize, max_incidence_deg: f64) -> Vec<(Vector3<f64>, Vector3<f64>)> {
    pixel_grid_hits(pose, n, 26.0, max_incidence_deg, cast)
}

/// Hits of an n × n pixel grid over a square field of view of `2·half_fov_deg` from
/// `pose` (z forward), in raster order: (world point, unit ray direction in world), the
/// first hit of each ray by `cast(origin, direction)` (point and outward unit normal),
/// those seen at more than `max_incidence_deg` from the normal dropped.
pub fn pixel_grid_hits(
    pose: &Pose,
    n: usize,
    half_fov_deg: f64,
    max_incidence_deg: f64,
    cast: impl Fn(&Vector3<f64>, &Vector3<f64>) -> Option<(Vector3<f64>, Vector3<f64>)>,
) -> Vec<(Vector3<f64>, Vector3<f64>)> {
    let half = half_fov_deg.to_radians().tan();
    let cos_max = max_incidence_deg.to_radians().cos();
    let origin = pose.translation.vector;
    let mut hits = Vec::new();
    for row in 0..n {
        for col in 0..n {
            let x = half * (2.0 * (col as f64 + 0.5) / n as f64 - 1.0);
            let y = half * (2.0 * (row as f64 + 0.5) / n as f64 - 1.0);
            let dir = pose.rotation * Vector3::new(x, y, 1.0).normalize();
            if let Some((p, normal)) = cast(&origin, &dir)
                && -normal.dot(&dir) >= cos_max
            {
                hits.push((p, dir));
            }
        }
    }
    hits
}

/// Generates the scenario of `spec`.
pub fn generate(spec: &Spec) -> Scenario {
    let noise = Normal::new(0.0, spec.noise.max(0.0)).unwrap();
    let mut views = Vec::new();
    let mut truth = Vec::new();
    let mut initial = Vec::new();
    for k in 0..spec.views {
        let mut rng =
            ChaCha8Rng::seed_from_u64(spec.seed.wrapping_mul(1000).wrapping_add(k as u64));
        let pose = sensor_pose(k, spec);
        // Pick the grid so that there are at least as many hits as points wanted.
        let trial = 48;
        let coverage = render(&pose, trial, spec.max_incidence_deg).len().max(1) as f64
            / (trial * trial) as f64;
        let mut n = ((spec.points_per_view as f64 / coverage).sqrt() * 1.03).ceil() as usize;
        let hits = loop {
            let hits = render(&pose, n, spec.max_incidence_deg);
            if hits.len() >= spec.points_per_view {
                break hits;
            }
            n += n / 20 + 1;
        };
        let world_to_view = pose.inverse();
        let points = (0..spec.points_per_view)
            .map(|i| {
                let (p, dir) = hits[i * hits.len() / spec.points_per_view];
                let p = if spec.noise > 0.0 {
                    p + dir * noise.sample(&mut rng)
                } else {
                    p
                };
                world_to_view * Point3::from(p)
            })
            .collect();
        let error = if k == 0 {
            Pose::identity()
        } else {
            random_error(&mut rng, spec.rotation_error_deg, spec.translation_error)
        };
        views.push(PointCloud::from_points(points));
        truth.push(pose);
        initial.push(pose * error);
    }
    Scenario {
        views,
        truth,
        initial,
    }
}

/// Like [`generate`] but every view takes exactly the same surface samples wherever it
/// overlaps another (no noise): a pool of `points_per_view` × `views` random surface
/// points, each given to every view whose sensor faces it within 65°. With exact
/// correspondences available, registration must be exact.
pub fn generate_shared(spec: &Spec) -> Scenario {
    let centre = Vector3::from(CENTRE);
    let mut rng = ChaCha8Rng::seed_from_u64(spec.seed);
    let pool: Vec<(Vector3<f64>, Vector3<f64>)> = (0..spec.points_per_view * spec.views)
        .map(|_| {
            let u = random_unit(&mut rng);
            (centre + radius(&u) * u, u)
        })
        .collect();
    let cos_cap = 65f64.to_radians().cos();
    let mut views = Vec::new();
    let mut truth = Vec::new();
    let mut initial = Vec::new();
    for k in 0..spec.views {
        let pose = sensor_pose(k, spec);
        let towards = (pose.translation.vector - centre).normalize();
        let world_to_view = pose.inverse();
        let points = pool
            .iter()
            .filter(|(_, u)| u.dot(&towards) > cos_cap)
            .map(|(p, _)| world_to_view * Point3::from(*p))
            .collect();
        let error = if k == 0 {
            Pose::identity()
        } else {
            random_error(&mut rng, spec.rotation_error_deg, spec.translation_error)
        };
        views.push(PointCloud::from_points(points));
        truth.push(pose);
        initial.push(pose * error);
    }
    Scenario {
        views,
        truth,
        initial,
    }
}

/// Rotation (degrees) and translation (metres) error of an estimated sensor pose.
pub fn pose_error(estimate: &Pose, truth: &Pose) -> (f64, f64) {
    let d = truth.inverse() * estimate;
    (d.rotation.angle().to_degrees(), d.translation.vector.norm())
}

/// Worst rotation and translation errors over all views.
pub fn worst_error(estimates: &[Pose], truth: &[Pose]) -> (f64, f64) {
    estimates
        .iter()
        .zip(truth)
        .map(|(e, t)| pose_error(e, t))
        .fold((0.0, 0.0), |(r, t), (er, et)| (r.max(er), t.max(et)))
}

/// Worst over views of the RMS displacement of a view's points between the estimated and
/// the true pose (metres): the registration error on the object itself.
pub fn worst_point_error(views: &[PointCloud], estimates: &[Pose], truth: &[Pose]) -> f64 {
    views
        .iter()
        .zip(estimates.iter().zip(truth))
        .map(|(v, (e, t))| {
            let sq: f64 = v
                .points
                .iter()
                .map(|p| (e * p - t * p).norm_squared())
                .sum();
            (sq / v.len() as f64).sqrt()
        })
        .fold(0.0, f64::max)
}
