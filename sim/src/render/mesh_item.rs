//! [`MeshItem`]: a triangle mesh placed in the world with a colour and a shading mode —
//! robot links, objects, the table, obstacles.

use super::Color;
use nalgebra::Isometry3;
use nbv_core::mesh::TriMesh;

/// How a mesh's normals are made.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Shading {
    /// One normal per triangle: facets show, edges of boxes stay crisp.
    #[default]
    Flat,
    /// Normals averaged over the triangles around each vertex whose normals differ by less
    /// than the crease angle (40°): curved surfaces look round, sharp edges stay sharp.
    Smooth,
}

/// A triangle mesh in its own frame, placed in the world by `pose`.
///
/// Triangles may be wound either way: both sides are lit. A colour with alpha below 1 is
/// drawn translucent, after every opaque drawable.
#[derive(Debug, Clone, PartialEq)]
pub struct MeshItem {
    /// The mesh, in its own frame.
    pub mesh: TriMesh,
    /// World pose of the mesh frame (`T_world_mesh`).
    pub pose: Isometry3<f64>,
    /// Surface colour.
    pub color: Color,
    /// Normal mode.
    pub shading: Shading,
}

impl MeshItem {
    /// A flat-shaded mesh.
    pub fn flat(mesh: TriMesh, pose: Isometry3<f64>, color: Color) -> Self {
        Self {
            mesh,
            pose,
            color,
            shading: Shading::Flat,
        }
    }

    /// A smooth-shaded mesh.
    pub fn smooth(mesh: TriMesh, pose: Isometry3<f64>, color: Color) -> Self {
        Self {
            mesh,
            pose,
            color,
            shading: Shading::Smooth,
        }
    }
}
