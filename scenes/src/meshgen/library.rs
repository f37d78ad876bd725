//! The object library: the six objects of the paper's Figure 5 ([`ObjectKind::PAPER`]) and
//! five shapes beyond them, as watertight meshes at real sizes (metres), each a smooth
//! signed-distance solid meshed by marching tetrahedra.
//!
//! | object | shape | size (x × y × z, approx.) |
//! |---|---|---|
//! | `jug` | lathe body (bulged, flared lip) + spout + tube handle | 0.18 × 0.14 × 0.20 |
//! | `bottle-a` | 0.5 l water bottle: grooved body, shoulder, neck ring, cap | Ø 0.067 × 0.21 |
//! | `bottle-b` | 1 l bottle: waisted grip, conical shoulder, cap | Ø 0.08 × 0.25 |
//! | `mallet` | rubber head (cylinder) + tapered handle, lying on the table | 0.28 × 0.10 × 0.055 |
//! | `horse` | toy horse: body, four legs, neck, head, ears, tail | 0.19 × 0.05 × 0.17 |
//! | `box` | cardboard box with rounded edges | 0.15 × 0.10 × 0.08 |
//! | `figurine` | standing cat figurine: legs 7 mm thick, ears, a 5.6 mm tail curling up | 0.15 × 0.034 × 0.145 |
//! | `pitcher` | hollow vessel, open top, 4 mm wall, C handle | 0.145 × 0.11 × 0.18 |
//! | `tall-bottle` | wine bottle: body, round shoulder, long neck, lip ring | Ø 0.05 × 0.30 |
//! | `spatula` | kitchen turner lying flat: handle, neck, 5 mm blade | 0.25 × 0.075 × 0.018 |
//! | `bowl` | low wide bowl, hollow, open top, 4 mm wall | Ø 0.18 × 0.06 |
//!
//! The generator draws from the paper's six by default, from all eleven on request
//! ([`crate::generator::ShapeSet`]).
//!
//! The exact bounds are those of the generated meshes ([`ObjectKind::mesh`]); `nbv scene
//! describe` prints them.

use super::decimate::decimate;
use super::marching_tetrahedra::{Grid, polygonize};
use super::sdf::{
    Lathe, above_floor, capsule, ellipsoid, round_box, round_cylinder, smooth_union, tube,
};
use nalgebra::{Point3, Vector3};
use nbv_core::mesh::TriMesh;
use nbv_core::mesh::io::{MeshIoError, write_stl_file};

/// Triangle budget of an object mesh after simplification.
const TARGET_TRIANGLES: usize = 16_000;
/// Largest quadric error (m², area-weighted squared distance) a simplification step may add.
const MAX_COLLAPSE_ERROR: f64 = 2e-11;

/// One of the library's objects.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum ObjectKind {
    /// A jug with a spout and a handle, ~0.20 m tall (a solid body).
    Jug,
    /// A 0.5 l plastic water bottle, ~0.21 m tall, Ø 0.065 m.
    BottleA,
    /// A 1 l plastic bottle with a waisted grip, ~0.25 m tall, Ø 0.08 m.
    BottleB,
    /// A rubber mallet lying on the table, ~0.28 m long.
    Mallet,
    /// A toy horse standing on four legs, ~0.18 m long.
    Horse,
    /// A cardboard box, 0.15 × 0.10 × 0.08 m.
    Box,
    /// A cat figurine standing on four thin legs (7 mm), with ears and a thin tail;
    /// ~0.15 m long.
    Figurine,
    /// A hollow pitcher with an open top, a 4 mm wall and a handle, ~0.18 m tall.
    Pitcher,
    /// A tall narrow wine bottle, Ø 0.05 × 0.30 m.
    TallBottle,
    /// A kitchen spatula lying flat, ~0.25 m long, ~0.018 m tall.
    Spatula,
    /// A low wide bowl, hollow with an open top, Ø 0.18 × 0.06 m.
    Bowl,
}

impl ObjectKind {
    /// The six objects of the paper's Figure 5, in a fixed order (the generator's default
    /// set).
    pub const PAPER: [ObjectKind; 6] = [
        ObjectKind::Jug,
        ObjectKind::BottleA,
        ObjectKind::BottleB,
        ObjectKind::Mallet,
        ObjectKind::Horse,
        ObjectKind::Box,
    ];

