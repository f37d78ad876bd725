//! Marching tetrahedra: the zero level set of a signed-distance function as a closed
//! triangle mesh.
//!
//! The box is sampled on a regular grid; every cube is split into six tetrahedra around its
//! main diagonal (the Kuhn split, identical in every cube, so neighbouring cubes agree on
//! their shared faces). Each grid edge that changes sign gets exactly one vertex, shared
//! by every tetrahedron around that edge, and the triangle orientation follows from the
//! exact (integer) orientation of the tetrahedron, so the result is watertight and
//! consistently oriented by construction — provided the function is positive on the
//! box's boundary. Vertices are kept at least 1% of an edge away from grid points, so
//! distinct vertices stay distinct after rounding to `f32` (STL).

use nalgebra::{Point3, Vector3};
use nbv_core::mesh::TriMesh;
use std::collections::HashMap;

/// A regular sampling grid: `origin + (i, j, k) · cell` for `i < dims[0]`, etc.
#[derive(Debug, Clone, PartialEq)]
pub struct Grid {
    /// Position of grid point `(0, 0, 0)`.
    pub origin: Point3<f64>,
    /// Edge length of a cube.
    pub cell: f64,
    /// Number of grid points along x, y and z.
    pub dims: [usize; 3],
}

impl Grid {
    /// A grid covering `[lo, hi]` with a margin of two cells, whose z planes fall half a cell
    /// off `z = 0` (so a flat base at `z = 0` is recovered exactly by interpolation).
    pub fn covering(lo: Point3<f64>, hi: Point3<f64>, cell: f64) -> Self {
        let margin = 2.0 * cell;
        let lo = lo - Vector3::repeat(margin);
        let hi = hi + Vector3::repeat(margin);
        let z0 = ((lo.z / cell - 0.5).floor() + 0.5) * cell;
        let origin = Point3::new(lo.x, lo.y, z0);
        let count = |a: f64, b: f64| ((b - a) / cell).ceil().max(1.0) as usize + 1;
        Self {
            origin,
            cell,
            dims: [
                count(origin.x, hi.x),
                count(origin.y, hi.y),
                count(origin.z, hi.z),
            ],
        }
    }

    fn point(&self, i: usize, j: usize, k: usize) -> Point3<f64> {
        self.origin + Vector3::new(i as f64, j as f64, k as f64) * self.cell
    }

    fn index(&self, i: usize, j: usize, k: usize) -> usize {
        (k * self.dims[1] + j) * self.dims[0] + i
    }
}

/// Corner offsets of a cube, indexed by `x | y << 1 | z << 2`.
const CORNERS: [[usize; 3]; 8] = [
    [0, 0, 0],
    [1, 0, 0],
    [0, 1, 0],
    [1, 1, 0],
    [0, 0, 1],
    [1, 0, 1],
    [0, 1, 1],
    [1, 1, 1],
];

/// The six tetrahedra of the Kuhn split: the monotone paths from corner 0 to corner 7.
const TETS: [[usize; 4]; 6] = [
    [0, 1, 3, 7],
    [0, 1, 5, 7],
    [0, 2, 3, 7],
    [0, 2, 6, 7],
    [0, 4, 5, 7],
    [0, 4, 6, 7],
];

