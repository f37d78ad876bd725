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
    let mut m = Collapsing::new(mesh);
    let mut heap = BinaryHeap::new();
    // Passes: fill the queue with every live edge, collapse until the queue runs dry;
    // refused candidates get another chance in the next pass, while passes make progress.
    let mut progress = true;
    while m.alive_count > target && progress {
        progress = false;
        m.fill_queue(&mut heap);
        while m.alive_count > target {
            let Some(c) = heap.pop() else { break };
            if c.cost > max_error {
                break;
            }
            if let Some(collapse) = m.checked_collapse(&c) {
                progress = true;
                m.collapse(collapse, &mut heap);
            }
        }
    }
    m.compact()
}

/// The cheapest position of an edge `(u, v)`'s collapse under `q` — `u`'s, `v`'s or the
/// midpoint — and its cost (with a tiny length term that orders the free collapses of
/// flat regions shortest first).
fn best(q: &Quadric, pos: &[Point3<f64>], u: u32, v: u32) -> (f64, Point3<f64>) {
    let (pu, pv) = (pos[u as usize], pos[v as usize]);
    let mid = Point3::from((pu.coords + pv.coords) * 0.5);
    let tie = LENGTH_WEIGHT * (pu - pv).norm_squared();
    [pu, pv, mid]
        .into_iter()
        .map(|p| (q.error(&p).max(0.0) + tie, p))
        .fold((f64::INFINITY, pu), |a, b| if b.0 < a.0 { b } else { a })
}

/// A collapse that passed every check: `v` into `u` at `target`.
struct Collapse {
    u: u32,
    v: u32,
    /// The two triangles on the edge, removed by it.
    shared: Vec<u32>,
    /// The summed quadric `u` carries afterwards.
    quadric: Quadric,
    /// Where `u` moves.
    target: Point3<f64>,
}

/// A mesh being simplified: its vertices and triangles (collapsed ones dead), each
/// vertex's triangles, quadric and version (bumped by each collapse that touches it).
struct Collapsing {
    pos: Vec<Point3<f64>>,
    tris: Vec<[u32; 3]>,
    alive: Vec<bool>,
    alive_count: usize,
    incident: Vec<Vec<u32>>,
    quadric: Vec<Quadric>,
    version: Vec<u32>,
}

impl Collapsing {
    /// `mesh` before any collapse: each vertex's quadric the sum of its triangles' planes
    /// weighted by their areas.
    fn new(mesh: &TriMesh) -> Self {
        let pos = mesh.vertices.clone();
        let tris: Vec<[u32; 3]> = mesh.triangles.clone();
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
        Self {
            alive: vec![true; tris.len()],
            alive_count: tris.len(),
            pos,
            tris,
            incident,
            quadric,
            version: vec![0u32; nv],
        }
    }

    /// The vertices sharing a triangle with `v`, sorted.
    fn neighbours(&self, v: u32) -> Vec<u32> {
        let mut n: Vec<u32> = self.incident[v as usize]
            .iter()
            .flat_map(|&t| self.tris[t as usize])
            .filter(|&w| w != v)
            .collect();
        n.sort_unstable();
        n.dedup();
        n
    }

    /// The edge `(u, v)` (`u < v`) as a queue entry at the vertices' current versions.
    fn candidate(&self, u: u32, v: u32) -> Candidate {
        let q = self.quadric[u as usize].add(&self.quadric[v as usize]);
        let (cost, _) = best(&q, &self.pos, u, v);
        Candidate {
            cost,
            u,
            v,
            stamp: (self.version[u as usize], self.version[v as usize]),
        }
    }

    /// Refills `heap` with every live edge, once each.
    fn fill_queue(&self, heap: &mut BinaryHeap<Candidate>) {
        heap.clear();
        let mut seen = HashSet::new();
        for (t, tri) in self.tris.iter().enumerate() {
            if !self.alive[t] {
                continue;
            }
            for k in 0..3 {
                let (u, v) = (tri[k].min(tri[(k + 1) % 3]), tri[k].max(tri[(k + 1) % 3]));
                if seen.insert((u, v)) {
                    heap.push(self.candidate(u, v));
                }
            }
        }
    }