    /// Every object, in a fixed order: the paper's six, then the other five.
    pub const ALL: [ObjectKind; 11] = [
        ObjectKind::Jug,
        ObjectKind::BottleA,
        ObjectKind::BottleB,
        ObjectKind::Mallet,
        ObjectKind::Horse,
        ObjectKind::Box,
        ObjectKind::Figurine,
        ObjectKind::Pitcher,
        ObjectKind::TallBottle,
        ObjectKind::Spatula,
        ObjectKind::Bowl,
    ];

    /// The object's name, which is also its mesh file stem (`<name>.stl`).
    pub fn name(self) -> &'static str {
        match self {
            ObjectKind::Jug => "jug",
            ObjectKind::BottleA => "bottle-a",
            ObjectKind::BottleB => "bottle-b",
            ObjectKind::Mallet => "mallet",
            ObjectKind::Horse => "horse",
            ObjectKind::Box => "box",
            ObjectKind::Figurine => "figurine",
            ObjectKind::Pitcher => "pitcher",
            ObjectKind::TallBottle => "tall-bottle",
            ObjectKind::Spatula => "spatula",
            ObjectKind::Bowl => "bowl",
        }
    }

    /// The object with this name, if any.
    ///
    /// ```
    /// use nbv_scenes::meshgen::ObjectKind;
    /// assert_eq!(ObjectKind::from_name("horse"), Some(ObjectKind::Horse));
    /// assert_eq!(ObjectKind::from_name("cat"), None);
    /// ```
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|k| k.name() == name)
    }

    /// Marching-tetrahedra cell size (m): fine enough for the thinnest part, coarse enough
    /// to keep the mesh under ~20K triangles.
    fn cell(self) -> f64 {
        match self {
            ObjectKind::Jug => 0.0034,
            ObjectKind::BottleA => 0.0025,
            ObjectKind::BottleB => 0.0030,
            ObjectKind::Mallet => 0.0025,
            ObjectKind::Horse => 0.0022,
            ObjectKind::Box => 0.0045,
            // Legs 7 mm and a tail 5.6 mm thick: four cells or more across.
            ObjectKind::Figurine => 0.0014,
            // Walls 4 mm thick: under two cells across, which marching tetrahedra still
            // closes (finer cells leave more triangles than the budget: the
            // simplification stops at about a tenth of the raw count).
            ObjectKind::Pitcher => 0.0024,
            ObjectKind::TallBottle => 0.0025,
            // Blade 5 mm thick: about three cells.
            ObjectKind::Spatula => 0.0018,
            ObjectKind::Bowl => 0.0022,
        }
    }

    /// The signed distance of the solid and a box that contains it.
    fn solid(self) -> Solid {
        match self {
            ObjectKind::Jug => jug(),
            ObjectKind::BottleA => bottle_a(),
            ObjectKind::BottleB => bottle_b(),
            ObjectKind::Mallet => mallet(),
            ObjectKind::Horse => horse(),
            ObjectKind::Box => cardboard_box(),
            ObjectKind::Figurine => figurine(),
            ObjectKind::Pitcher => pitcher(),
            ObjectKind::TallBottle => tall_bottle(),
            ObjectKind::Spatula => spatula(),
            ObjectKind::Bowl => bowl(),
        }
    }

    /// Generates the object's mesh (deterministic): watertight, outward oriented, resting on
    /// `z = 0` (its lowest vertices are exactly at `z = 0`).
    ///
    /// ```
    /// use nbv_scenes::meshgen::ObjectKind;
    /// let m = ObjectKind::Box.mesh();
    /// assert!(m.is_watertight());
    /// let (lo, hi) = m.bounds().unwrap();
    /// assert_eq!(lo.z, 0.0);
    /// assert!((hi.x - lo.x - 0.15).abs() < 0.002);
    /// ```
    pub fn mesh(self) -> TriMesh {
        let (f, lo, hi) = self.solid();
        let grid = Grid::covering(lo, hi, self.cell());
        let raw = polygonize(&grid, |p| above_floor(f(p), p));
        let mut mesh = decimate(&raw, TARGET_TRIANGLES, MAX_COLLAPSE_ERROR);
        if let Some((lo, hi)) = mesh.bounds() {
            // Lathe objects keep their axis at the origin; the others centre their footprint.
            let (cx, cy) = match self {
                ObjectKind::Mallet
                | ObjectKind::Horse
                | ObjectKind::Figurine
                | ObjectKind::Spatula => (0.5 * (lo.x + hi.x), 0.5 * (lo.y + hi.y)),
                _ => (0.0, 0.0),
            };
            let shift = Vector3::new(-cx, -cy, -lo.z);
            mesh.vertices.iter_mut().for_each(|p| *p += shift);
        }
        mesh
    }
}

