//! Distances between placed triangle meshes, and point containment: the geometric tests
//! behind scene validation (objects must not touch or interpenetrate).
//!
//! parry (f64) does the geometry: its mesh-against-mesh closest points within a limit (a
//! bounding-volume hierarchy over each mesh, a triangle–triangle distance per pair it
//! cannot prune; 0 when the surfaces cross or touch), and its containment test by angle-weighted
//! pseudo-normals for closed, consistently oriented meshes. This file is the boundary:
//! it converts the project's meshes (nalgebra) to parry's (glam).

use std::cell::OnceCell;

use nalgebra::Point3;
use nbv_core::mesh::TriMesh;
use parry3d_f64::math::{Pose, Vector};
use parry3d_f64::query::{self, ClosestPoints, PointQuery};
use parry3d_f64::shape::{TriMesh as ParryMesh, TriMeshFlags};

/// `mesh` as a parry mesh (its triangles with indices in range), if it has a triangle.
fn to_parry(mesh: &TriMesh, flags: TriMeshFlags) -> Option<ParryMesh> {
    let n = mesh.vertices.len();
    let vertices: Vec<Vector> = mesh
        .vertices
        .iter()
        .map(|p| Vector::new(p.x, p.y, p.z))
        .collect();
    let triangles: Vec<[u32; 3]> = mesh
        .triangles
        .iter()
        .filter(|t| t.iter().all(|&v| (v as usize) < n))
        .copied()
        .collect();
    if triangles.is_empty() {
        return None;
    }
    ParryMesh::with_flags(vertices, triangles, flags).ok()
}

/// Placed meshes converted to parry once, for many distance and containment queries
/// (scene validation asks about every pair; building a mesh's hierarchy is most of a
/// query's cost).
///
/// ```
/// use nbv_core::mesh::TriMesh;
/// use nbv_scenes::mesh_distance::Surfaces;
/// use nalgebra::{Isometry3, Point3};
/// let a = TriMesh::cuboid([0.5; 3]);
/// let b = a.transformed(&Isometry3::translation(1.25, 0.0, 0.0));
/// let set = Surfaces::new([&a, &b]);
/// assert!((set.distance_below(0, 1, 1.0).unwrap() - 0.25).abs() < 1e-12);
/// assert!(set.contains(1, &Point3::new(1.2, 0.0, 0.0)));
/// ```
pub struct Surfaces<'a> {
    meshes: Vec<&'a TriMesh>,
    plain: Vec<Option<ParryMesh>>,
    oriented: Vec<OnceCell<Option<ParryMesh>>>,
}

impl<'a> Surfaces<'a> {
    /// Converts each mesh (the oriented form for containment is built on first use).
    pub fn new(meshes: impl IntoIterator<Item = &'a TriMesh>) -> Self {
        let meshes: Vec<&TriMesh> = meshes.into_iter().collect();
        Self {
            plain: meshes
                .iter()
                .map(|m| to_parry(m, TriMeshFlags::empty()))
                .collect(),
            oriented: meshes.iter().map(|_| OnceCell::new()).collect(),
            meshes,
        }
    }

    /// The distance between meshes `a` and `b`'s surfaces if it is below `limit`, else
    /// `None` (also when a mesh has no triangle). 0 when they cross or touch.
    ///
    /// # Panics
    /// If `a` or `b` is not an index of the set.
    pub fn distance_below(&self, a: usize, b: usize, limit: f64) -> Option<f64> {
        let (pa, pb) = (self.plain[a].as_ref()?, self.plain[b].as_ref()?);
        // Closest points within `limit` only: the hierarchies prune every pair farther apart.
        let pair = query::closest_points(&Pose::IDENTITY, pa, &Pose::IDENTITY, pb, limit).ok()?;
        let d = match pair {
            ClosestPoints::Intersecting => 0.0,
            ClosestPoints::WithinMargin(p, q) => (p - q).length(),
            ClosestPoints::Disjoint => return None,
        };
        (d < limit).then_some(d)
    }

    /// Whether `p` lies inside closed mesh `i` (behind the pseudo-normal of its nearest
    /// surface feature; a mesh parry cannot orient contains nothing).
    ///
    /// # Panics
    /// If `i` is not an index of the set.
    pub fn contains(&self, i: usize, p: &Point3<f64>) -> bool {
        let flags = TriMeshFlags::ORIENTED | TriMeshFlags::MERGE_DUPLICATE_VERTICES;
        self.oriented[i]
            .get_or_init(|| to_parry(self.meshes[i], flags))
            .as_ref()
            .is_some_and(|m| m.contains_local_point(Vector::new(p.x, p.y, p.z)))
    }
}

/// The distance between two meshes' surfaces if it is below `limit`, else `None` (also
/// when a mesh has no triangle); one query of a two-mesh [`Surfaces`].
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
    Surfaces::new([a, b]).distance_below(0, 1, limit)
}

