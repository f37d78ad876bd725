//! An independent collision checker for the tests: built directly from the URDF
//! primitives, the analytic scene's boxes and the reduced map's voxel lists, with parry's
//! own composite-shape broad phase (one `Compound` of every obstacle voxel) — no bitset, no
//! bounding-sphere pruning, no code shared with `nbv_core::planning`.
#![allow(dead_code)]

use nalgebra::Point3;
use nbv_core::kinematics::{Joints, Robot, Shape};
use nbv_core::math::Pose;
use nbv_core::occupancy::ReducedMap;
use parry3d::glamx::{Quat, Vec3};
use parry3d::math::Pose as PPose;
use parry3d::query::intersection_test;
use parry3d::shape::SharedShape;

use super::scene::Solid;

fn ppose(p: &Pose) -> PPose {
    let t = p.translation.vector;
    let q = p.rotation.quaternion();
    PPose::from_parts(
        Vec3::new(t.x as f32, t.y as f32, t.z as f32),
        Quat::from_xyzw(q.i as f32, q.j as f32, q.k as f32, q.w as f32),
    )
}

/// Robot links, obstacles and voxels as parry shapes.
pub struct BruteForce {
    robot: Robot,
    /// (frame index, body, shape pose in the link, shape, link name).
    links: Vec<(usize, usize, PPose, SharedShape)>,
    obstacles: Vec<(PPose, SharedShape)>,
    voxels: Option<SharedShape>,
}

impl BruteForce {
    /// From the robot's URDF primitives, boxes of the scene and (optionally) M̄.
    pub fn new(robot: &Robot, boxes: &[Solid], map: Option<&ReducedMap>) -> Self {
        let links = robot
            .collision_geometry()
            .iter()
            .map(|g| {
                let local = ppose(&g.origin);
                let (shape, fix) = match g.shape {
                    Shape::Box { size } => (
                        SharedShape::cuboid(
                            size[0] as f32 / 2.0,
                            size[1] as f32 / 2.0,
                            size[2] as f32 / 2.0,
                        ),
                        PPose::IDENTITY,
                    ),
                    // parry's cylinder axis is y: turn it onto the URDF's z.
                    Shape::Cylinder { radius, length } => (
                        SharedShape::cylinder(length as f32 / 2.0, radius as f32),
                        PPose::from_rotation(Quat::from_rotation_x(std::f32::consts::FRAC_PI_2)),
                    ),
                    ref other => panic!("unexpected shape {other:?}"),
                };
                (g.frame, robot.body_of(&g.link).unwrap(), local * fix, shape)
            })
            .collect();
        let obstacles = boxes
            .iter()
            .map(|s| match *s {
                Solid::Box(lo, hi) => (
                    PPose::from_translation(Vec3::new(
                        ((lo[0] + hi[0]) / 2.0) as f32,
                        ((lo[1] + hi[1]) / 2.0) as f32,
                        ((lo[2] + hi[2]) / 2.0) as f32,
                    )),
                    SharedShape::cuboid(
                        ((hi[0] - lo[0]) / 2.0) as f32,
                        ((hi[1] - lo[1]) / 2.0) as f32,
                        ((hi[2] - lo[2]) / 2.0) as f32,
                    ),
                ),
                Solid::Cylinder(..) => panic!("boxes only"),
            })
            .collect();
        let voxels = map.filter(|m| !m.is_empty()).map(|m| {
            let g = m.geometry();
            let h = (g.resolution() / 2.0) as f32;
            let parts = m
                .iter()
                .map(|(l, _)| {
                    let c: Point3<f64> = g.center(g.unlinear(l).unwrap());
                    (
                        PPose::from_translation(Vec3::new(c.x as f32, c.y as f32, c.z as f32)),
                        SharedShape::cuboid(h, h, h),
                    )
                })
                .collect();
            SharedShape::compound(parts)
        });
        Self {
            robot: robot.clone(),
            links,
            obstacles,
            voxels,
        }
    }

    /// Whether `q` is in collision (self pairs on bodies ≥ 2 apart, obstacles, voxels).
    pub fn collides(&self, q: &Joints) -> bool {
        let frames = self.robot.link_poses(q);
        let posed: Vec<PPose> = self
            .links
            .iter()
            .map(|(f, _, local, _)| ppose(&frames[*f]) * *local)
            .collect();
        let hit = |p1: &PPose, s1: &SharedShape, p2: &PPose, s2: &SharedShape| {
            intersection_test(p1, s1.as_ref(), p2, s2.as_ref())
                .unwrap()
                .intersecting
        };
        for i in 0..self.links.len() {
            for j in i + 1..self.links.len() {
                if self.links[i].1.abs_diff(self.links[j].1) >= 2
                    && hit(&posed[i], &self.links[i].3, &posed[j], &self.links[j].3)
                {
                    return true;
                }
            }
        }
        for (p, (_, _, _, s)) in posed.iter().zip(&self.links) {
            if self.obstacles.iter().any(|(op, os)| hit(p, s, op, os)) {
                return true;
            }
            if let Some(v) = &self.voxels
                && hit(p, s, &PPose::IDENTITY, v)
            {
                return true;
            }
        }
        false
    }

    /// Re-checks every segment of a joint path at a fine step: no point of the robot moves
    /// more than `resolution` metres between checks, using a crude lever arm of 2.5 m for
    /// every joint (more than the arm's reach plus its end effector). Returns the first
    /// configuration in collision.
    pub fn first_collision_on_path(&self, path: &[Joints], resolution: f64) -> Option<Joints> {
        if let Some(q) = path.first()
            && self.collides(q)
        {
            return Some(*q);
        }
        for w in path.windows(2) {
            let d = w[1] - w[0];
            let l1: f64 = d.iter().map(|v| v.abs()).sum();
            let n = ((2.5 * l1) / resolution).ceil().max(1.0) as usize;
            for i in 1..=n {
                let q = w[0] + d * (i as f64 / n as f64);
                if self.collides(&q) {
                    return Some(q);
                }
            }
        }
        None
    }
}