    /// The collapse of `c`, if it is current (no collapse touched its vertices since it
    /// was queued) and allowed: an edge of two triangles, the link condition, degrees
    /// within [`MAX_DEGREE`], no surviving triangle flipped or degenerate.
    fn checked_collapse(&self, c: &Candidate) -> Option<Collapse> {
        let (u, v) = (c.u, c.v);
        if c.stamp != (self.version[u as usize], self.version[v as usize]) {
            return None;
        }
        let shared: Vec<u32> = self.incident[u as usize]
            .iter()
            .copied()
            .filter(|t| self.tris[*t as usize].contains(&v))
            .collect();
        if shared.len() != 2 {
            return None;
        }
        let nu = self.neighbours(u);
        let nv = self.neighbours(v);
        let common = nu.iter().filter(|w| nv.binary_search(w).is_ok()).count();
        let degree = nu.len() + nv.len() - common - 2;
        if common != 2 || nu.len() <= 3 || nv.len() <= 3 || degree > MAX_DEGREE {
            return None;
        }
        let quadric = self.quadric[u as usize].add(&self.quadric[v as usize]);
        let (_, target) = best(&quadric, &self.pos, u, v);
        let collapse = Collapse {
            u,
            v,
            shared,
            quadric,
            target,
        };
        self.keeps_surviving_triangles(&collapse)
            .then_some(collapse)
    }

    /// Whether every triangle that survives `c` keeps its orientation (within about 78°)
    /// and an area, and is compact enough or no less compact than before.
    fn keeps_surviving_triangles(&self, c: &Collapse) -> bool {
        let (u, v) = (c.u, c.v);
        self.incident[u as usize]
            .iter()
            .chain(self.incident[v as usize].iter())
            .filter(|t| !c.shared.contains(t))
            .all(|&t| {
                let tri = self.tris[t as usize];
                let old = tri.map(|i| self.pos[i as usize]);
                let new = tri.map(|i| {
                    if i == u || i == v {
                        c.target
                    } else {
                        self.pos[i as usize]
                    }
                });
                let n_old = (old[1] - old[0]).cross(&(old[2] - old[0]));
                let n_new = (new[1] - new[0]).cross(&(new[2] - new[0]));
                let (lo, ln) = (n_old.norm(), n_new.norm());
                ln > 1e-14
                    && n_old.dot(&n_new) > 0.2 * lo * ln
                    && (compactness(&new) >= MIN_COMPACTNESS
                        || compactness(&new) >= compactness(&old))
            })
    }

    /// Collapses `v` into `u` and queues `u`'s edges again.
    fn collapse(&mut self, c: Collapse, heap: &mut BinaryHeap<Candidate>) {
        let Collapse {
            u,
            v,
            shared,
            quadric,
            target,
        } = c;
        self.pos[u as usize] = target;
        self.quadric[u as usize] = quadric;
        for &t in &shared {
            self.alive[t as usize] = false;
            self.alive_count -= 1;
            for &w in &self.tris[t as usize] {
                self.incident[w as usize].retain(|&x| x != t);
            }
        }
        let moved = std::mem::take(&mut self.incident[v as usize]);
        for t in moved {
            let tri = &mut self.tris[t as usize];
            tri.iter_mut().filter(|w| **w == v).for_each(|w| *w = u);
            self.incident[u as usize].push(t);
        }
        self.version[u as usize] += 1;
        self.version[v as usize] += 1;
        for w in self.neighbours(u) {
            heap.push(self.candidate(u.min(w), u.max(w)));
        }
    }

    /// The surviving triangles and the vertices they use, in order.
    fn compact(self) -> TriMesh {
        let mut remap = vec![u32::MAX; self.pos.len()];
        let mut out = TriMesh::default();
        for (t, tri) in self.tris.iter().enumerate() {
            if !self.alive[t] {
                continue;
            }
            let mapped = tri.map(|i| {
                let slot = &mut remap[i as usize];
                if *slot == u32::MAX {
                    *slot = out.vertices.len() as u32;
                    out.vertices.push(self.pos[i as usize]);
                }
                *slot
            });
            out.triangles.push(mapped);
        }
        out
    }
}