/// Whether `p` lies inside the closed mesh; one query of a one-mesh [`Surfaces`].
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
    Surfaces::new([mesh]).contains(0, p)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Isometry3, Vector3};
    use proptest::prelude::*;

    /// The distance between two axis-aligned boxes (min, max): 0 when they overlap.
    fn box_gap(a: ([f64; 3], [f64; 3]), b: ([f64; 3], [f64; 3])) -> f64 {
        let gap = |k: usize| (b.0[k] - a.1[k]).max(a.0[k] - b.1[k]).max(0.0);
        Vector3::new(gap(0), gap(1), gap(2)).norm()
    }

    /// The smallest distance over every pair of triangles, each pair by parry's exact
    /// triangle–triangle distance: what the hierarchy's pruning must not change.
    fn all_pairs(a: &TriMesh, b: &TriMesh) -> f64 {
        let tri = |m: &TriMesh, i: usize| {
            let [p, q, r] = m.triangle(i).map(|v| Vector::new(v.x, v.y, v.z));
            parry3d_f64::shape::Triangle::new(p, q, r)
        };
        let mut best = f64::INFINITY;
        for i in 0..a.triangles.len() {
            for j in 0..b.triangles.len() {
                let d = query::distance(&Pose::IDENTITY, &tri(a, i), &Pose::IDENTITY, &tri(b, j))
                    .unwrap()
                    .distance;
                best = best.min(d);
            }
        }
        best
    }

    /// The smallest distance between the surfaces by sampling: every vertex of one mesh
    /// against a dense grid of points on the other's faces — an upper bound of the truth.
    fn sampled(a: &TriMesh, b: &TriMesh) -> f64 {
        let mut best = f64::INFINITY;
        for (m, other) in [(a, b), (b, a)] {
            for i in 0..m.triangles.len() {
                let [p, q, r] = m.triangle(i);
                for s in 0..=12 {
                    for t in 0..=(12 - s) {
                        let (u, v) = (s as f64 / 12.0, t as f64 / 12.0);
                        let x = p + (q - p) * u + (r - p) * v;
                        for w in &other.vertices {
                            best = best.min((x - w).norm());
                        }
                    }
                }
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
        let d = surface_distance_below(&a, &b, 1.0).unwrap();
        assert!((d - 0.4).abs() < 1e-12, "{d}");
        assert!(contains_point(&a, &b.vertices[0]));
        assert!(!contains_point(&b, &a.vertices[0]));
    }

    #[test]
    fn empty_meshes_have_no_distance_and_contain_nothing() {
        let empty = TriMesh {
            vertices: vec![Point3::origin()],
            triangles: vec![[0, 1, 2]],
        };
        let cube = TriMesh::cuboid([0.5; 3]);
        assert_eq!(surface_distance_below(&empty, &cube, 10.0), None);
        assert!(!contains_point(&empty, &Point3::origin()));
    }

    proptest! {
        #[test]
        fn translated_boxes_are_at_their_gap(
            x in -1.5f64..1.5, y in -1.5f64..1.5, z in -1.5f64..1.5,
        ) {
            let (ha, hb) = ([0.5, 0.3, 0.2], [0.2, 0.4, 0.3]);
            let a = TriMesh::cuboid(ha);
            let b = TriMesh::cuboid(hb).transformed(&Isometry3::translation(x, y, z));
            let exact = box_gap(
                (ha.map(|h| -h), ha),
                ([x - hb[0], y - hb[1], z - hb[2]], [x + hb[0], y + hb[1], z + hb[2]]),
            );
            match surface_distance_below(&a, &b, 0.5) {
                Some(d) if exact > 0.0 => prop_assert!((d - exact).abs() < 1e-9 && d < 0.5),
                // Overlapping boxes: their surfaces cross, unless one holds the other.
                Some(d) => prop_assert!(d == 0.0 || d < 0.5),
                None => prop_assert!(exact >= 0.5 - 1e-9 || exact == 0.0),
            }
        }

        #[test]
        fn the_hierarchy_finds_the_closest_pair_of_rotated_boxes(
            x in -1.5f64..1.5, y in -1.5f64..1.5, z in -1.5f64..1.5,
            rx in -3.0f64..3.0, ry in -3.0f64..3.0, rz in -3.0f64..3.0,
        ) {
            let a = TriMesh::cuboid([0.5, 0.3, 0.2]);
            let b = TriMesh::cuboid([0.2, 0.4, 0.3])
                .transformed(&Isometry3::new(Vector3::new(x, y, z), Vector3::new(rx, ry, rz)));
            let upper = sampled(&a, &b);
            let exact = all_pairs(&a, &b);
            match surface_distance_below(&a, &b, 10.0) {
                Some(d) => {
                    prop_assert!((d - exact).abs() < 1e-9, "{d} against all pairs {exact}");
                    prop_assert!(d <= upper + 1e-9, "{d} > sampled {upper}");
                }
                None => prop_assert!(false, "boxes within 10 m have a distance"),
            }
        }

        #[test]
        fn containment_of_a_rotated_box(
            px in -1.0f64..1.0, py in -1.0f64..1.0, pz in -1.0f64..1.0,
            rx in -3.0f64..3.0, ry in -3.0f64..3.0, rz in -3.0f64..3.0,
        ) {
            let pose = Isometry3::new(Vector3::new(0.1, -0.2, 0.05), Vector3::new(rx, ry, rz));
            let half = [0.5, 0.3, 0.2];
            let mesh = TriMesh::cuboid(half).transformed(&pose);
            let p = Point3::new(px, py, pz);
            let local = pose.inverse_transform_point(&p);
            let margin = (0..3).map(|k| half[k] - local[k].abs()).fold(f64::INFINITY, f64::min);
            // Away from the surface (1e-9), inside is exactly the local box test.
            prop_assume!(margin.abs() > 1e-9);
            prop_assert_eq!(contains_point(&mesh, &p), margin > 0.0);
        }
    }
}
