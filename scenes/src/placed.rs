//! The scene's shapes in the world frame: object and obstacle meshes loaded and placed
//! at their poses, and the table as a box mesh.

use crate::error::SceneError;
use crate::scene::Scene;
use crate::schema::{ObstacleSpec, Table};
use nalgebra::{Isometry3, Point3};
use nbv_core::mesh::TriMesh;
use nbv_core::mesh::io::{MeshIoError, read_mesh};
use std::path::PathBuf;

/// An obstacle's mesh in its own frame (a box stands on its bottom face's centre).
pub fn obstacle_local_mesh(o: &ObstacleSpec) -> Result<TriMesh, MeshIoError> {
    match (&o.box_size, &o.mesh) {
        (Some([sx, sy, sz]), _) => Ok(TriMesh::cuboid([0.5 * sx, 0.5 * sy, 0.5 * sz])
            .transformed(&Isometry3::translation(0.0, 0.0, 0.5 * sz))),
        (None, Some(path)) => read_mesh(path),
        (None, None) => Err(MeshIoError::Empty {
            path: PathBuf::from(&o.name),
        }),
    }
}

/// The table as a closed box mesh in the world frame.
pub fn table_mesh(t: &Table) -> TriMesh {
    let c = Point3::from((nalgebra::Vector3::from(t.min) + nalgebra::Vector3::from(t.max)) * 0.5);
    let half = [0, 1, 2].map(|a| 0.5 * (t.max[a] - t.min[a]));
    TriMesh::cuboid(half).transformed(&Isometry3::translation(c.x, c.y, c.z))
}

impl Scene {
    /// Every object's mesh placed in the world frame, in `objects` order.
    pub fn object_meshes(&self) -> Result<Vec<TriMesh>, SceneError> {
        self.objects
            .iter()
            .enumerate()
            .map(|(i, o)| {
                read_mesh(&o.mesh)
                    .map(|m| m.transformed(&o.pose.to_pose()))
                    .map_err(|source| SceneError::Mesh {
                        file: self.file(),
                        key: format!("objects[{i}].mesh"),
                        source,
                    })
            })
            .collect()
    }

    /// Every obstacle's mesh placed in the world frame, in `obstacles` order.
    pub fn obstacle_meshes(&self) -> Result<Vec<TriMesh>, SceneError> {
        self.obstacles
            .iter()
            .enumerate()
            .map(|(i, o)| {
                obstacle_local_mesh(o)
                    .map(|m| m.transformed(&o.pose.to_pose()))
                    .map_err(|source| SceneError::Mesh {
                        file: self.file(),
                        key: format!("obstacles[{i}].mesh"),
                        source,
                    })
            })
            .collect()
    }
}
