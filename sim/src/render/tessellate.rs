//! Triangle meshes of the primitive shapes that URDF links and scene obstacles use: box,
//! cylinder (along z) and sphere, all centred at the origin, closed and outward-oriented.

use nalgebra::Point3;
use nbv_core::mesh::TriMesh;
use std::f64::consts::TAU;

/// A box with the given full `size` along x, y and z (URDF `<box size>`).
///
/// ```
/// let m = nbv_sim::render::tessellate::cuboid([0.2, 0.4, 0.6]);
/// assert!((m.volume() - 0.048).abs() < 1e-12);
/// ```
pub fn cuboid(size: [f64; 3]) -> TriMesh {
    TriMesh::cuboid([size[0] / 2.0, size[1] / 2.0, size[2] / 2.0])
}

/// A cylinder of `radius` and `length` along z, with `segments` sides (at least 3),
/// as URDF's `<cylinder>`.
///
/// ```
/// let m = nbv_sim::render::tessellate::cylinder(0.1, 0.5, 48);
/// assert!(m.is_watertight());
/// let exact = std::f64::consts::PI * 0.01 * 0.5;
/// assert!((m.volume() - exact).abs() / exact < 0.01);
/// ```
pub fn cylinder(radius: f64, length: f64, segments: usize) -> TriMesh {
    let n = segments.max(3);
    let h = length / 2.0;
    let mut vertices = Vec::with_capacity(2 * n + 2);
    for z in [-h, h] {
        for i in 0..n {
            let a = TAU * i as f64 / n as f64;
            vertices.push(Point3::new(radius * a.cos(), radius * a.sin(), z));
        }
    }
    let bottom = vertices.len() as u32;
    vertices.push(Point3::new(0.0, 0.0, -h));
    let top = bottom + 1;
    vertices.push(Point3::new(0.0, 0.0, h));
    let n32 = n as u32;
    let mut triangles = Vec::with_capacity(4 * n);
    for i in 0..n32 {
        let j = (i + 1) % n32;
        let (b0, b1, t0, t1) = (i, j, i + n32, j + n32);
        triangles.push([b0, b1, t1]);
        triangles.push([b0, t1, t0]);
        triangles.push([bottom, b1, b0]);
        triangles.push([top, t0, t1]);
    }
    TriMesh {
        vertices,
        triangles,
    }
}

/// A UV sphere of `radius` with `rings` latitude bands (at least 2) and `segments`
/// longitude sectors (at least 3), as URDF's `<sphere>`.
///
/// ```
/// let m = nbv_sim::render::tessellate::sphere(0.2, 24, 48);
/// assert!(m.is_watertight());
/// let exact = 4.0 / 3.0 * std::f64::consts::PI * 0.008;
/// assert!((m.volume() - exact).abs() / exact < 0.02);
/// ```
pub fn sphere(radius: f64, rings: usize, segments: usize) -> TriMesh {
    let (rings, n) = (rings.max(2), segments.max(3));
    let mut vertices = vec![Point3::new(0.0, 0.0, -radius)];
    for r in 1..rings {
        let polar = std::f64::consts::PI * r as f64 / rings as f64;
        let (z, rho) = (-radius * polar.cos(), radius * polar.sin());
        for i in 0..n {
            let a = TAU * i as f64 / n as f64;
            vertices.push(Point3::new(rho * a.cos(), rho * a.sin(), z));
        }
    }
    let north = vertices.len() as u32;
    vertices.push(Point3::new(0.0, 0.0, radius));
    let n32 = n as u32;
    let ring = |r: u32, i: u32| 1 + r * n32 + i % n32;
    let mut triangles = Vec::with_capacity(2 * n * rings);
    for i in 0..n32 {
        triangles.push([0, ring(0, i + 1), ring(0, i)]);
        let last = rings as u32 - 2;
        triangles.push([north, ring(last, i), ring(last, i + 1)]);
    }
    for r in 0..rings as u32 - 2 {
        for i in 0..n32 {
            let (a, b) = (ring(r, i), ring(r, i + 1));
            let (c, d) = (ring(r + 1, i), ring(r + 1, i + 1));
            triangles.push([a, b, d]);
            triangles.push([a, d, c]);
        }
    }
    TriMesh {
        vertices,
        triangles,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cylinder_has_outward_normals() {
        let m = cylinder(0.3, 1.0, 16);
        assert!(m.volume() > 0.0);
        let (lo, hi) = m.bounds().unwrap();
        assert!((lo.z + 0.5).abs() < 1e-12 && (hi.z - 0.5).abs() < 1e-12);
        assert!((hi.x - 0.3).abs() < 1e-12);
    }

    #[test]
    fn smallest_shapes_are_closed() {
        assert!(cylinder(1.0, 1.0, 0).is_watertight());
        assert!(sphere(1.0, 0, 0).is_watertight());
        assert!(sphere(1.0, 2, 3).volume() > 0.0);
    }

    proptest::proptest! {
        #[test]
        fn sphere_volume_converges(rings in 8usize..40, segments in 8usize..64, r in 0.01f64..2.0) {
            let m = sphere(r, rings, segments);
            proptest::prop_assert!(m.is_watertight());
            let exact = 4.0 / 3.0 * std::f64::consts::PI * r.powi(3);
            // An inscribed polyhedron: never larger, and close for fine tessellations.
            proptest::prop_assert!(m.volume() <= exact * (1.0 + 1e-9));
            proptest::prop_assert!(m.volume() >= exact * 0.80);
        }
    }
}
