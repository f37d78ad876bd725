//! [`TwinWorld`]: the Rapier world of a scene with the robot posed kinematically.
//!
//! The robot's colliders come from its URDF through `rapier3d-urdf` (one collider per
//! `<collision>` primitive). They are inserted without parent bodies and moved directly:
//! the twin arm is position-controlled, so no dynamics is simulated. Setting a
//! configuration computes every link pose with [`Robot::link_poses`] and refreshes the
//! colliders' leaves in the broad phase, so later queries see the new pose.
//!
//! Contacts are exact shape intersection tests: every robot collider against the static
//! bodies through Rapier's query pipeline, and against the colliders of non-adjacent robot
//! bodies (bodies whose joint numbers differ by more than one; see [`Robot::body_of`]).

use super::{Contact, Contacted, RayCaster, StaticBody, StaticShape, WorldError};
use crate::convert::{from_rapier_pose, to_rapier_pose};
use nbv_core::kinematics::{Joints, Robot};
use nbv_core::math::Pose;
use nbv_core::rig::TruthLabel;
use rapier3d::prelude::*;
use rapier3d_urdf::{UrdfLoaderOptions, UrdfRobot};
use std::collections::HashMap;
use std::path::Path;

/// Who owns a collider.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Owner {
    /// `statics[i]`.
    Static(usize),
    /// Robot collider `robot_colliders[i]`.
    Robot(usize),
}

/// One robot collider: its handle, link frame, body number and pose in the link frame.
#[derive(Debug, Clone)]
pub(crate) struct RobotCollider {
    pub(crate) handle: ColliderHandle,
    pub(crate) frame: usize,
    pub(crate) body: usize,
    pub(crate) local: Pose,
}

/// The twin's world: static bodies plus the robot at a configuration.
pub struct TwinWorld {
    robot: Robot,
    base: Pose,
    statics: Vec<StaticBody>,
    q: Joints,
    pub(crate) bodies: RigidBodySet,
    pub(crate) colliders: ColliderSet,
    pub(crate) broad_phase: BroadPhaseBvh,
    pub(crate) narrow_phase: NarrowPhase,
    params: IntegrationParameters,
    pub(crate) owners: HashMap<ColliderHandle, Owner>,
    pub(crate) robot_colliders: Vec<RobotCollider>,
}

impl TwinWorld {
    /// Builds the world: the robot from `urdf_path` (whose kinematic model is `robot`,
    /// mounted at `base` in the world), and the static bodies. The robot starts at the
    /// configuration `q`.
    pub fn new(
        robot: Robot,
        urdf_path: &Path,
        base: Pose,
        statics: Vec<StaticBody>,
        q: Joints,
    ) -> Result<Self, WorldError> {
        let options = UrdfLoaderOptions {
            make_roots_fixed: true,
            squeeze_empty_fixed_links: false,
            apply_imported_mass_props: false,
            ..UrdfLoaderOptions::default()
        };
        let (urdf_robot, model) =
            UrdfRobot::from_file(urdf_path, options, None).map_err(|e| WorldError::Urdf {
                path: urdf_path.to_path_buf(),
                detail: format!("{e:#}"),
            })?;

        let mut world = Self {
            robot,
            base,
            statics: Vec::new(),
            q,
            bodies: RigidBodySet::new(),
            colliders: ColliderSet::new(),
            broad_phase: BroadPhaseBvh::new(),
            narrow_phase: NarrowPhase::new(),
            params: IntegrationParameters::default(),
            owners: HashMap::new(),
            robot_colliders: Vec::new(),
        };

        for link in urdf_robot.links {
            let urdf_link = &model.links[link.urdf_link_index];
            let expected = urdf_link.collision.len();
            if link.colliders.len() != expected {
                return Err(WorldError::MissingCollider {
                    path: urdf_path.to_path_buf(),
                    link: urdf_link.name.clone(),
                    expected,
                    loaded: link.colliders.len(),
                });
            }
            if expected == 0 {
                continue;
            }
            let unknown = || WorldError::UnknownLink {
                path: urdf_path.to_path_buf(),
                link: urdf_link.name.clone(),
            };
            let frame = world
                .robot
                .frame_index(&urdf_link.name)
                .ok_or_else(unknown)?;
            let body = world
                .robot
                .body_of(&urdf_link.name)
                .map_err(|_| unknown())?;
            for c in link.colliders {
                // Not yet inserted: the collider's position is its pose in the link frame.
                let local = from_rapier_pose(c.collider.position());
                let handle = world.colliders.insert(c.collider);
                world
                    .owners
                    .insert(handle, Owner::Robot(world.robot_colliders.len()));
                world.robot_colliders.push(RobotCollider {
                    handle,
                    frame,
                    body,
                    local,
                });
            }
        }

        for body in statics {
            let collider = match &body.shape {
                StaticShape::Cuboid { half_extents, pose } => {
                    let [x, y, z] = half_extents.map(|h| h as f32);
                    ColliderBuilder::cuboid(x, y, z)
                        .position(to_rapier_pose(pose))
                        .build()
                }
                StaticShape::Mesh(mesh) => {
                    let vertices = mesh
                        .vertices
                        .iter()
                        .map(crate::convert::to_rapier_point)
                        .collect();
                    ColliderBuilder::trimesh_with_flags(
                        vertices,
                        mesh.triangles.clone(),
                        TriMeshFlags::FIX_INTERNAL_EDGES | TriMeshFlags::ORIENTED,
                    )
                    .map_err(|e| WorldError::Mesh {
                        name: body.name.clone(),
                        detail: e.to_string(),
                    })?
                    .build()
                }
            };
            let handle = world.colliders.insert(collider);
            world
                .owners
                .insert(handle, Owner::Static(world.statics.len()));
            world.statics.push(body);
            let aabb = world.colliders[handle].compute_aabb();
            world.broad_phase.set_aabb(&world.params, handle, aabb);
        }
        world.set_configuration(q);
        Ok(world)
    }