/// Generates every library mesh and writes it to `dir/<name>.stl` (binary, atomic).
/// Returns the written paths.
pub fn write_library(dir: &std::path::Path) -> Result<Vec<std::path::PathBuf>, MeshIoError> {
    ObjectKind::ALL
        .iter()
        .map(|kind| {
            let path = dir.join(format!("{}.stl", kind.name()));
            write_stl_file(&kind.mesh(), &path).map(|()| path)
        })
        .collect()
}

/// A signed-distance function and the corners of a box containing the solid.
type Solid = (Box<dyn Fn(&Point3<f64>) -> f64>, Point3<f64>, Point3<f64>);

/// Points of a quarter-ish arc from `a` to `b` in the `(ρ, z)` plane, bulging by `sag`.
fn arc(a: [f64; 2], b: [f64; 2], sag: f64, n: usize) -> Vec<[f64; 2]> {
    let (dx, dz) = (b[0] - a[0], b[1] - a[1]);
    let len = (dx * dx + dz * dz).sqrt().max(1e-12);
    let normal = [dz / len, -dx / len];
    (1..=n)
        .map(|i| {
            let t = i as f64 / n as f64;
            let bump = sag * (std::f64::consts::PI * t).sin();
            [
                a[0] + dx * t + normal[0] * bump,
                a[1] + dz * t + normal[1] * bump,
            ]
        })
        .collect()
}

fn jug() -> Solid {
    // Body: slightly bulged, narrowing to a neck, flared lip; height 0.20 m.
    let mut profile = vec![[0.0, 0.0], [0.056, 0.0]];
    profile.extend(arc([0.056, 0.0], [0.060, 0.006], 0.002, 3));
    profile.extend(arc([0.060, 0.006], [0.052, 0.165], 0.016, 24));
    profile.extend(arc([0.052, 0.165], [0.058, 0.196], -0.004, 6));
    profile.extend([[0.058, 0.200], [0.052, 0.200], [0.050, 0.190], [0.0, 0.190]]);
    let body = Lathe::new(&profile);
    // Handle: a C-shaped tube on the +x side.
    let handle: Vec<Point3<f64>> = (0..=16)
        .map(|i| {
            let t = std::f64::consts::PI * (i as f64 / 16.0 - 0.5);
            Point3::new(0.05 + 0.052 * t.cos(), 0.0, 0.115 + 0.058 * t.sin())
        })
        .collect();
    let f = move |p: &Point3<f64>| {
        let b = body.distance(p);
        let spout = ellipsoid(
            p,
            &Point3::new(-0.054, 0.0, 0.193),
            &Vector3::new(0.018, 0.016, 0.008),
        );
        let h = tube(p, &handle, 0.0085);
        smooth_union(smooth_union(b, spout, 0.008), h, 0.010)
    };
    (
        Box::new(f),
        Point3::new(-0.08, -0.07, 0.0),
        Point3::new(0.12, 0.07, 0.21),
    )
}

fn bottle_a() -> Solid {
    // 0.5 l water bottle: Ø 0.065, ribbed body, round shoulder, neck ring, cap; 0.21 m.
    let r = 0.0325;
    let mut profile = vec![[0.0, 0.0], [0.027, 0.0]];
    profile.extend(arc([0.027, 0.0], [r, 0.006], 0.002, 4));
    for z in [0.045, 0.075, 0.105] {
        profile.push([r, z]);
        profile.extend(arc([r, z], [r, z + 0.008], -0.002, 6));
    }
    profile.push([r, 0.125]);
    profile.extend(arc([r, 0.125], [0.0135, 0.172], 0.009, 18));
    profile.extend([
        [0.0135, 0.180],
        [0.0180, 0.181],
        [0.0180, 0.185],
        [0.0135, 0.186],
        [0.0135, 0.188],
        [0.0155, 0.188],
        [0.0155, 0.207],
        [0.0140, 0.210],
        [0.0, 0.210],
    ]);
    let body = Lathe::new(&profile);
    let f = move |p: &Point3<f64>| body.distance(p);
    (
        Box::new(f),
        Point3::new(-0.035, -0.035, 0.0),
        Point3::new(0.035, 0.035, 0.215),
    )
}

