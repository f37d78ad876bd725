//! [`TsdfVolume::extract_mesh`]: the zero set of the fused distance as a triangle mesh,
//! by Surface Nets (`fast-surface-nets`: one vertex per cell the surface crosses, placed
//! at the mean of the edge crossings, quads between them).
//!
//! The allocated blocks are copied into one array (unobserved voxels outside, +1) and the
//! mesh kept only where every corner of a vertex's cell was observed: a surface between an
//! observed voxel and one never seen (the inside beyond the truncation, the space no view
//! looked at) is no surface, the rule Open3D's extraction follows too. Where the views saw
//! an object all round the mesh is closed; where they did not (its base on the table) it
//! is open.

use fast_surface_nets::ndshape::{RuntimeShape, Shape};
use fast_surface_nets::{SurfaceNetsBuffer, surface_nets};
use nalgebra::{Point3, Vector3};

use crate::mesh::TriMesh;

use super::TsdfVolume;
use super::tsdf::{BLOCK, local_coords};

/// A triangle mesh with a unit normal per vertex (pointing out of the surface).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SurfaceMesh {
    /// Vertices (world frame) and triangles, counter-clockwise seen from outside.
    pub mesh: TriMesh,
    /// Unit normal of each vertex: the distance field's gradient.
    pub normals: Vec<Vector3<f64>>,
}

