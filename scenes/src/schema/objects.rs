//! [`ObjectSpec`] and [`ObstacleSpec`]: what stands on the table.

use super::Check;
use super::PoseSpec;
use crate::error::{Problem, SceneError};
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

/// An object to explore (`[[objects]]`).
///
/// The mesh is in the object's own frame: z up, the object rests on its `z = 0` plane,
/// centred on the origin; so `pose.xyz[2]` is the table-top height for an upright object.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObjectSpec {
    /// Unique name (among objects and obstacles). Required.
    pub name: String,
    /// Mesh file (binary/ASCII STL or OBJ, metres), relative to the scene file; must be
    /// watertight with positive volume. Required.
    pub mesh: PathBuf,
    /// Pose of the mesh frame in the world. Required.
    pub pose: PoseSpec,
}

/// An obstacle (`[[obstacles]]`): a box or a mesh, known to the planner or not.
///
/// Exactly one of `box` and `mesh` is given. A box's frame is the centre of its *bottom*
/// face (like the object meshes), so `pose.xyz[2]` is the height it stands on.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObstacleSpec {
    /// Unique name (among objects and obstacles). Required.
    pub name: String,
    /// Box size `[sx, sy, sz]` (m), all positive.
    #[serde(rename = "box", default, skip_serializing_if = "Option::is_none")]
    pub box_size: Option<[f64; 3]>,
    /// Mesh file (STL or OBJ), relative to the scene file; watertight.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mesh: Option<PathBuf>,
    /// Pose of the obstacle frame in the world. Required.
    pub pose: PoseSpec,
    /// Whether the planner is given this obstacle's model (the paper: obstacles' 3D models
    /// are included in the planning environment). Default `true`. Unknown obstacles are
    /// only avoided once the occupancy map has seen them.
    #[serde(default = "default_known")]
    pub known: bool,
}

fn default_known() -> bool {
    true
}

impl ObjectSpec {
    /// Checks the name and pose of `objects[i]`; the error names the key. (Names unique
    /// across objects and obstacles, and the meshes, are checked with the whole scene.)
    pub(crate) fn check(&self, i: usize, c: &Check) -> Result<(), SceneError> {
        c.name(&format!("objects[{i}].name"), &self.name)?;
        c.pose(&format!("objects[{i}].pose"), &self.pose)
    }
}

impl ObstacleSpec {
    /// Checks the name, pose and shape (a box or a mesh, not both) of `obstacles[i]`;
    /// the error names the key.
    pub(crate) fn check(&self, i: usize, c: &Check) -> Result<(), SceneError> {
        c.name(&format!("obstacles[{i}].name"), &self.name)?;
        c.pose(&format!("obstacles[{i}].pose"), &self.pose)?;
        match (&self.box_size, &self.mesh) {
            (Some(b), None) => {
                for (a, v) in b.iter().enumerate() {
                    c.positive(&format!("obstacles[{i}].box[{a}]"), *v)?;
                }
                Ok(())
            }
            (None, Some(_)) => Ok(()),
            _ => Err(c.err(format!("obstacles[{i}]"), Problem::ShapeChoice)),
        }
    }
}
