//! [`WorldError`]: why a twin world could not be built.

use std::path::PathBuf;
use thiserror::Error;

/// A failure to build the twin world.
#[derive(Debug, Error)]
pub enum WorldError {
    /// rapier3d-urdf could not load the robot.
    #[error("{path}: cannot load the robot into Rapier: {detail}")]
    Urdf {
        /// URDF file.
        path: PathBuf,
        /// Loader message.
        detail: String,
    },
    /// A link with collision geometry in the URDF has no collider in the Rapier robot
    /// (rapier3d-urdf skips what it cannot load, e.g. a mesh in an unsupported format).
    #[error(
        "{path}: link `{link}` has {expected} collision shape(s) in the URDF but {loaded} collider(s) were loaded"
    )]
    MissingCollider {
        /// URDF file.
        path: PathBuf,
        /// Link name.
        link: String,
        /// Shapes in the URDF.
        expected: usize,
        /// Colliders created.
        loaded: usize,
    },
    /// A link of the Rapier robot is not a frame of the kinematic model.
    #[error("{path}: link `{link}` is not in the kinematic model")]
    UnknownLink {
        /// URDF file.
        path: PathBuf,
        /// Link name.
        link: String,
    },
    /// A static body's mesh is not a valid Rapier triangle mesh.
    #[error("static body `{name}`: invalid triangle mesh: {detail}")]
    Mesh {
        /// Body name.
        name: String,
        /// Builder message.
        detail: String,
    },
}