fn bottle_b() -> Solid {
    // 1 l bottle: Ø 0.08, waisted grip, conical shoulder, wide cap; 0.25 m.
    let r = 0.040;
    let mut profile = vec![[0.0, 0.0], [0.034, 0.0]];
    profile.extend(arc([0.034, 0.0], [r, 0.007], 0.002, 4));
    profile.push([r, 0.060]);
    profile.extend(arc([r, 0.060], [r, 0.150], -0.0065, 18));
    profile.push([r, 0.170]);
    profile.extend(arc([r, 0.170], [0.0165, 0.218], 0.004, 14));
    profile.extend([
        [0.0165, 0.224],
        [0.0200, 0.225],
        [0.0200, 0.247],
        [0.0185, 0.250],
        [0.0, 0.250],
    ]);
    let body = Lathe::new(&profile);
    let f = move |p: &Point3<f64>| body.distance(p);
    (
        Box::new(f),
        Point3::new(-0.042, -0.042, 0.0),
        Point3::new(0.042, 0.042, 0.255),
    )
}

fn mallet() -> Solid {
    // Rubber head Ø 0.055 × 0.10 along y at x = 0; handle towards −x, tilted so that its
    // end rests on the table; overall length ~0.28 m.
    let rh = 0.0275;
    let head_a = Point3::new(0.0, -0.05, rh);
    let head_b = Point3::new(0.0, 0.05, rh);
    let grip_end = Point3::new(-0.238, 0.0, 0.0135);
    let neck = Point3::new(-0.02, 0.0, rh);
    let f = move |p: &Point3<f64>| {
        let head = round_cylinder(p, &head_a, &head_b, rh, 0.005);
        // Taper: radius 0.0095 at the head, 0.0135 at the grip end.
        let ab = grip_end - neck;
        let t = ((p - neck).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0);
        let handle = capsule(p, &neck, &grip_end, 0.0) - (0.0095 + 0.004 * t);
        let collar = round_cylinder(
            p,
            &Point3::new(-0.034, 0.0, rh),
            &Point3::new(-0.022, 0.0, rh),
            0.013,
            0.003,
        );
        smooth_union(smooth_union(head, handle, 0.006), collar, 0.004)
    };
    (
        Box::new(f),
        Point3::new(-0.26, -0.06, 0.0),
        Point3::new(0.035, 0.06, 0.06),
    )
}

fn horse() -> Solid {
    // Toy horse: body ellipsoid, four legs, neck, head, ears, tail; ~0.18 m long.
    let legs = [
        (0.038, 0.016),
        (0.038, -0.016),
        (-0.040, 0.016),
        (-0.040, -0.016),
    ];
    let f = move |p: &Point3<f64>| {
        let mut d = ellipsoid(
            p,
            &Point3::new(0.0, 0.0, 0.088),
            &Vector3::new(0.062, 0.024, 0.027),
        );
        for (x, y) in legs {
            let leg = capsule(
                p,
                &Point3::new(x, y, 0.080),
                &Point3::new(x * 1.08, y * 1.05, 0.004),
                0.0075,
            );
            d = smooth_union(d, leg, 0.008);
        }
        let neck = capsule(
            p,
            &Point3::new(0.042, 0.0, 0.098),
            &Point3::new(0.066, 0.0, 0.140),
            0.0135,
        );
        let head = capsule(
            p,
            &Point3::new(0.068, 0.0, 0.146),
            &Point3::new(0.100, 0.0, 0.126),
            0.0105,
        );
        let ear_l = capsule(
            p,
            &Point3::new(0.066, 0.006, 0.152),
            &Point3::new(0.062, 0.008, 0.168),
            0.0035,
        );
        let ear_r = capsule(
            p,
            &Point3::new(0.066, -0.006, 0.152),
            &Point3::new(0.062, -0.008, 0.168),
            0.0035,
        );
        let tail = capsule(
            p,
            &Point3::new(-0.058, 0.0, 0.098),
            &Point3::new(-0.078, 0.0, 0.055),
            0.0055,
        );
        d = smooth_union(d, neck, 0.012);
        d = smooth_union(d, head, 0.010);
        d = smooth_union(d, ear_l.min(ear_r), 0.004);
        smooth_union(d, tail, 0.008)
    };
    (
        Box::new(f),
        Point3::new(-0.095, -0.04, 0.0),
        Point3::new(0.12, 0.04, 0.18),
    )
}

