//! Triangle meshes: the shape of objects, obstacles and robot links.

mod tri_mesh;

pub use tri_mesh::TriMesh;
