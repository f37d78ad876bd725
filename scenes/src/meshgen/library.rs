//! The object library: the six objects of the paper's Figure 5 as watertight meshes at
//! real sizes (metres), each a smooth signed-distance solid meshed by marching tetrahedra.
//!
//! | object | shape | size (x × y × z, approx.) |
//! |---|---|---|
//! | `jug` | lathe body (bulged, flared lip) + spout + tube handle | 0.18 × 0.14 × 0.20 |
//! | `bottle-a` | 0.5 l water bottle: grooved body, shoulder, neck ring, cap | Ø 0.067 × 0.21 |
//! | `bottle-b` | 1 l bottle: waisted grip, conical shoulder, cap | Ø 0.08 × 0.25 |
//! | `mallet` | rubber head (cylinder) + tapered handle, lying on the table | 0.28 × 0.10 × 0.055 |
//! | `horse` | toy horse: body, four legs, neck, head, ears, tail | 0.19 × 0.05 × 0.17 |
//! | `box` | cardboard box with rounded edges | 0.15 × 0.10 × 0.08 |
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
    /// A jug (pitcher) with a handle, ~0.20 m tall.
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
}

impl ObjectKind {
    /// Every object, in a fixed order.
    pub const ALL: [ObjectKind; 6] = [
        ObjectKind::Jug,
        ObjectKind::BottleA,
        ObjectKind::BottleB,
        ObjectKind::Mallet,
        ObjectKind::Horse,
        ObjectKind::Box,
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
                ObjectKind::Mallet | ObjectKind::Horse => {
                    (0.5 * (lo.x + hi.x), 0.5 * (lo.y + hi.y))
                }
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
}
