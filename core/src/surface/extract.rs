//! [`TsdfVolume::extract_mesh`]: the zero set of the fused distance as a triangle mesh, by
//! marching cubes (`mcubes`: Lorensen & Cline's cases, a vertex where the distance changes
//! sign along a cell edge, linearly interpolated), block by block, welded into one indexed
//! mesh.
//!
//! Each allocated 8³ block is meshed with the first voxels of its neighbours (9³ values,
//! unobserved voxels outside, +1), in parallel, and a cell's triangles are kept only when
//! its eight corners were observed: a surface between an observed voxel and one never seen
//! (the inside beyond the truncation, the space no view looked at) is no surface, the rule
//! Open3D's extraction follows too. Where the views saw an object all round the mesh is
//! closed; where they did not (its base on the table) it is open. Marching cubes rather
//! than Surface Nets: Surface Nets places one vertex inside each cell and joins the
//! vertices of the four cells around a crossed edge, so at every rim of what the views saw
//! (and on thin parts) the surface stops short of the last observed cell; on the paper
//! scenes that strip cost 1–5 points of completeness at 5 mm (docs/surface.md).

use rustc_hash::FxHashMap;

use lin_alg::f32::Vec3;
use mcubes::{MarchingCubes, MeshSide};
use nalgebra::{Point3, Vector3};
use rayon::prelude::*;

use crate::mesh::TriMesh;

use super::TsdfVolume;
use super::tsdf::BLOCK;

/// A triangle mesh with a unit normal per vertex (pointing out of the surface).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SurfaceMesh {
    /// Vertices (world frame) and triangles, counter-clockwise seen from outside.
    pub mesh: TriMesh,
    /// Unit normal of each vertex: the distance field's gradient.
    pub normals: Vec<Vector3<f64>>,
}

/// Values per edge of the array a block is meshed from: its voxels and its neighbours' first.
const SPAN: usize = BLOCK as usize + 1;

/// Half-voxel positions per edge of a block's cells: 0 ..= 2·BLOCK.
const HALF: usize = 2 * BLOCK as usize + 1;

/// One block's share of the surface: its vertices (welded within the block) and
/// triangles indexing them.
#[derive(Default)]
struct BlockMesh {
    /// Each vertex's cell edge (half-voxel units, within the block: 0 ..= 2·BLOCK), its
    /// position (voxel units, global) and its normal.
    vertices: Vec<([u8; 3], Vector3<f64>, Vector3<f64>)>,
    triangles: Vec<[u32; 3]>,
}

impl TsdfVolume {
    /// The fused surface: vertices in the world frame, triangles counter-clockwise seen
    /// from outside, only through cells whose eight corners each had at least
    /// [`min_observations`](super::TsdfParams::min_observations). Empty for an empty
    /// volume. The same for any thread count.
    pub fn extract_mesh(&self) -> SurfaceMesh {
        let per_block: Vec<BlockMesh> = self
            .keys
            .par_iter()
            .map(|key| self.block_mesh(*key))
            .collect();
        // Blocks in allocation order; a vertex inside a block is its own, one on a block's
        // face is shared with the neighbour across it and welded by its global cell edge.
        let voxel = self.params().voxel;
        let mut out = SurfaceMesh::default();
        let mut shared: FxHashMap<[i64; 3], u32> = FxHashMap::default();
        let mut ids = Vec::new();
        for (part, key) in per_block.iter().zip(&self.keys) {
            ids.clear();
            for (edge, grid, normal) in &part.vertices {
                let mut push = || {
                    out.mesh.vertices.push(Point3::from(grid * voxel));
                    out.normals
                        .push(normal.try_normalize(1e-12).unwrap_or_else(Vector3::z));
                    (out.mesh.vertices.len() - 1) as u32
                };
                let on_face = edge.iter().any(|&h| h == 0 || usize::from(h) == HALF - 1);
                ids.push(if on_face {
                    let global = [0, 1, 2]
                        .map(|a| i64::from(edge[a]) + 2 * i64::from(key[a]) * i64::from(BLOCK));
                    *shared.entry(global).or_insert_with(push)
                } else {
                    push()
                });
            }
            for t in &part.triangles {
                let tri = t.map(|i| ids[i as usize]);
                if tri[0] != tri[1] && tri[1] != tri[2] && tri[2] != tri[0] {
                    out.mesh.triangles.push(tri);
                }
            }
        }
        out
    }