impl TsdfVolume {
    /// The fused surface: vertices in the world frame, triangles counter-clockwise seen
    /// from outside, only through cells whose eight corners each had at least
    /// [`min_observations`](super::TsdfParams::min_observations). Empty for an empty
    /// volume.
    pub fn extract_mesh(&self) -> SurfaceMesh {
        let Some((lo, hi)) = self.voxel_bounds() else {
            return SurfaceMesh::default();
        };
        // One voxel of padding on each side, unobserved.
        let dims = [0, 1, 2].map(|a| (hi[a] - lo[a] + 3) as u32);
        let shape = RuntimeShape::<u32, 3>::new(dims);
        let len = shape.size() as usize;
        let mut sdf = vec![1.0f32; len];
        let mut seen = vec![false; len];
        let min = self.params().min_observations;
        for (key, block) in self.keys.iter().zip(&self.blocks) {
            for i in 0..block.tsdf.len() {
                if block.count[i] < min {
                    continue;
                }
                let v = Vector3::new(key[0], key[1], key[2]) * BLOCK + local_coords(i);
                let a = [0, 1, 2].map(|k| (v[k] - lo[k] + 1) as u32);
                let at = shape.linearize(a) as usize;
                sdf[at] = block.tsdf[i];
                seen[at] = true;
            }
        }
        let mut buffer = SurfaceNetsBuffer::default();
        surface_nets(&sdf, &shape, [0; 3], dims.map(|d| d - 1), &mut buffer);
        // A vertex stands when every corner of its cell was observed.
        let corner_strides: Vec<usize> = (0..8u32)
            .map(|c| shape.linearize([c & 1, (c >> 1) & 1, (c >> 2) & 1]) as usize)
            .collect();
        let keep: Vec<bool> = buffer
            .surface_strides
            .iter()
            .map(|&s| corner_strides.iter().all(|&c| seen[s as usize + c]))
            .collect();
        let mut new_index = vec![u32::MAX; keep.len()];
        let voxel = self.params().voxel;
        let mut out = SurfaceMesh::default();
        for (k, p) in buffer.positions.iter().enumerate() {
            if !keep[k] {
                continue;
            }
            new_index[k] = out.mesh.vertices.len() as u32;
            let grid = Vector3::new(p[0], p[1], p[2]).cast::<f64>();
            let lo = Vector3::new(lo[0], lo[1], lo[2]).cast::<f64>();
            out.mesh
                .vertices
                .push(Point3::from((grid + lo).add_scalar(-1.0) * voxel));
            let n = buffer.normals[k];
            let n = Vector3::new(n[0], n[1], n[2]).cast::<f64>();
            out.normals
                .push(n.try_normalize(0.0).unwrap_or_else(Vector3::z));
        }
        for t in buffer.indices.chunks_exact(3) {
            let t = [t[0], t[1], t[2]].map(|i| new_index[i as usize]);
            if t.iter().all(|&i| i != u32::MAX) {
                // Surface Nets winds its quads counter-clockwise seen from outside.
                out.mesh.triangles.push(t);
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rig::DepthCameraSpec;
    use crate::surface::{DepthView, PinholeIntrinsics, TsdfParams};
    use nalgebra::Isometry3;
    use nbv_fixtures::sphere_views::{look_at, sphere_depth};

    /// The depth view of a sphere of radius `r` at `centre` seen from a camera at `pose`.
    fn sphere_view(pose: Isometry3<f64>, centre: Point3<f64>, r: f64) -> DepthView {
        let k = PinholeIntrinsics::of_camera(&DepthCameraSpec::ipa1110());
        let depth = sphere_depth(k.width, k.height, k.fx, &pose, centre, r);
        DepthView {
            intrinsics: k,
            depth,
            pose,
        }
    }

    /// A 5 cm sphere seen from 14 directions: a closed, outward surface within half a
    /// millimetre of the sphere.
    #[test]
    fn a_sphere_seen_all_round_is_closed_and_on_the_sphere() {
        let centre = Point3::new(0.8, 0.1, 0.3);
        let r = 0.05;
        let mut volume = TsdfVolume::new(TsdfParams::default()).unwrap();
        let dirs = [
            (1.0, 0.0, 0.0),
            (-1.0, 0.0, 0.0),
            (0.0, 1.0, 0.0),
            (0.0, -1.0, 0.0),
            (0.0, 0.0, 1.0),
            (0.0, 0.0, -1.0),
            (1.0, 1.0, 1.0),
            (-1.0, 1.0, 1.0),
            (1.0, -1.0, 1.0),
            (-1.0, -1.0, 1.0),
            (1.0, 1.0, -1.0),
            (-1.0, 1.0, -1.0),
            (1.0, -1.0, -1.0),
            (-1.0, -1.0, -1.0),
        ];
        for (x, y, z) in dirs {
            let eye = centre + Vector3::new(x, y, z).normalize() * 0.4;
            volume
                .integrate(&sphere_view(look_at(eye, centre), centre, r), |_| 0.002)
                .unwrap();
        }
        let s = volume.extract_mesh();
        let err: Vec<f64> = s
            .mesh
            .vertices
            .iter()
            .map(|p| ((p - centre).norm() - r).abs())
            .collect();
        let mean = err.iter().sum::<f64>() / err.len() as f64;
        assert!(mean < 5e-4, "mean {mean}");
        assert!(err.iter().all(|e| *e < 2e-3));
        assert!(s.mesh.volume() > 0.0, "outward");
        let true_volume = 4.0 / 3.0 * std::f64::consts::PI * r.powi(3);
        assert!((s.mesh.volume() - true_volume).abs() < 0.05 * true_volume);
        // Normals point away from the centre (the gradient of a few ambiguous cells less
        // so).
        let dots: Vec<f64> = s
            .mesh
            .vertices
            .iter()
            .zip(&s.normals)
            .map(|(p, n)| n.dot(&(p - centre).normalize()))
            .collect();
        assert!(dots.iter().all(|d| *d > 0.0));
        assert!(dots.iter().sum::<f64>() / dots.len() as f64 > 0.98);
        // Closed; Surface Nets joins two sheets at a vertex in a few ambiguous cells.
        let (boundary, non_manifold) = s.mesh.edge_counts();
        assert_eq!(boundary, 0);
        assert!(
            non_manifold * 500 < s.mesh.triangles.len(),
            "{non_manifold}"
        );
    }

    /// One view of the sphere: its near cap only, open at the silhouette.
    #[test]
    fn one_view_gives_the_near_cap_only() {
        let centre = Point3::new(0.0, 0.0, 0.4);
        let mut volume = TsdfVolume::new(TsdfParams::default()).unwrap();
        volume
            .integrate(&sphere_view(Isometry3::identity(), centre, 0.05), |_| 0.002)
            .unwrap();
        let s = volume.extract_mesh();
        assert!(!s.mesh.triangles.is_empty());
        assert!(s.mesh.vertices.iter().all(|p| p.z < 0.4 + 0.002));
        assert!(!s.mesh.is_watertight());
    }
}
