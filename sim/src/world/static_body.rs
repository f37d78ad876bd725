//! [`StaticBody`]: a fixed part of the world (table, obstacle, object) with its ground-truth
//! label.

use nbv_core::math::Pose;
use nbv_core::mesh::TriMesh;
use nbv_core::rig::TruthLabel;

/// The shape of a static body.
#[derive(Debug, Clone, PartialEq)]
pub enum StaticShape {
    /// A solid box with the given half extents, centred at `pose`.
    Cuboid {
        /// Half extents along the box's own axes (m).
        half_extents: [f64; 3],
        /// Pose of the box centre in the world frame.
        pose: Pose,
    },
    /// A closed triangle mesh already placed in the world frame.
    Mesh(TriMesh),
}

/// A fixed body of the twin world.
#[derive(Debug, Clone, PartialEq)]
pub struct StaticBody {
    /// Name shown in reports (`table`, `back-panel`, `jug`...).
    pub name: String,
    /// What a ray that hits this body reports.
    pub label: TruthLabel,
    /// Its shape.
    pub shape: StaticShape,
}