    /// The triangles of the cells of block `key` whose corners were all observed, their
    /// vertices welded by the cell edge they lie on.
    fn block_mesh(&self, key: [i32; 3]) -> BlockMesh {
        let min = self.params().min_observations;
        // mcubes' convention: inside where the value is above the level, so −TSDF.
        let mut density = vec![-1.0f32; SPAN * SPAN * SPAN];
        let mut seen = vec![false; density.len()];
        let (mut inside, mut outside) = (false, false);
        let b = BLOCK as usize;
        // The block and its neighbours towards +x, +y, +z (their first voxels close its cells).
        let neighbours: [Option<&super::tsdf::Block>; 8] = std::array::from_fn(|n| {
            let next = [n & 1, (n >> 1) & 1, (n >> 2) & 1].map(|c| c as i32);
            self.index
                .get(&[0, 1, 2].map(|a| key[a] + next[a]))
                .map(|&i| &self.blocks[i])
        });
        for z in 0..SPAN {
            for y in 0..SPAN {
                for x in 0..SPAN {
                    let n = x / b + 2 * (y / b) + 4 * (z / b);
                    let Some(block) = neighbours[n] else {
                        continue;
                    };
                    let i = x % b + b * (y % b + b * (z % b));
                    if block.count[i] < min {
                        continue;
                    }
                    let at = x + SPAN * (y + SPAN * z);
                    density[at] = -block.tsdf[i];
                    seen[at] = true;
                    inside |= block.tsdf[i] < 0.0;
                    outside |= block.tsdf[i] >= 0.0;
                }
            }
        }
        let mut out = BlockMesh::default();
        if !(inside && outside) {
            return out;
        }
        let Ok(cubes) = MarchingCubes::new(
            (SPAN, SPAN, SPAN),
            (1.0, 1.0, 1.0),
            (1.0, 1.0, 1.0),
            Vec3::new_zero(),
            density,
            0.0,
        ) else {
            return out;
        };
        // With −TSDF as the density, the tables' own winding (`InsideOnly`) is the one
        // counter-clockwise seen from outside (the sphere test checks it).
        let soup = cubes.generate(MeshSide::InsideOnly);
        let observed_cell = |c: [f32; 3]| {
            let cell = c.map(|x| (x.max(0.0) as usize).min(SPAN - 2));
            (0..8).all(|k: usize| {
                let p = [0, 1, 2].map(|a| cell[a] + ((k >> a) & 1));
                seen[p[0] + SPAN * (p[1] + SPAN * p[2])]
            })
        };
        let origin = (Vector3::new(key[0], key[1], key[2]) * BLOCK).cast::<f64>();
        let mut slot = vec![u32::MAX; HALF * HALF * HALF];
        for t in soup.indices.chunks_exact(3) {
            let sum =
                soup.vertices[t[0]].posit + soup.vertices[t[1]].posit + soup.vertices[t[2]].posit;
            if !observed_cell([sum.x, sum.y, sum.z].map(|c| c / 3.0)) {
                continue;
            }
            let tri = [t[0], t[1], t[2]].map(|i| {
                let v = &soup.vertices[i];
                let edge = edge_key(v.posit);
                let at = &mut slot[usize::from(edge[0])
                    + HALF * (usize::from(edge[1]) + HALF * usize::from(edge[2]))];
                if *at == u32::MAX {
                    *at = out.vertices.len() as u32;
                    let grid = Vector3::new(v.posit.x, v.posit.y, v.posit.z).cast::<f64>() + origin;
                    let normal = Vector3::new(v.normal.x, v.normal.y, v.normal.z).cast::<f64>();
                    out.vertices.push((edge, grid, normal));
                }
                *at
            });
            out.triangles.push(tri);
        }
        out
    }
}

/// The cell edge (or corner) a marching-cubes vertex at block coordinates `p` (voxel units,
/// in `[0, BLOCK]`) lies on, in half-voxel units (`0 ..= 2·BLOCK`): the two cells sharing an
/// edge interpolate it from opposite ends, so their positions can differ in the last bit
/// and are welded by the edge, not by the position.
fn edge_key(p: Vec3) -> [u8; 3] {
    [p.x, p.y, p.z].map(|c| {
        // Block coordinates are non-negative: truncation is the floor.
        let c = c.max(0.0);
        let r = (c + 0.5) as u32 as f32;
        let half = if (c - r).abs() < 1e-4 {
            2.0 * r
        } else {
            2.0 * (c as u32 as f32) + 1.0
        };
        half.min((HALF - 1) as f32) as u8
    })
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
        // Closed and manifold: marching cubes' cells join edge to edge.
        assert_eq!(s.mesh.edge_counts(), (0, 0));
        assert!(s.mesh.is_watertight());
    }

    /// A square patch of wall seen once: the mesh reaches the patch's rim (within a voxel
    /// and a pixel's footprint), not a strip short of it.
    #[test]
    fn the_mesh_reaches_the_rim_of_what_was_seen() {
        let k = PinholeIntrinsics::of_camera(&DepthCameraSpec::ipa1110());
        let (u0, u1) = (100, 220);
        let depth = (0..k.width * k.height)
            .map(|i| {
                let (u, v) = (i % k.width, i / k.width);
                if (u0..u1).contains(&u) && (u0 - 40..u1 - 40).contains(&v) {
                    0.4
                } else {
                    f32::NAN
                }
            })
            .collect();
        let view = DepthView {
            intrinsics: k,
            depth,
            pose: Isometry3::identity(),
        };
        let params = TsdfParams::default();
        let mut volume = TsdfVolume::new(params).unwrap();
        volume.integrate(&view, |_| 0.002).unwrap();
        let mesh = volume.extract_mesh().mesh;
        let x = |u: usize| (u as f64 - k.cx) / k.fx * 0.4;
        let (lo, hi) = mesh
            .vertices
            .iter()
            .fold((f64::MAX, f64::MIN), |(lo, hi), p| {
                (lo.min(p.x), hi.max(p.x))
            });
        let slack = params.voxel + 0.4 / k.fx;
        assert!(lo < x(u0) + slack, "{lo} against {}", x(u0));
        assert!(hi > x(u1 - 1) - slack, "{hi} against {}", x(u1 - 1));
        assert!(lo > x(u0) - slack && hi < x(u1 - 1) + slack);
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