fn cardboard_box() -> Solid {
    let half = Vector3::new(0.075, 0.05, 0.04);
    let f = move |p: &Point3<f64>| round_box(p, &Point3::new(0.0, 0.0, 0.04), &half, 0.003);
    (
        Box::new(f),
        Point3::new(-0.08, -0.055, 0.0),
        Point3::new(0.08, 0.055, 0.085),
    )
}

fn figurine() -> Solid {
    // Standing cat facing +x: body, four thin legs (Ø 7 mm), neck, head, two ears (Ø 6 mm)
    // and a thin tail (Ø 5.6 mm) curling up behind; ~0.15 m long, ~0.145 m tall.
    let legs = [
        (0.030, 0.010),
        (0.030, -0.010),
        (-0.030, 0.010),
        (-0.030, -0.010),
    ];
    let tail = [
        Point3::new(-0.038, 0.0, 0.080),
        Point3::new(-0.056, 0.0, 0.088),
        Point3::new(-0.068, 0.0, 0.104),
        Point3::new(-0.073, 0.0, 0.124),
        Point3::new(-0.069, 0.0, 0.142),
    ];
    let f = move |p: &Point3<f64>| {
        let mut d = ellipsoid(
            p,
            &Point3::new(0.0, 0.0, 0.075),
            &Vector3::new(0.045, 0.017, 0.019),
        );
        for (x, y) in legs {
            let leg = capsule(
                p,
                &Point3::new(x, y, 0.070),
                &Point3::new(x * 1.06, y * 1.1, 0.0035),
                0.0035,
            );
            d = smooth_union(d, leg, 0.005);
        }
        let neck = capsule(
            p,
            &Point3::new(0.034, 0.0, 0.082),
            &Point3::new(0.050, 0.0, 0.100),
            0.0095,
        );
        let head = ellipsoid(
            p,
            &Point3::new(0.056, 0.0, 0.106),
            &Vector3::new(0.016, 0.015, 0.014),
        );
        let ears = [1.0, -1.0]
            .map(|s| {
                capsule(
                    p,
                    &Point3::new(0.056, s * 0.008, 0.116),
                    &Point3::new(0.054, s * 0.010, 0.131),
                    0.003,
                )
            })
            .into_iter()
            .fold(f64::INFINITY, f64::min);
        d = smooth_union(d, neck, 0.008);
        d = smooth_union(d, head, 0.006);
        d = smooth_union(d, ears, 0.003);
        smooth_union(d, tube(p, &tail, 0.0028), 0.004)
    };
    (
        Box::new(f),
        Point3::new(-0.085, -0.03, 0.0),
        Point3::new(0.08, 0.03, 0.15),
    )
}

/// A hollow vessel open at the top: the lathe solid of `outer` (its profile carried on
/// above `height`), less the same solid shrunk by `wall` (so the bottom is `wall` thick
/// too), cut at `height`; `extra` (a handle) is joined to its outside with blend radius
/// `k` and kept out of the cavity.
fn vessel(
    outer: &[[f64; 2]],
    height: f64,
    wall: f64,
    extra: Option<(Vec<Point3<f64>>, f64, f64)>,
) -> impl Fn(&Point3<f64>) -> f64 + 'static {
    let body = Lathe::new(outer);
    move |p: &Point3<f64>| {
        let o = body.distance(p);
        let cavity = o + wall;
        let mut d = o.max(p.z - height);
        if let Some((path, r, k)) = &extra {
            d = smooth_union(d, tube(p, path, *r), *k);
        }
        d.max(-cavity)
    }
}

