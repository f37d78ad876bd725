//! Mesh simplification by edge collapse with quadric error metrics (after Garland &
//! Heckbert), restricted to collapses that keep a closed mesh closed and manifold.
//!
//! Marching tetrahedra gives many small, thin triangles; this brings an object down to a
//! modest triangle count while keeping its shape (each collapse takes the cheaper of the two
//! end points and the midpoint under the summed plane quadrics). A collapse is refused when
//! the two end points share neighbours other than the two opposite corners (the link
//! condition), when a surviving triangle would flip or degenerate, or when its error
//! exceeds `max_error`. Deterministic: ties are broken by vertex indices.

use nalgebra::{Point3, Vector3};
use nbv_core::mesh::TriMesh;
use std::cmp::Ordering;
use std::collections::{BinaryHeap, HashSet};

/// Weight (m² per m²) of the squared edge length added to a collapse's cost.
const LENGTH_WEIGHT: f64 = 1e-8;
/// Largest vertex degree a collapse may create.
const MAX_DEGREE: usize = 12;
/// Smallest compactness (1 for an equilateral triangle) a collapse may create.
const MIN_COMPACTNESS: f64 = 0.15;

/// `4√3 · area / Σ edge²`: 1 for an equilateral triangle, 0 for a degenerate one.
fn compactness(t: &[Point3<f64>; 3]) -> f64 {
    let twice_area = (t[1] - t[0]).cross(&(t[2] - t[0])).norm();
    let sum =
        (t[1] - t[0]).norm_squared() + (t[2] - t[1]).norm_squared() + (t[0] - t[2]).norm_squared();
    if sum > 0.0 {
        2.0 * 3f64.sqrt() * twice_area / sum
    } else {
        0.0
    }
}

/// A symmetric 4×4 quadric (upper triangle, row major).
#[derive(Debug, Clone, Copy, Default)]
struct Quadric([f64; 10]);

impl Quadric {
    fn plane(n: Vector3<f64>, d: f64, w: f64) -> Self {
        let (a, b, c) = (n.x, n.y, n.z);
        Self(
            [
                a * a,
                a * b,
                a * c,
                a * d,
                b * b,
                b * c,
                b * d,
                c * c,
                c * d,
                d * d,
            ]
            .map(|x| x * w),
        )
    }

    fn add(&self, o: &Quadric) -> Quadric {
        let mut q = self.0;
        q.iter_mut().zip(o.0).for_each(|(a, b)| *a += b);
        Quadric(q)
    }

    fn error(&self, p: &Point3<f64>) -> f64 {
        let q = &self.0;
        let (x, y, z) = (p.x, p.y, p.z);
        q[0] * x * x
            + 2.0 * q[1] * x * y
            + 2.0 * q[2] * x * z
            + 2.0 * q[3] * x
            + q[4] * y * y
            + 2.0 * q[5] * y * z
            + 2.0 * q[6] * y
            + q[7] * z * z
            + 2.0 * q[8] * z
            + q[9]
    }
}

#[derive(Debug, PartialEq)]
struct Candidate {
    cost: f64,
    u: u32,
    v: u32,
    stamp: (u32, u32),
}

impl Eq for Candidate {}

impl Ord for Candidate {
    fn cmp(&self, o: &Self) -> Ordering {
        // Min-heap on cost, then on indices.
        o.cost
            .total_cmp(&self.cost)
            .then_with(|| o.u.cmp(&self.u))
            .then_with(|| o.v.cmp(&self.v))
    }
}

impl PartialOrd for Candidate {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}

