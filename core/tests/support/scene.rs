//! A synthetic table-top environment at the paper's scale, built analytically: the Comau
//! robot, a table (x 0.35–1.35 m, y ±0.6 m, top at z 0.25 m), a wall behind it, objects on
//! the table; a mid-range sweep cast against it fills the paper's 60×70×30 grid of 2 cm
//! voxels (126K voxels), from which the reduced map is computed.
#![allow(dead_code)]

use nalgebra::{Point3, Vector3};
use nbv_core::kinematics::{Joints, Robot};
use nbv_core::nbv::{NbvParams, NbvPreset};
use nbv_core::occupancy::{GridGeometry, OccupancyGrid, OccupancyParams, ReducedMap};
use nbv_core::planning::Obstacle;
use nbv_core::rig::DepthCameraSpec;

/// A solid of the analytic scene.
#[derive(Debug, Clone, Copy)]
pub enum Solid {
    /// Axis-aligned box (min, max).
    Box([f64; 3], [f64; 3]),
    /// Vertical cylinder: centre (x, y), radius, z range.
    Cylinder([f64; 2], f64, [f64; 2]),
}

/// Table top (the table is a box from the floor).
pub const TABLE: Solid = Solid::Box([0.35, -0.6, 0.0], [1.35, 0.6, 0.25]);
/// The wall behind the table.
pub const WALL: Solid = Solid::Box([1.42, -0.7, 0.0], [1.47, 0.7, 0.9]);
/// Objects on the table; index 1 (the "jug") is the object explored in the tests.
pub const OBJECTS: [Solid; 3] = [
    Solid::Box([0.60, -0.30, 0.25], [0.72, -0.18, 0.45]),
    Solid::Cylinder([0.85, 0.15], 0.06, [0.25, 0.50]),
    Solid::Box([1.00, -0.05, 0.25], [1.06, 0.01, 0.55]),
];

/// Nearest intersection distance of a ray (unit `d`) with a solid.
pub fn intersect(solid: &Solid, o: &Point3<f64>, d: &Vector3<f64>) -> Option<f64> {
    match *solid {
        Solid::Box(lo, hi) => {
            let (mut t0, mut t1) = (0.0f64, f64::INFINITY);
            for a in 0..3 {
                if d[a] == 0.0 {
                    if o[a] < lo[a] || o[a] > hi[a] {
                        return None;
                    }
                } else {
                    let (ta, tb) = ((lo[a] - o[a]) / d[a], (hi[a] - o[a]) / d[a]);
                    t0 = t0.max(ta.min(tb));
                    t1 = t1.min(ta.max(tb));
                }
            }
            (t0 <= t1).then_some(t0)
        }
        Solid::Cylinder(c, r, z) => {
            let (ox, oy) = (o.x - c[0], o.y - c[1]);
            let a = d.x * d.x + d.y * d.y;
            let mut best: Option<f64> = None;
            if a > 0.0 {
                let b = ox * d.x + oy * d.y;
                let disc = b * b - a * (ox * ox + oy * oy - r * r);
                if disc >= 0.0 {
                    let t = (-b - disc.sqrt()) / a;
                    let zt = o.z + t * d.z;
                    if t >= 0.0 && zt >= z[0] && zt <= z[1] {
                        best = Some(t);
                    }
                }
            }
            // Top cap.
            if d.z < 0.0 {
                let t = (z[1] - o.z) / d.z;
                let (px, py) = (ox + t * d.x, oy + t * d.y);
                if t >= 0.0 && px * px + py * py <= r * r && best.is_none_or(|b| t < b) {
                    best = Some(t);
                }
            }
            best
        }
    }
}

/// All solids: the table, the wall, the objects, and the floor as a large thin box.
pub fn solids() -> Vec<Solid> {
    let mut v = vec![TABLE, WALL, Solid::Box([-5.0, -5.0, -0.1], [5.0, 5.0, 0.0])];
    v.extend(OBJECTS);
    v
}

/// Nearest hit of a ray with the scene: (distance, index into [`solids`]).
pub fn cast(o: &Point3<f64>, d: &Vector3<f64>) -> Option<(f64, usize)> {
    solids()
        .iter()
        .enumerate()
        .filter_map(|(i, s)| intersect(s, o, d).map(|t| (t, i)))
        .min_by(|a, b| a.0.total_cmp(&b.0))
}

/// The paper's grid: 1.20 × 1.40 × 0.60 m at 2 cm over the table (60 × 70 × 30 voxels).
pub fn geometry() -> GridGeometry {
    GridGeometry::new(
        Point3::new(0.30, -0.70, 0.23),
        Point3::new(1.50, 0.70, 0.83),
        0.02,
    )
    .unwrap()
}

