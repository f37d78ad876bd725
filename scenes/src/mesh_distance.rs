//! Exact distances between placed triangle meshes, and point containment: the geometric
//! tests behind scene validation (objects must not touch or interpenetrate).
//!
//! Two triangles are at distance 0 when an edge of one crosses the other; otherwise their
//! distance is the smallest of the six vertex–triangle and nine edge–edge distances.
//! Bounding-volume hierarchies prune the pairs that cannot beat the best distance so far.
//! Containment uses the generalised winding number (sum of signed solid angles), which is
//! robust for closed meshes.

use nalgebra::{Point3, Vector3};
use nbv_core::mesh::TriMesh;

/// The closest point of triangle `abc` to `p`.
pub fn closest_point_on_triangle(
    p: &Point3<f64>,
    a: &Point3<f64>,
    b: &Point3<f64>,
    c: &Point3<f64>,
) -> Point3<f64> {
    let ab = b - a;
    let ac = c - a;
    let ap = p - a;
    let d1 = ab.dot(&ap);
    let d2 = ac.dot(&ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return *a;
    }
    let bp = p - b;
    let d3 = ab.dot(&bp);
    let d4 = ac.dot(&bp);
    if d3 >= 0.0 && d4 <= d3 {
        return *b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return a + ab * v;
    }
    let cp = p - c;
    let d5 = ab.dot(&cp);
    let d6 = ac.dot(&cp);
    if d6 >= 0.0 && d5 <= d6 {
        return *c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return a + ac * w;
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return b + (c - b) * w;
    }
    let denom = va + vb + vc;
    if denom.abs() < f64::MIN_POSITIVE {
        return *a;
    }
    let v = vb / denom;
    let w = vc / denom;
    a + ab * v + ac * w
}