fn pitcher() -> Solid {
    // Ø 0.11 body, slightly bulged, flared towards the rim at 0.18 m; wall and bottom 4 mm;
    // a C-shaped handle (tube Ø 13 mm) on the +x side.
    let mut profile = vec![[0.0, 0.0], [0.046, 0.0]];
    profile.extend(arc([0.046, 0.0], [0.050, 0.005], 0.002, 3));
    profile.extend(arc([0.050, 0.005], [0.050, 0.150], 0.006, 24));
    profile.extend(arc([0.050, 0.150], [0.055, 0.180], -0.002, 6));
    profile.extend([[0.055, 0.230], [0.0, 0.230]]);
    let handle: Vec<Point3<f64>> = (0..=16)
        .map(|i| {
            let t = std::f64::consts::PI * (i as f64 / 16.0 - 0.5);
            Point3::new(0.048 + 0.034 * t.cos(), 0.0, 0.100 + 0.050 * t.sin())
        })
        .collect();
    let f = vessel(&profile, 0.180, 0.004, Some((handle, 0.0065, 0.006)));
    (
        Box::new(f),
        Point3::new(-0.06, -0.06, 0.0),
        Point3::new(0.095, 0.06, 0.185),
    )
}

fn tall_bottle() -> Solid {
    // Wine bottle: Ø 0.05 body to 0.19 m, round shoulder, long neck Ø 0.019, lip ring;
    // 0.30 m.
    let r = 0.025;
    let mut profile = vec![[0.0, 0.0], [0.021, 0.0]];
    profile.extend(arc([0.021, 0.0], [r, 0.005], 0.0015, 4));
    profile.push([r, 0.190]);
    profile.extend(arc([r, 0.190], [0.0100, 0.235], 0.007, 16));
    profile.extend([
        [0.0095, 0.284],
        [0.0115, 0.286],
        [0.0115, 0.297],
        [0.0100, 0.300],
        [0.0, 0.300],
    ]);
    let body = Lathe::new(&profile);
    let f = move |p: &Point3<f64>| body.distance(p);
    (
        Box::new(f),
        Point3::new(-0.027, -0.027, 0.0),
        Point3::new(0.027, 0.027, 0.305),
    )
}

fn spatula() -> Solid {
    // Kitchen turner lying flat along x: handle 0.12 × 0.026 × 0.018, a neck sloping down
    // to the blade, blade 0.10 × 0.075 × 0.005 on the table; 0.25 m long.
    let f = move |p: &Point3<f64>| {
        let handle = round_box(
            p,
            &Point3::new(0.065, 0.0, 0.009),
            &Vector3::new(0.060, 0.013, 0.009),
            0.006,
        );
        let neck = capsule(
            p,
            &Point3::new(0.012, 0.0, 0.008),
            &Point3::new(-0.040, 0.0, 0.0035),
            0.0035,
        );
        let blade = round_box(
            p,
            &Point3::new(-0.075, 0.0, 0.0025),
            &Vector3::new(0.050, 0.0375, 0.0025),
            0.0015,
        );
        smooth_union(smooth_union(handle, neck, 0.004), blade, 0.004)
    };
    (
        Box::new(f),
        Point3::new(-0.13, -0.042, 0.0),
        Point3::new(0.13, 0.042, 0.022),
    )
}