    /// The kinematic model of the robot.
    pub fn robot(&self) -> &Robot {
        &self.robot
    }

    /// Pose of the robot base in the world.
    pub fn base(&self) -> &Pose {
        &self.base
    }

    /// The static bodies, in insertion order.
    pub fn statics(&self) -> &[StaticBody] {
        &self.statics
    }

    /// The robot's current configuration.
    pub fn configuration(&self) -> Joints {
        self.q
    }

    /// World pose of a robot frame at the current configuration.
    pub fn frame_pose(&self, frame: &str) -> Option<Pose> {
        self.robot.fk(&self.q, frame).ok().map(|p| self.base * p)
    }

    /// Moves the robot to `q` (no limit check: that is the arm's business).
    pub fn set_configuration(&mut self, q: Joints) {
        self.q = q;
        let poses = self.robot.link_poses(&q);
        for rc in &self.robot_colliders {
            let world = self.base * poses[rc.frame] * rc.local;
            let collider = &mut self.colliders[rc.handle];
            collider.set_position(to_rapier_pose(&world));
            let aabb = collider.compute_aabb();
            self.broad_phase.set_aabb(&self.params, rc.handle, aabb);
        }
    }

    /// A ray caster over the world as it is now (robot included). Cheap to build; build
    /// one per thread.
    pub fn ray_caster(&self) -> RayCaster<'_> {
        RayCaster::new(self)
    }

    /// Every contact of the robot at its current configuration: with static bodies, and
    /// between non-adjacent links. Sorted by link then by what is touched.
    pub fn contacts(&self) -> Vec<Contact> {
        self.contacts_limited(usize::MAX)
    }

    /// Whether the robot touches anything at its current configuration.
    pub fn in_collision(&self) -> bool {
        !self.contacts_limited(1).is_empty()
    }

    /// Moves to `q` and reports its contacts.
    pub fn contacts_at(&mut self, q: Joints) -> Vec<Contact> {
        self.set_configuration(q);
        self.contacts()
    }

    fn link_name(&self, rc: &RobotCollider) -> String {
        self.robot.frame_names()[rc.frame].clone()
    }

    fn contacts_limited(&self, limit: usize) -> Vec<Contact> {
        let mut out = Vec::new();
        let statics_only =
            |h: ColliderHandle, _: &Collider| matches!(self.owners.get(&h), Some(Owner::Static(_)));
        let filter = QueryFilter::default().predicate(&statics_only);
        let qp = self.broad_phase.as_query_pipeline(
            self.narrow_phase.query_dispatcher(),
            &self.bodies,
            &self.colliders,
            filter,
        );
        let dispatcher = self.narrow_phase.query_dispatcher();
        for (i, rc) in self.robot_colliders.iter().enumerate() {
            let co = &self.colliders[rc.handle];
            for (h, _) in qp.intersect_shape(*co.position(), co.shape()) {
                if let Some(Owner::Static(s)) = self.owners.get(&h) {
                    let body = &self.statics[*s];
                    out.push(Contact {
                        link: self.link_name(rc),
                        with: Contacted::Static {
                            name: body.name.clone(),
                            label: body.label,
                        },
                    });
                }
            }
            for other in &self.robot_colliders[i + 1..] {
                if rc.body.abs_diff(other.body) <= 1 {
                    continue;
                }
                let co2 = &self.colliders[other.handle];
                let pos12 = co.position().inv_mul(co2.position());
                if dispatcher
                    .intersection_test(&pos12, co.shape(), co2.shape())
                    .is_ok_and(|hit| hit.intersecting)
                {
                    out.push(Contact {
                        link: self.link_name(rc),
                        with: Contacted::Link(self.link_name(other)),
                    });
                }
            }
            if out.len() >= limit {
                break;
            }
        }
        out.sort_by(|a, b| (&a.link, a.with.to_string()).cmp(&(&b.link, b.with.to_string())));
        out.dedup();
        out
    }

    /// World-frame bounding spheres `(body, centre, radius)` of the robot's colliders at
    /// the current configuration; `body` is the collider's [`Robot::body_of`] number.
    pub fn robot_bounding_spheres(&self) -> Vec<(usize, nalgebra::Point3<f64>, f64)> {
        self.robot_colliders
            .iter()
            .map(|rc| {
                let co = &self.colliders[rc.handle];
                let s = co.shape().compute_bounding_sphere(co.position());
                let c = crate::convert::from_rapier_vector(s.center);
                (rc.body, nalgebra::Point3::from(c), f64::from(s.radius))
            })
            .collect()
    }

    /// The label a collider reports when hit by a ray.
    pub(crate) fn label_of(&self, h: ColliderHandle) -> Option<(TruthLabel, usize)> {
        match self.owners.get(&h)? {
            Owner::Static(s) => Some((self.statics[*s].label, *s)),
            Owner::Robot(r) => Some((TruthLabel::Robot, self.robot_colliders[*r].frame)),
        }
    }
}
