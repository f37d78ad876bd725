//! Collision and visual geometry of the robot's links, as plain data read from the URDF, so
//! that collision checkers and renderers can build their own shapes from it.

use crate::math::Pose;
use serde::{Deserialize, Serialize};

/// A URDF geometric primitive, in the link-local frame given by [`LinkGeometry::origin`].
///
/// Conventions are URDF's: boxes are centred on the origin, cylinders and capsules run along
/// the local z axis and are centred on the origin.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum Shape {
    /// A box with the given full side lengths along x, y, z (m).
    Box {
        /// Full side lengths (m).
        size: [f64; 3],
    },
    /// A cylinder along z.
    Cylinder {
        /// Radius (m).
        radius: f64,
        /// Full length along z (m).
        length: f64,
    },
    /// A capsule along z: a cylinder of `length` with hemispherical caps.
    Capsule {
        /// Radius (m).
        radius: f64,
        /// Length of the cylindrical part (m).
        length: f64,
    },
    /// A sphere.
    Sphere {
        /// Radius (m).
        radius: f64,
    },
    /// A mesh file, as named in the URDF (not loaded here).
    Mesh {
        /// File name or URI as written in the URDF.
        filename: String,
        /// Scale along x, y, z.
        scale: [f64; 3],
    },
}

/// One `<collision>` or `<visual>` element of a link.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LinkGeometry {
    /// Index of the link in [`Robot::frame_names`](super::Robot::frame_names).
    pub frame: usize,
    /// Name of the link.
    pub link: String,
    /// The element's optional `name` attribute.
    pub name: Option<String>,
    /// Pose of the shape in the link frame (`T_link_shape`).
    pub origin: Pose,
    /// The primitive.
    pub shape: Shape,
    /// Colour (RGBA in 0..1) of a visual, resolved from its material; `None` for collisions
    /// and for visuals without a colour.
    pub rgba: Option<[f64; 4]>,
}