/// Simplifies a closed manifold mesh down to at most `target` triangles, stopping early
/// where the next collapse would cost more than `max_error` (summed squared distances to
/// the original planes, m²). The result stays watertight and consistently oriented.
///
/// ```
/// use nbv_scenes::meshgen::{decimate::decimate, marching_tetrahedra::{Grid, polygonize}};
/// use nalgebra::Point3;
/// let grid = Grid::covering(Point3::new(-1.0, -1.0, -1.0), Point3::new(1.0, 1.0, 1.0), 0.1);
/// let sphere = polygonize(&grid, |p| p.coords.norm() - 1.0);
/// let small = decimate(&sphere, 2000, f64::INFINITY);
/// assert_eq!(small.triangles.len(), 2000);
/// assert!(small.is_watertight());
/// assert!((small.volume() - sphere.volume()).abs() < 0.05 * sphere.volume());
/// ```
pub fn decimate(mesh: &TriMesh, target: usize, max_error: f64) -> TriMesh {
    let mut pos = mesh.vertices.clone();
    let mut tris: Vec<[u32; 3]> = mesh.triangles.clone();
    let mut alive = vec![true; tris.len()];
    let mut alive_count = tris.len();
    let nv = pos.len();
    let mut incident: Vec<Vec<u32>> = vec![Vec::new(); nv];
    let mut quadric = vec![Quadric::default(); nv];
    for (t, tri) in tris.iter().enumerate() {
        let [a, b, c] = tri.map(|i| pos[i as usize]);
        let cross = (b - a).cross(&(c - a));
        let area = 0.5 * cross.norm();
        if let Some(n) = cross.try_normalize(0.0) {
            let q = Quadric::plane(n, -n.dot(&a.coords), area);
            for &i in tri {
                quadric[i as usize] = quadric[i as usize].add(&q);
            }
        }
        for &i in tri {
            incident[i as usize].push(t as u32);
        }
    }
    let mut version = vec![0u32; nv];
    let mut heap = BinaryHeap::new();
    let best = |q: &Quadric, pos: &[Point3<f64>], u: u32, v: u32| -> (f64, Point3<f64>) {
        let (pu, pv) = (pos[u as usize], pos[v as usize]);
        let mid = Point3::from((pu.coords + pv.coords) * 0.5);
        // A tiny length term orders the free collapses of flat regions shortest first.
        let tie = LENGTH_WEIGHT * (pu - pv).norm_squared();
        [pu, pv, mid]
            .into_iter()
            .map(|p| (q.error(&p).max(0.0) + tie, p))
            .fold((f64::INFINITY, pu), |a, b| if b.0 < a.0 { b } else { a })
    };
    let neighbours = |tris: &[[u32; 3]], incident: &[Vec<u32>], v: u32| -> Vec<u32> {
        let mut n: Vec<u32> = incident[v as usize]
            .iter()
            .flat_map(|&t| tris[t as usize])
            .filter(|&w| w != v)
            .collect();
        n.sort_unstable();
        n.dedup();
        n
    };
    // Passes: fill the queue with every live edge, collapse until the queue runs dry;
    // refused candidates get another chance in the next pass, while passes make progress.
    let mut progress = true;
    while alive_count > target && progress {
        progress = false;
        heap.clear();
        let mut seen = HashSet::new();
        for (t, tri) in tris.iter().enumerate() {
            if !alive[t] {
                continue;
            }
            for k in 0..3 {
                let (u, v) = (tri[k].min(tri[(k + 1) % 3]), tri[k].max(tri[(k + 1) % 3]));
                if seen.insert((u, v)) {
                    let q = quadric[u as usize].add(&quadric[v as usize]);
                    let (cost, _) = best(&q, &pos, u, v);
                    heap.push(Candidate {
                        cost,
                        u,
                        v,
                        stamp: (version[u as usize], version[v as usize]),
                    });
                }
            }
        }
        while alive_count > target {
            let Some(c) = heap.pop() else { break };
            if c.cost > max_error {
                break;
            }
            let (u, v) = (c.u, c.v);
            if c.stamp != (version[u as usize], version[v as usize]) {
                continue;
            }
            let shared: Vec<u32> = incident[u as usize]
                .iter()
                .copied()
                .filter(|t| tris[*t as usize].contains(&v))
                .collect();
            if shared.len() != 2 {
                continue;
            }
            let nu = neighbours(&tris, &incident, u);
            let nv_ = neighbours(&tris, &incident, v);
            let common = nu.iter().filter(|w| nv_.binary_search(w).is_ok()).count();
            let degree = nu.len() + nv_.len() - common - 2;
            if common != 2 || nu.len() <= 3 || nv_.len() <= 3 || degree > MAX_DEGREE {
                continue;
            }
            let q = quadric[u as usize].add(&quadric[v as usize]);
            let (_, target_pos) = best(&q, &pos, u, v);
            // Reject flips and degeneracies of the triangles that survive.
            let ok = incident[u as usize]
                .iter()
                .chain(incident[v as usize].iter())
                .filter(|t| !shared.contains(t))
                .all(|&t| {
                    let tri = tris[t as usize];
                    let old = tri.map(|i| pos[i as usize]);
                    let new = tri.map(|i| {
                        if i == u || i == v {
                            target_pos
                        } else {
                            pos[i as usize]
                        }
                    });
                    let n_old = (old[1] - old[0]).cross(&(old[2] - old[0]));
                    let n_new = (new[1] - new[0]).cross(&(new[2] - new[0]));
                    let (lo, ln) = (n_old.norm(), n_new.norm());
                    ln > 1e-14
                        && n_old.dot(&n_new) > 0.2 * lo * ln
                        && (compactness(&new) >= MIN_COMPACTNESS
                            || compactness(&new) >= compactness(&old))
                });
            if !ok {
                continue;
            }
            // Collapse v into u.
            progress = true;
            pos[u as usize] = target_pos;
            quadric[u as usize] = q;
            for &t in &shared {
                alive[t as usize] = false;
                alive_count -= 1;
                for &w in &tris[t as usize] {
                    incident[w as usize].retain(|&x| x != t);
                }
            }
            let moved = std::mem::take(&mut incident[v as usize]);
            for t in moved {
                let tri = &mut tris[t as usize];
                tri.iter_mut().filter(|w| **w == v).for_each(|w| *w = u);
                incident[u as usize].push(t);
            }
            version[u as usize] += 1;
            version[v as usize] += 1;
            for w in neighbours(&tris, &incident, u) {
                let (a, b) = (u.min(w), u.max(w));
                let q = quadric[a as usize].add(&quadric[b as usize]);
                let (cost, _) = best(&q, &pos, a, b);
                heap.push(Candidate {
                    cost,
                    u: a,
                    v: b,
                    stamp: (version[a as usize], version[b as usize]),
                });
            }
        }
    }
    // Compact: keep the surviving triangles and the vertices they use, in order.
    let mut remap = vec![u32::MAX; nv];
    let mut out = TriMesh::default();
    for (t, tri) in tris.iter().enumerate() {
        if !alive[t] {
            continue;
        }
        let mapped = tri.map(|i| {
            let slot = &mut remap[i as usize];
            if *slot == u32::MAX {
                *slot = out.vertices.len() as u32;
                out.vertices.push(pos[i as usize]);
            }
            *slot
        });
        out.triangles.push(mapped);
    }
    out
}