fn bowl() -> Solid {
    // Ø 0.18 at the rim, 0.06 m tall, a rounded side down to a Ø 0.09 base; wall and bottom
    // 4 mm.
    let mut profile = vec![[0.0, 0.0], [0.045, 0.0]];
    profile.extend(arc([0.045, 0.0], [0.090, 0.060], 0.012, 24));
    profile.extend([[0.090, 0.100], [0.0, 0.100]]);
    let f = vessel(&profile, 0.060, 0.004, None);
    (
        Box::new(f),
        Point3::new(-0.095, -0.095, 0.0),
        Point3::new(0.095, 0.095, 0.065),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_object_is_watertight_real_sized_and_modest() {
        for kind in ObjectKind::ALL {
            let m = kind.mesh();
            let (lo, hi) = m.bounds().unwrap();
            let size = hi - lo;
            println!(
                "{:9} {:6} triangles, size {:.3} x {:.3} x {:.3}, volume {:.3e} m3",
                kind.name(),
                m.triangles.len(),
                size.x,
                size.y,
                size.z,
                m.volume()
            );
            assert!(m.is_watertight(), "{} is not watertight", kind.name());
            assert!(m.volume() > 0.0, "{} has no positive volume", kind.name());
            assert!(m.triangles.len() <= 21_000, "{} too fine", kind.name());
            assert_eq!(lo.z, 0.0);
            let (expect, tol): ([f64; 3], f64) = match kind {
                ObjectKind::Jug => ([0.18, 0.145, 0.20], 0.01),
                ObjectKind::BottleA => ([0.065, 0.065, 0.21], 0.005),
                ObjectKind::BottleB => ([0.08, 0.08, 0.25], 0.005),
                ObjectKind::Mallet => ([0.28, 0.10, 0.055], 0.01),
                ObjectKind::Horse => ([0.19, 0.05, 0.17], 0.01),
                ObjectKind::Box => ([0.15, 0.10, 0.08], 0.003),
                ObjectKind::Figurine => ([0.15, 0.034, 0.145], 0.005),
                ObjectKind::Pitcher => ([0.145, 0.11, 0.18], 0.005),
                ObjectKind::TallBottle => ([0.05, 0.05, 0.30], 0.003),
                ObjectKind::Spatula => ([0.25, 0.075, 0.018], 0.003),
                ObjectKind::Bowl => ([0.18, 0.18, 0.06], 0.003),
            };
            for a in 0..3 {
                assert!(
                    (size[a] - expect[a]).abs() < tol,
                    "{} axis {a}: {}",
                    kind.name(),
                    size[a]
                );
            }
        }
    }

    /// The highest point where the vertical line through `(x, y)` meets the mesh.
    fn top_hit(m: &TriMesh, x: f64, y: f64) -> Option<f64> {
        m.triangles
            .iter()
            .filter_map(|t| {
                let [a, b, c] = t.map(|i| m.vertices[i as usize]);
                let cross = |p: &Point3<f64>, q: &Point3<f64>| {
                    (q.x - p.x) * (y - p.y) - (q.y - p.y) * (x - p.x)
                };
                let (u, v, w) = (cross(&b, &c), cross(&c, &a), cross(&a, &b));
                let sum = u + v + w;
                let inside =
                    (u >= 0.0 && v >= 0.0 && w >= 0.0) || (u <= 0.0 && v <= 0.0 && w <= 0.0);
                (inside && sum.abs() > 1e-18).then(|| (u * a.z + v * b.z + w * c.z) / sum)
            })
            .reduce(f64::max)
    }

    #[test]
    fn the_vessels_are_hollow_with_an_open_top() {
        for (kind, height) in [(ObjectKind::Pitcher, 0.18), (ObjectKind::Bowl, 0.06)] {
            let (f, _, _) = kind.solid();
            // The inside centre is outside the solid, the wall and the bottom are inside.
            assert!(
                f(&Point3::new(0.0, 0.0, 0.5 * height)) > 0.0,
                "{}",
                kind.name()
            );
            assert!(f(&Point3::new(0.0, 0.0, 0.002)) < 0.0, "{}", kind.name());
            // A vertical ray from above the open top first meets the 4 mm bottom.
            let m = kind.mesh();
            let z = top_hit(&m, 0.001, 0.0013).unwrap();
            assert!(
                (z - 0.004).abs() < 0.0015,
                "{}: ray meets z = {z}",
                kind.name()
            );
            // The rim is the top: no lid.
            let (_, hi) = m.bounds().unwrap();
            assert!((hi.z - height).abs() < 0.002);
        }
    }

    #[test]
    fn the_figurine_stands_on_four_thin_legs() {
        let m = ObjectKind::Figurine.mesh();
        // Between 1 and 4 cm up, only the legs: four clumps, each under 9 mm across.
        let mut quadrants = [[
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ]; 4];
        let mut n = 0;
        for p in m.vertices.iter().filter(|p| (0.01..0.04).contains(&p.z)) {
            let q = usize::from(p.x > 0.0) * 2 + usize::from(p.y > 0.0);
            let b = &mut quadrants[q];
            b[0] = b[0].min(p.x);
            b[1] = b[1].max(p.x);
            b[2] = b[2].min(p.y);
            b[3] = b[3].max(p.y);
            n += 1;
        }
        assert!(n > 0);
        for b in quadrants {
            assert!(
                b[1] - b[0] < 0.009 && b[3] - b[2] < 0.009,
                "leg section {b:?}"
            );
        }
    }
}
