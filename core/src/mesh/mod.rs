//! Triangle meshes: the shape of objects, obstacles and robot links.

pub mod io;
mod tri_mesh;

pub use tri_mesh::TriMesh;
