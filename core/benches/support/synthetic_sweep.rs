//! The paper-scale synthetic mid-range sweep shared by the occupancy benchmark and the
//! OctoMap comparison (`examples/occupancy_peer.rs`): a table plane at z = 0.25 m with
//! boxes on it, swept by a line scanner (275 lines × 200 rays, 70° fan) moving along y
//! about 1 m above. Analytic ray casting: every run gives the same rays.

#![allow(dead_code)]

use nalgebra::{Point3, Vector3};
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};

/// Axis-aligned boxes standing on the table: (min, max).
pub const BOXES: [([f64; 3], [f64; 3]); 5] = [
    ([0.55, -0.40, 0.25], [0.70, -0.25, 0.45]),
    ([0.80, -0.10, 0.25], [0.90, 0.05, 0.55]),
    ([0.60, 0.20, 0.25], [0.75, 0.32, 0.35]),
    ([1.00, 0.35, 0.25], [1.12, 0.50, 0.40]),
    ([1.30, -0.60, 0.25], [1.40, 0.60, 0.70]),
];
/// Height of the table plane.
pub const TABLE_Z: f64 = 0.25;
/// Scan lines of the sweep.
pub const LINES: usize = 275;
/// Rays per scan line.
pub const RAYS: usize = 200;

/// Nearest hit of a ray with the table plane and the boxes.
fn cast(o: &Point3<f64>, d: &Vector3<f64>) -> Option<f64> {
    let mut best = if d.z < 0.0 {
        Some((TABLE_Z - o.z) / d.z)
    } else {
        None
    };
    for (lo, hi) in BOXES {
        let (mut t0, mut t1) = (0.0f64, f64::INFINITY);
        for a in 0..3 {
            if d[a] == 0.0 {
                if o[a] < lo[a] || o[a] > hi[a] {
                    t0 = f64::INFINITY;
                }
                continue;
            }
            let (ta, tb) = ((lo[a] - o[a]) / d[a], (hi[a] - o[a]) / d[a]);
            t0 = t0.max(ta.min(tb));
            t1 = t1.min(ta.max(tb));
        }
        if t0 <= t1 && best.is_none_or(|b| t0 < b) {
            best = Some(t0);
        }
    }
    best
}

/// The sweep: (origins, points) of every return within the LMS400's 0.7–3.0 m, line
/// after line (all returns of a line share its origin). No noise; the scanner's origins
/// and several box faces lie exactly on 2 cm voxel boundaries.
pub fn sweep() -> (Vec<Point3<f64>>, Vec<Point3<f64>>) {
    sweep_from(Vector3::zeros())
}

/// The same sweep from origins moved off the 2 cm lattice by a fraction of a millimetre,
/// with the LMS400's Gaussian range noise (σ = 2 mm, seeded): no return and no scan plane
/// lies exactly on a voxel boundary, as with a real sensor, so that two mappers that
/// round boundary coordinates differently (OctoMap works in f32) still agree.
pub fn noisy_sweep(seed: u64) -> (Vec<Point3<f64>>, Vec<Point3<f64>>) {
    let (origins, mut points) = sweep_from(Vector3::new(0.00131, 0.00073, 0.00117));
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let noise = Normal::new(0.0, 0.002).unwrap();
    for (o, p) in origins.iter().zip(points.iter_mut()) {
        let d = (*p - o).normalize();
        *p += d * noise.sample(&mut rng);
    }
    (origins, points)
}

fn sweep_from(offset: Vector3<f64>) -> (Vec<Point3<f64>>, Vec<Point3<f64>>) {
    let fov = 70f64.to_radians();
    let mut origins = Vec::new();
    let mut points = Vec::new();
    for l in 0..LINES {
        let o = Point3::new(0.10, -0.55 + 1.1 * l as f64 / (LINES - 1) as f64, 1.20) + offset;
        for r in 0..RAYS {
            // Angle from the vertical, in the x–z plane: 0° (straight down) to 70° (forward).
            let a = fov * r as f64 / (RAYS - 1) as f64;
            let d = Vector3::new(a.sin(), 0.0, -a.cos());
            if let Some(t) = cast(&o, &d).filter(|t| (0.7..=3.0).contains(t)) {
                origins.push(o);
                points.push(o + d * t);
            }
        }
    }
    (origins, points)
}