/// Meshes the surface `f = 0` inside `grid` (`f < 0` is inside). The function must be
/// positive on the grid's boundary for the result to be closed.
///
/// ```
/// use nbv_scenes::meshgen::marching_tetrahedra::{Grid, polygonize};
/// use nalgebra::Point3;
/// let grid = Grid::covering(Point3::new(-1.0, -1.0, -1.0), Point3::new(1.0, 1.0, 1.0), 0.1);
/// let sphere = polygonize(&grid, |p| p.coords.norm() - 1.0);
/// assert!(sphere.is_watertight());
/// let v = sphere.volume();
/// assert!((v - 4.0 / 3.0 * std::f64::consts::PI).abs() < 0.05);
/// ```
pub fn polygonize(grid: &Grid, f: impl Fn(&Point3<f64>) -> f64) -> TriMesh {
    let [nx, ny, nz] = grid.dims;
    let mut values = vec![0.0; nx * ny * nz];
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                values[grid.index(i, j, k)] = f(&grid.point(i, j, k));
            }
        }
    }
    let mut mesh = TriMesh::default();
    let mut edge_vertex: HashMap<(usize, usize), u32> = HashMap::new();
    let mut vertex_on = |a: usize, pa: [usize; 3], b: usize, pb: [usize; 3], mesh: &mut TriMesh| {
        // Canonical direction (lower grid index first) so both sides compute the same point.
        let ((a, pa), (b, pb)) = if a < b {
            ((a, pa), (b, pb))
        } else {
            ((b, pb), (a, pa))
        };
        *edge_vertex.entry((a, b)).or_insert_with(|| {
            let (fa, fb) = (values[a], values[b]);
            let t = fa / (fa - fb);
            let t = if t.is_finite() {
                t.clamp(0.01, 0.99)
            } else {
                0.5
            };
            let p = grid.point(pa[0], pa[1], pa[2]);
            let q = grid.point(pb[0], pb[1], pb[2]);
            mesh.vertices.push(p + (q - p) * t);
            (mesh.vertices.len() - 1) as u32
        })
    };
    for k in 0..nz.saturating_sub(1) {
        for j in 0..ny.saturating_sub(1) {
            for i in 0..nx.saturating_sub(1) {
                let pos = CORNERS.map(|c| [i + c[0], j + c[1], k + c[2]]);
                let idx = pos.map(|p| grid.index(p[0], p[1], p[2]));
                let inside = idx.map(|g| values[g] < 0.0);
                if inside.iter().all(|&b| b) || inside.iter().all(|&b| !b) {
                    continue;
                }
                for tet in TETS {
                    let ins: Vec<usize> = tet.iter().copied().filter(|&c| inside[c]).collect();
                    let outs: Vec<usize> = tet.iter().copied().filter(|&c| !inside[c]).collect();
                    let mut v = |a: usize, b: usize, mesh: &mut TriMesh| {
                        vertex_on(idx[a], pos[a], idx[b], pos[b], mesh)
                    };
                    match (ins.as_slice(), outs.as_slice()) {
                        (&[i0], &[o0, o1, o2]) => {
                            let tri = [
                                v(i0, o0, &mut mesh),
                                v(i0, o1, &mut mesh),
                                v(i0, o2, &mut mesh),
                            ];
                            // Normal away from the inside corner when det(o0-i, o1-i, o2-i) > 0.
                            push(&mut mesh, tri, orient(i0, o0, o1, o2) > 0);
                        }
                        (&[i0, i1, i2], &[o0]) => {
                            let tri = [
                                v(o0, i0, &mut mesh),
                                v(o0, i1, &mut mesh),
                                v(o0, i2, &mut mesh),
                            ];
                            // Normal towards the outside corner.
                            push(&mut mesh, tri, orient(o0, i0, i1, i2) < 0);
                        }
                        (&[a, b], &[c, d]) => {
                            let ac = v(a, c, &mut mesh);
                            let ad = v(a, d, &mut mesh);
                            let bd = v(b, d, &mut mesh);
                            let bc = v(b, c, &mut mesh);
                            // (ac, ad, bd) faces out of {a, b} when det(b-a, c-a, d-a) > 0.
                            let keep = orient(a, b, c, d) > 0;
                            push(&mut mesh, [ac, ad, bd], keep);
                            push(&mut mesh, [ac, bd, bc], keep);
                        }
                        _ => {}
                    }
                }
            }
        }
    }
    mesh
}

/// Sign of `det(b - a, c - a, d - a)` for cube corners (exact, integer).
fn orient(a: usize, b: usize, c: usize, d: usize) -> i64 {
    let p = |x: usize| CORNERS[x].map(|v| v as i64);
    let (pa, pb, pc, pd) = (p(a), p(b), p(c), p(d));
    let u = [pb[0] - pa[0], pb[1] - pa[1], pb[2] - pa[2]];
    let v = [pc[0] - pa[0], pc[1] - pa[1], pc[2] - pa[2]];
    let w = [pd[0] - pa[0], pd[1] - pa[1], pd[2] - pa[2]];
    u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0])
        + u[2] * (v[0] * w[1] - v[1] * w[0])
}

fn push(mesh: &mut TriMesh, tri: [u32; 3], keep: bool) {
    mesh.triangles
        .push(if keep { tri } else { [tri[0], tri[2], tri[1]] });
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn cube_volume_is_exact_for_a_linear_field() {
        // A box 0.4 × 0.3 × 0.2 resting on z = 0: the field is piecewise linear in each
        // axis away from edges, so the faces are exact planes.
        let grid = Grid::covering(
            Point3::new(-0.2, -0.15, 0.0),
            Point3::new(0.2, 0.15, 0.2),
            0.013,
        );
        let m = polygonize(&grid, |p| {
            (p.x.abs() - 0.2)
                .max(p.y.abs() - 0.15)
                .max((p.z - 0.1).abs() - 0.1)
        });
        assert!(m.is_watertight());
        let (lo, hi) = m.bounds().unwrap();
        assert!(lo.z.abs() < 1e-12, "flat base at z = 0, got {}", lo.z);
        assert!((hi.z - 0.2).abs() < 0.013);
        assert!((m.volume() - 0.024).abs() < 0.024 * 0.05);
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(24))]
        #[test]
        fn random_blobs_are_watertight(
            cx in -0.3f64..0.3, cy in -0.3f64..0.3, r1 in 0.05f64..0.3, r2 in 0.05f64..0.3,
            cell in 0.03f64..0.08,
        ) {
            let grid = Grid::covering(Point3::new(-0.7, -0.7, -0.7), Point3::new(0.7, 0.7, 0.7), cell);
            let m = polygonize(&grid, |p| {
                let a = (p - Point3::new(cx, cy, 0.1)).norm() - r1;
                let b = (p - Point3::new(-cx, 0.0, -cy)).norm() - r2;
                a.min(b)
            });
            prop_assert!(m.is_watertight());
            prop_assert!(m.volume() > 0.0);
        }
    }
}