/// Distance between segments `p1q1` and `p2q2`.
pub fn segment_distance(
    p1: &Point3<f64>,
    q1: &Point3<f64>,
    p2: &Point3<f64>,
    q2: &Point3<f64>,
) -> f64 {
    let d1 = q1 - p1;
    let d2 = q2 - p2;
    let r = p1 - p2;
    let a = d1.norm_squared();
    let e = d2.norm_squared();
    let f = d2.dot(&r);
    let eps = 1e-30;
    let (s, t) = if a <= eps && e <= eps {
        (0.0, 0.0)
    } else if a <= eps {
        (0.0, (f / e).clamp(0.0, 1.0))
    } else {
        let c = d1.dot(&r);
        if e <= eps {
            ((-c / a).clamp(0.0, 1.0), 0.0)
        } else {
            let b = d1.dot(&d2);
            let denom = a * e - b * b;
            let mut s = if denom > eps {
                ((b * f - c * e) / denom).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let mut t = (b * s + f) / e;
            if t < 0.0 {
                t = 0.0;
                s = (-c / a).clamp(0.0, 1.0);
            } else if t > 1.0 {
                t = 1.0;
                s = ((b - c) / a).clamp(0.0, 1.0);
            }
            (s, t)
        }
    };
    ((p1 + d1 * s) - (p2 + d2 * t)).norm()
}

/// Whether segment `pq` crosses triangle `abc` (Möller–Trumbore on the segment).
pub fn segment_hits_triangle(
    p: &Point3<f64>,
    q: &Point3<f64>,
    a: &Point3<f64>,
    b: &Point3<f64>,
    c: &Point3<f64>,
) -> bool {
    let dir = q - p;
    let e1 = b - a;
    let e2 = c - a;
    let h = dir.cross(&e2);
    let det = e1.dot(&h);
    if det.abs() < 1e-30 {
        return false;
    }
    let inv = 1.0 / det;
    let s = p - a;
    let u = inv * s.dot(&h);
    if !(0.0..=1.0).contains(&u) {
        return false;
    }
    let qv = s.cross(&e1);
    let v = inv * dir.dot(&qv);
    if v < 0.0 || u + v > 1.0 {
        return false;
    }
    let t = inv * e2.dot(&qv);
    (0.0..=1.0).contains(&t)
}

/// Distance between two triangles (0 when they intersect or touch).
pub fn triangle_distance(t1: &[Point3<f64>; 3], t2: &[Point3<f64>; 3]) -> f64 {
    for k in 0..3 {
        let (p, q) = (&t1[k], &t1[(k + 1) % 3]);
        if segment_hits_triangle(p, q, &t2[0], &t2[1], &t2[2]) {
            return 0.0;
        }
        let (p, q) = (&t2[k], &t2[(k + 1) % 3]);
        if segment_hits_triangle(p, q, &t1[0], &t1[1], &t1[2]) {
            return 0.0;
        }
    }
    let mut best = f64::INFINITY;
    for k in 0..3 {
        best = best.min((t1[k] - closest_point_on_triangle(&t1[k], &t2[0], &t2[1], &t2[2])).norm());
        best = best.min((t2[k] - closest_point_on_triangle(&t2[k], &t1[0], &t1[1], &t1[2])).norm());
        for m in 0..3 {
            best = best.min(segment_distance(
                &t1[k],
                &t1[(k + 1) % 3],
                &t2[m],
                &t2[(m + 1) % 3],
            ));
        }
    }
    best
}

fn tri_bounds(t: &[Point3<f64>; 3]) -> (Point3<f64>, Point3<f64>) {
    (t[0].inf(&t[1]).inf(&t[2]), t[0].sup(&t[1]).sup(&t[2]))
}

/// Distance between two axis-aligned boxes (0 when they overlap).
fn box_distance(a: &(Point3<f64>, Point3<f64>), b: &(Point3<f64>, Point3<f64>)) -> f64 {
    let gap = |k: usize| (b.0[k] - a.1[k]).max(a.0[k] - b.1[k]).max(0.0);
    Vector3::new(gap(0), gap(1), gap(2)).norm()
}

/// A bounding-volume hierarchy over a mesh's triangles (median splits, small leaves).
struct Bvh {
    /// Node boxes.
    bounds: Vec<(Point3<f64>, Point3<f64>)>,
    /// Children `(left, right)` of inner nodes, or `(start, end)` into `order` for leaves.
    links: Vec<(usize, usize, bool)>,
    /// Triangles (corners) in leaf order.
    tris: Vec<[Point3<f64>; 3]>,
}

const LEAF: usize = 8;

impl Bvh {
    fn new(mesh: &TriMesh) -> Self {
        let n = mesh.vertices.len();
        let mut tris: Vec<[Point3<f64>; 3]> = (0..mesh.triangles.len())
            .filter(|&i| mesh.triangles[i].iter().all(|&v| (v as usize) < n))
            .map(|i| mesh.triangle(i))
            .collect();
        let mut bvh = Bvh {
            bounds: Vec::new(),
            links: Vec::new(),
            tris: Vec::new(),
        };
        if !tris.is_empty() {
            let len = tris.len();
            bvh.build(&mut tris, 0, len);
        }
        bvh.tris = tris;
        bvh
    }

    fn build(&mut self, tris: &mut [[Point3<f64>; 3]], start: usize, end: usize) -> usize {
        let slice = &mut tris[start..end];
        let mut lo = slice[0][0];
        let mut hi = slice[0][0];
        for t in slice.iter() {
            let (a, b) = tri_bounds(t);
            lo = lo.inf(&a);
            hi = hi.sup(&b);
        }
        let id = self.bounds.len();
        self.bounds.push((lo, hi));
        self.links.push((start, end, true));
        if end - start > LEAF {
            let ext = hi - lo;
            let axis = if ext.x >= ext.y && ext.x >= ext.z {
                0
            } else if ext.y >= ext.z {
                1
            } else {
                2
            };
            let key = |t: &[Point3<f64>; 3]| t[0][axis] + t[1][axis] + t[2][axis];
            let mid = (end - start) / 2;
            slice.select_nth_unstable_by(mid, |a, b| key(a).total_cmp(&key(b)));
            let left = self.build(tris, start, start + mid);
            let right = self.build(tris, start + mid, end);
            self.links[id] = (left, right, false);
        }
        id
    }
}

/// The distance between two meshes' surfaces if it is below `limit`, else `None`.
///
/// Branch and bound over two bounding-volume hierarchies: exact, and fast when the meshes
/// are far apart or close only in a small region.
///
/// ```
/// use nbv_core::mesh::TriMesh;
/// use nbv_scenes::mesh_distance::surface_distance_below;
/// use nalgebra::{Isometry3, Vector3};
/// let a = TriMesh::cuboid([0.5; 3]);
/// let b = a.transformed(&Isometry3::translation(1.25, 0.0, 0.0));
/// let d = surface_distance_below(&a, &b, 1.0).unwrap();
/// assert!((d - 0.25).abs() < 1e-12);
/// assert_eq!(surface_distance_below(&a, &b, 0.1), None);
/// ```
pub fn surface_distance_below(a: &TriMesh, b: &TriMesh, limit: f64) -> Option<f64> {
    let (ba, bb) = (Bvh::new(a), Bvh::new(b));
    if ba.tris.is_empty() || bb.tris.is_empty() {
        return None;
    }
    let mut best = limit;
    let mut stack = vec![(0usize, 0usize)];
    while let Some((i, j)) = stack.pop() {
        if box_distance(&ba.bounds[i], &bb.bounds[j]) >= best {
            continue;
        }
        let (li, ri, leaf_i) = ba.links[i];
        let (lj, rj, leaf_j) = bb.links[j];
        match (leaf_i, leaf_j) {
            (true, true) => {
                for ta in &ba.tris[li..ri] {
                    for tb in &bb.tris[lj..rj] {
                        let d = triangle_distance(ta, tb);
                        if d < best {
                            best = d;
                            if d == 0.0 {
                                return Some(0.0);
                            }
                        }
                    }
                }
            }
            _ => {
                // Split the larger (or the only inner) node; visit the nearer child first.
                let size = |bx: &(Point3<f64>, Point3<f64>)| (bx.1 - bx.0).norm_squared();
                let split_a = !leaf_i && (leaf_j || size(&ba.bounds[i]) >= size(&bb.bounds[j]));
                let (c1, c2) = if split_a {
                    ((li, j), (ri, j))
                } else {
                    ((i, lj), (i, rj))
                };
                let d = |c: (usize, usize)| box_distance(&ba.bounds[c.0], &bb.bounds[c.1]);
                if d(c1) <= d(c2) {
                    stack.push(c2);
                    stack.push(c1);
                } else {
                    stack.push(c1);
                    stack.push(c2);
                }
            }
        }
    }
    (best < limit).then_some(best)
}

/// Whether `p` lies inside the closed mesh (generalised winding number above one half).
///
/// ```
/// use nbv_core::mesh::TriMesh;
/// use nbv_scenes::mesh_distance::contains_point;
/// use nalgebra::Point3;
/// let cube = TriMesh::cuboid([0.5; 3]);
/// assert!(contains_point(&cube, &Point3::new(0.1, 0.2, -0.3)));
/// assert!(!contains_point(&cube, &Point3::new(0.6, 0.0, 0.0)));
/// ```
pub fn contains_point(mesh: &TriMesh, p: &Point3<f64>) -> bool {
    let n = mesh.vertices.len();
    let mut total = 0.0;
    for t in &mesh.triangles {
        if t.iter().any(|&i| i as usize >= n) {
            continue;
        }
        let [a, b, c] = t.map(|i| mesh.vertices[i as usize] - p);
        let (la, lb, lc) = (a.norm(), b.norm(), c.norm());
        let num = a.dot(&b.cross(&c));
        let den = la * lb * lc + a.dot(&b) * lc + b.dot(&c) * la + c.dot(&a) * lb;
        total += 2.0 * num.atan2(den);
    }
    (total / (4.0 * std::f64::consts::PI)).abs() > 0.5
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Isometry3;
    use proptest::prelude::*;

    fn brute(a: &TriMesh, b: &TriMesh) -> f64 {
        let mut best = f64::INFINITY;
        for i in 0..a.triangles.len() {
            for j in 0..b.triangles.len() {
                best = best.min(triangle_distance(&a.triangle(i), &b.triangle(j)));
            }
        }
        best
    }

    #[test]
    fn overlapping_boxes_are_at_zero() {
        let a = TriMesh::cuboid([0.5; 3]);
        let b = a.transformed(&Isometry3::new(
            Vector3::new(0.8, 0.3, 0.1),
            Vector3::new(0.2, 0.5, 0.1),
        ));
        assert_eq!(surface_distance_below(&a, &b, 0.1), Some(0.0));
    }

    #[test]
    fn nested_boxes_are_apart_but_contained() {
        let a = TriMesh::cuboid([0.5; 3]);
        let b = TriMesh::cuboid([0.1; 3]);
        assert_eq!(surface_distance_below(&a, &b, 0.2), None);
        assert!(contains_point(&a, &b.vertices[0]));
    }

    proptest! {
        #[test]
        fn bvh_search_matches_brute_force(
            x in -1.5f64..1.5, y in -1.5f64..1.5, z in -1.5f64..1.5,
            rx in -3.0f64..3.0, ry in -3.0f64..3.0, rz in -3.0f64..3.0,
        ) {
            let a = TriMesh::cuboid([0.5, 0.3, 0.2]);
            let b = TriMesh::cuboid([0.2, 0.4, 0.3])
                .transformed(&Isometry3::new(Vector3::new(x, y, z), Vector3::new(rx, ry, rz)));
            let exact = brute(&a, &b);
            match surface_distance_below(&a, &b, 0.5) {
                Some(d) => prop_assert!((d - exact).abs() < 1e-9 && d < 0.5),
                None => prop_assert!(exact >= 0.5 - 1e-9),
            }
        }

        #[test]
        fn point_to_triangle_is_not_beaten_by_samples(
            px in -2.0f64..2.0, py in -2.0f64..2.0, pz in -2.0f64..2.0,
        ) {
            let (a, b, c) = (Point3::new(0.0, 0.0, 0.0), Point3::new(1.0, 0.2, 0.0), Point3::new(0.3, 1.0, 0.4));
            let p = Point3::new(px, py, pz);
            let d = (p - closest_point_on_triangle(&p, &a, &b, &c)).norm();
            for i in 0..=20 {
                for j in 0..=(20 - i) {
                    let (u, v) = (i as f64 / 20.0, j as f64 / 20.0);
                    let q = a + (b - a) * u + (c - a) * v;
                    prop_assert!(d <= (p - q).norm() + 1e-12);
                }
            }
        }
    }
}
