//! [`Obstacle`]: a known obstacle of the scene (the table, the objects' supports, walls) as
//! plain data for the planner.

use crate::math::Pose;
use crate::mesh::TriMesh;

/// The geometry of an [`Obstacle`], in its own frame.
#[derive(Debug, Clone, PartialEq)]
pub enum ObstacleShape {
    /// A box centred on the obstacle frame, with half extents along its x, y, z (m).
    Cuboid {
        /// Half extents (m), each > 0.
        half_extents: [f64; 3],
    },
    /// A triangle mesh. Collision is tested against its **surface**: a link entirely inside
    /// a closed mesh is not reported (use cuboids for solid volumes a link could enter).
    TriMesh(TriMesh),
}

/// A named obstacle at a pose in the robot's base frame.
///
/// ```
/// use nbv_core::planning::Obstacle;
/// // The table: x 0.35–1.35, y −0.6–0.6, z 0–0.25.
/// let table = Obstacle::cuboid("table", [0.85, 0.0, 0.125], [0.5, 0.6, 0.125]);
/// assert_eq!(table.name, "table");
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Obstacle {
    /// Name, used in collision reports.
    pub name: String,
    /// Geometry.
    pub shape: ObstacleShape,
    /// `T_base_obstacle`.
    pub pose: Pose,
}

impl Obstacle {
    /// An axis-aligned box with the given centre and half extents.
    pub fn cuboid(name: impl Into<String>, center: [f64; 3], half_extents: [f64; 3]) -> Self {
        Self {
            name: name.into(),
            shape: ObstacleShape::Cuboid { half_extents },
            pose: Pose::translation(center[0], center[1], center[2]),
        }
    }
}
