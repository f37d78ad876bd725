//! [`RobotShapes`]: the robot's collision primitives as parry shapes, which body carries
//! each, and the pairs tested for self-collision.

use super::PlanningError;
use super::parry_bridge::{ParryShape, bounding_radius, link_shape};
use super::shape_core::ShapeCore;
use crate::kinematics::Robot;
use crate::math::Pose;

/// One collision primitive of a link.
#[derive(Debug, Clone)]
pub(crate) struct LinkShape {
    /// Index of its link in `Robot::frame_names`.
    pub frame: usize,
    /// The rigid body that carries it (`Robot::body_of`).
    pub body: usize,
    /// Link name.
    pub link: String,
    /// `T_link_parryshape`: the URDF origin composed with the parry axis fix.
    pub local: Pose,
    /// The shape.
    pub shape: ParryShape,
    /// The shape's core and rounding, at the shape's origin.
    pub core: Option<ShapeCore>,
    /// Radius of a sphere about the shape's centre (the URDF origin) enclosing the URDF
    /// primitive, without padding (m).
    pub radius: f64,
}

/// All link shapes and the self-collision pairs.
#[derive(Debug, Clone)]
pub(crate) struct RobotShapes {
    /// Shapes in `Robot::collision_geometry` order.
    pub shapes: Vec<LinkShape>,
    /// Index pairs (i < j) of shapes on bodies that are neither the same nor adjacent
    /// (body numbers differing by at least 2).
    pub self_pairs: Vec<(usize, usize)>,
    /// How much every shape is grown (m).
    pub padding: f64,
}

impl RobotShapes {
    /// Builds the shapes of every `<collision>` element, grown by `padding` (m, finite,
    /// ≥ 0). Meshes are refused.
    pub fn new(robot: &Robot, padding: f64) -> Result<Self, PlanningError> {
        if !(padding.is_finite() && padding >= 0.0) {
            return Err(PlanningError::InvalidConfig {
                name: "padding",
                value: padding,
                reason: "must be finite and >= 0",
            });
        }
        let mut shapes = Vec::new();
        for g in robot.collision_geometry() {
            let (shape, fix) = link_shape(&g.shape, padding).map_err(|kind| {
                PlanningError::UnsupportedLinkShape {
                    link: g.link.clone(),
                    shape: kind,
                }
            })?;
            let body = robot
                .body_of(&g.link)
                .map_err(|_| PlanningError::UnsupportedLinkShape {
                    link: g.link.clone(),
                    shape: "link not in the kinematic model",
                })?;
            shapes.push(LinkShape {
                frame: g.frame,
                body,
                link: g.link.clone(),
                local: g.origin * fix,
                core: ShapeCore::of(&shape),
                shape,
                radius: bounding_radius(&g.shape),
            });
        }
        let mut self_pairs = Vec::new();
        for i in 0..shapes.len() {
            for j in i + 1..shapes.len() {
                if shapes[i].body.abs_diff(shapes[j].body) >= 2 {
                    self_pairs.push((i, j));
                }
            }
        }
        Ok(Self {
            shapes,
            self_pairs,
            padding,
        })
    }
}