/// A mid-range sweep: 275 lines × 200 rays of a 70° fan in the x–z plane, from a scanner
/// at x = 0.25 m, z = 1.35 m moving along y from −0.6 to 0.6 m, the fan centred 55° below
/// the horizontal; returns within 0.7–3.0 m. Returns (origins, points, solid index).
pub fn sweep() -> (Vec<Point3<f64>>, Vec<Point3<f64>>, Vec<usize>) {
    let (mut origins, mut points, mut labels) = (Vec::new(), Vec::new(), Vec::new());
    for line in 0..275 {
        let y = -0.6 + 1.2 * line as f64 / 274.0;
        let o = Point3::new(0.25, y, 1.35);
        for k in 0..200 {
            let depression = (55.0 - 35.0 + 70.0 * k as f64 / 199.0).to_radians();
            let d = Vector3::new(depression.cos(), 0.0, -depression.sin());
            if let Some((t, i)) = cast(&o, &d)
                && (0.7..=3.0).contains(&t)
            {
                origins.push(o);
                points.push(o + t * d);
                labels.push(i);
            }
        }
    }
    (origins, points, labels)
}

/// The grid after the sweep and its reduced map, and the sweep's points on object `j`.
pub fn mapped_scene(object: usize) -> (OccupancyGrid, ReducedMap, Vec<Point3<f64>>) {
    let mut grid = OccupancyGrid::new(geometry(), OccupancyParams::default()).unwrap();
    let (origins, points, labels) = sweep();
    grid.insert_rays(&origins, &points, 3.0).unwrap();
    let map = ReducedMap::from_grid(&grid);
    let first_object = solids().len() - OBJECTS.len();
    let on_object = points
        .iter()
        .zip(&labels)
        .filter(|(_, l)| **l == first_object + object)
        .map(|(p, _)| *p)
        .collect();
    (grid, map, on_object)
}

/// The robot.
pub fn robot() -> Robot {
    nbv_core::kinematics::comau_smart_six().unwrap()
}

/// The Dinast IPA-1110 as the paper gives it.
pub fn dinast() -> DepthCameraSpec {
    DepthCameraSpec::ipa1110()
}

/// The table and the wall as known obstacles.
pub fn known_obstacles() -> Vec<Obstacle> {
    let to_obstacle = |name: &str, s: &Solid| match *s {
        Solid::Box(lo, hi) => Obstacle::cuboid(
            name,
            std::array::from_fn(|a| 0.5 * (lo[a] + hi[a])),
            std::array::from_fn(|a| 0.5 * (hi[a] - lo[a])),
        ),
        Solid::Cylinder(..) => unreachable!("only boxes are known obstacles"),
    };
    vec![to_obstacle("table", &TABLE), to_obstacle("wall", &WALL)]
}

/// The arm raised above the scene with the sensors looking down.
pub fn home() -> Joints {
    Joints::new(
        0.0,
        0.0,
        -std::f64::consts::FRAC_PI_2,
        0.0,
        std::f64::consts::FRAC_PI_2,
        0.0,
    )
}

/// The table and the wall as boxes (for the independent checker).
pub fn known_boxes() -> Vec<Solid> {
    vec![TABLE, WALL]
}

/// The centroid of the sweep's points on object `j` (the paper's P_j^0 centroid).
pub fn centroid(points: &[Point3<f64>]) -> Point3<f64> {
    let sum: Vector3<f64> = points.iter().map(|p| p.coords).sum();
    Point3::from(sum / points.len() as f64)
}

/// A simulated depth frame: every `stride`-th pixel of `camera` cast from `pose` against
/// the scene, returns within the camera's range, as world points.
pub fn depth_frame(
    pose: &nbv_core::math::Pose,
    camera: &DepthCameraSpec,
    stride: usize,
) -> Vec<Point3<f64>> {
    let o = Point3::from(pose.translation.vector);
    let mut out = Vec::new();
    for v in (0..camera.height).step_by(stride) {
        for u in (0..camera.width).step_by(stride) {
            let d = (pose.rotation * camera.pixel_ray(u, v)).normalize();
            if let Some((t, _)) = cast(&o, &d)
                && t >= camera.range[0]
                && t <= camera.range[1]
            {
                out.push(o + t * d);
            }
        }
    }
    out
}

/// Algorithm 2 as the paper prints it: its preset's sphere and eq. (4) as printed, with
/// eq. (3)'s roll only.
#[allow(dead_code)]
pub fn paper_nbv() -> NbvParams {
    NbvParams {
        roll_candidates: 1,
        ..NbvPreset::Paper.params()
    }
}
