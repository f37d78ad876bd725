//! [`TriMesh`]: an indexed triangle mesh with the measures the scenes and the metrics
//! need (area, enclosed volume, bounds, watertightness).

use nalgebra::{Isometry3, Point3, Vector3};
use std::collections::HashMap;

/// An indexed triangle mesh. Triangles are counter-clockwise seen from outside.
///
/// ```
/// use nbv_core::mesh::TriMesh;
/// let cube = TriMesh::cuboid([0.5, 0.5, 0.5]);
/// assert!(cube.is_watertight());
/// assert!((cube.volume() - 1.0).abs() < 1e-12);
/// assert!((cube.area() - 6.0).abs() < 1e-12);
/// ```
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TriMesh {
    /// Vertex positions.
    pub vertices: Vec<Point3<f64>>,
    /// Vertex indices of each triangle.
    pub triangles: Vec<[u32; 3]>,
}

impl TriMesh {
    /// An axis-aligned box centred at the origin with the given half extents.
    pub fn cuboid(half: [f64; 3]) -> Self {
        let [hx, hy, hz] = half;
        let vertices = (0..8)
            .map(|i| {
                Point3::new(
                    if i & 1 == 0 { -hx } else { hx },
                    if i & 2 == 0 { -hy } else { hy },
                    if i & 4 == 0 { -hz } else { hz },
                )
            })
            .collect();
        // Two triangles per face, outward normals.
        let triangles = vec![
            [0, 2, 1],
            [1, 2, 3], // -z
            [4, 5, 6],
            [5, 7, 6], // +z
            [0, 1, 4],
            [1, 5, 4], // -y
            [2, 6, 3],
            [3, 6, 7], // +y
            [0, 4, 2],
            [2, 4, 6], // -x
            [1, 3, 5],
            [3, 7, 5], // +x
        ];
        Self {
            vertices,
            triangles,
        }
    }

    /// The three corners of triangle `i`.
    pub fn triangle(&self, i: usize) -> [Point3<f64>; 3] {
        let [a, b, c] = self.triangles[i];
        [
            self.vertices[a as usize],
            self.vertices[b as usize],
            self.vertices[c as usize],
        ]
    }

    /// Total surface area.
    pub fn area(&self) -> f64 {
        (0..self.triangles.len())
            .map(|i| {
                let [a, b, c] = self.triangle(i);
                0.5 * (b - a).cross(&(c - a)).norm()
            })
            .sum()
    }

    /// Signed enclosed volume (positive for a closed, outward-oriented mesh).
    pub fn volume(&self) -> f64 {
        (0..self.triangles.len())
            .map(|i| {
                let [a, b, c] = self.triangle(i);
                a.coords.dot(&b.coords.cross(&c.coords)) / 6.0
            })
            .sum()
    }

    /// Axis-aligned bounds `(min, max)`, or `None` for a mesh without vertices.
    pub fn bounds(&self) -> Option<(Point3<f64>, Point3<f64>)> {
        let first = *self.vertices.first()?;
        Some(
            self.vertices
                .iter()
                .fold((first, first), |(lo, hi), p| (lo.inf(p), hi.sup(p))),
        )
    }

    /// Whether every edge is shared by exactly two triangles traversing it in opposite
    /// directions (closed, consistently oriented, manifold), and no triangle is degenerate.
    pub fn is_watertight(&self) -> bool {
        if self.triangles.is_empty() {
            return false;
        }
        let mut directed: HashMap<(u32, u32), u32> = HashMap::new();
        for t in &self.triangles {
            if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
                return false;
            }
            for k in 0..3 {
                *directed.entry((t[k], t[(k + 1) % 3])).or_default() += 1;
            }
        }
        directed
            .iter()
            .all(|(&(a, b), &n)| n == 1 && directed.get(&(b, a)) == Some(&1))
    }

    /// Its edges by how many triangles share each: those of one triangle (the boundary of
    /// a hole or an open rim) and those of three or more (non-manifold).
    ///
    /// ```
    /// use nbv_core::mesh::TriMesh;
    /// let cube = TriMesh::cuboid([0.5; 3]);
    /// assert_eq!(cube.edge_counts(), (0, 0));
    /// let mut open = cube.clone();
    /// open.triangles.pop();
    /// assert_eq!(open.edge_counts(), (3, 0));
    /// ```
    pub fn edge_counts(&self) -> (usize, usize) {
        let mut edges: HashMap<(u32, u32), u32> = HashMap::new();
        for t in &self.triangles {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                *edges.entry((a.min(b), a.max(b))).or_default() += 1;
            }
        }
        let boundary = edges.values().filter(|&&n| n == 1).count();
        let non_manifold = edges.values().filter(|&&n| n > 2).count();
        (boundary, non_manifold)
    }

    /// Applies a rigid transform to every vertex.
    pub fn transformed(&self, t: &Isometry3<f64>) -> Self {
        Self {
            vertices: self.vertices.iter().map(|p| t * p).collect(),
            triangles: self.triangles.clone(),
        }
    }

    /// Appends another mesh (its indices are shifted).
    pub fn append(&mut self, other: &TriMesh) {
        let base = self.vertices.len() as u32;
        self.vertices.extend_from_slice(&other.vertices);
        self.triangles.extend(
            other
                .triangles
                .iter()
                .map(|t| [t[0] + base, t[1] + base, t[2] + base]),
        );
    }

    /// Unit normal of triangle `i` (zero for a degenerate triangle).
    pub fn triangle_normal(&self, i: usize) -> Vector3<f64> {
        let [a, b, c] = self.triangle(i);
        (b - a)
            .cross(&(c - a))
            .try_normalize(0.0)
            .unwrap_or_else(Vector3::zeros)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn open_mesh_is_not_watertight() {
        let mut m = TriMesh::cuboid([1.0, 2.0, 3.0]);
        assert!((m.volume() - 48.0).abs() < 1e-9);
        m.triangles.pop();
        assert!(!m.is_watertight());
    }

    #[test]
    fn flipped_triangle_is_not_watertight() {
        let mut m = TriMesh::cuboid([1.0, 1.0, 1.0]);
        m.triangles[0].swap(1, 2);
        assert!(!m.is_watertight());
    }

    #[test]
    fn transform_keeps_volume() {
        let m = TriMesh::cuboid([0.1, 0.2, 0.3]);
        let t = Isometry3::new(Vector3::new(1.0, 2.0, 3.0), Vector3::new(0.3, -0.2, 0.9));
        let moved = m.transformed(&t);
        assert!((moved.volume() - m.volume()).abs() < 1e-12);
        assert!(moved.is_watertight());
    }
}
