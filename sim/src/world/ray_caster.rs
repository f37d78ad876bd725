//! [`RayCaster`]: first-hit ray queries against the twin world through Rapier's query
//! pipeline. The query pipeline is a borrowed view and not `Sync`: build one caster per
//! thread (e.g. with rayon's `map_init`).

use super::TwinWorld;
use super::twin_world::Owner;
use crate::convert::{from_rapier_vector, to_rapier_point, to_rapier_vector};
use nalgebra::{Point3, Vector3};
use nbv_core::rig::TruthLabel;
use rapier3d::prelude::*;

/// The first thing a ray hits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RayHit {
    /// Distance from the ray origin along the unit direction, metres.
    pub distance: f64,
    /// The hit point in the world frame.
    pub point: Point3<f64>,
    /// Unit surface normal at the hit, facing the ray.
    pub normal: Vector3<f64>,
    /// What was hit.
    pub label: TruthLabel,
}

/// Casts rays through a [`TwinWorld`].
pub struct RayCaster<'a> {
    world: &'a TwinWorld,
}

impl<'a> RayCaster<'a> {
    pub(crate) fn new(world: &'a TwinWorld) -> Self {
        Self { world }
    }

    /// The first hit of the ray from `origin` along the unit vector `dir` within
    /// `max_distance`, ignoring the colliders of the robot frame `ignore_frame` (a sensor's
    /// own housing, whose window the ray starts on).
    pub fn cast(
        &self,
        origin: &Point3<f64>,
        dir: &Vector3<f64>,
        max_distance: f64,
        ignore_frame: Option<usize>,
    ) -> Option<RayHit> {
        let w = self.world;
        let keep = |h: ColliderHandle, _: &Collider| match w.owners.get(&h) {
            Some(Owner::Robot(r)) => Some(w.robot_colliders[*r].frame) != ignore_frame,
            Some(Owner::Static(_)) => true,
            None => false,
        };
        let qp = w.broad_phase.as_query_pipeline(
            w.narrow_phase.query_dispatcher(),
            &w.bodies,
            &w.colliders,
            QueryFilter::default().predicate(&keep),
        );
        let ray = Ray::new(to_rapier_point(origin), to_rapier_vector(dir));
        let (h, hit) = qp.cast_ray_and_get_normal(&ray, max_distance as f32, true)?;
        let (label, _) = w.label_of(h)?;
        let distance = f64::from(hit.time_of_impact);
        let mut normal = from_rapier_vector(hit.normal);
        if normal.dot(dir) > 0.0 {
            normal = -normal;
        }
        Some(RayHit {
            distance,
            point: origin + dir * distance,
            normal,
            label,
        })
    }
}
