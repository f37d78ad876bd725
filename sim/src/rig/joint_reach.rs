//! [`JointReach`]: how far a joint motion can move any point of the robot's colliders, so
//! the arm checks a path finely enough that nothing moves more than a set distance between
//! two collision checks.
//!
//! For joint `j`, `R_j` bounds the distance from a point on joint `j`'s axis to any point
//! of the colliders it carries: along the chain, `R_j = max_{b ≥ j} (Σ_{k=j}^{b-1} |o_{k+1}
//! − o_k| + ρ_b)`, with `o_k` a point on joint `k`'s axis and `ρ_b` the farthest extent of
//! body `b`'s collider bounding spheres from `o_b` — all distances within rigid bodies, so
//! the bound holds in every configuration. A joint-space step `Δq` then moves no collider
//! point by more than `Σ_j |Δq_j| · R_j`.

use crate::world::TwinWorld;
use nbv_core::kinematics::{DOF, Joints};

/// Per-joint reach bounds (m).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct JointReach(pub(crate) [f64; DOF]);

/// Used when no frame on a joint's axis can be found (a URDF this model does not expect):
/// larger than any arm the twin handles, so checks are only finer.
const FALLBACK_REACH: f64 = 3.0;

impl JointReach {
    /// The bounds of the robot in `world` (measured at its current configuration).
    pub(crate) fn of(world: &TwinWorld) -> Self {
        let robot = world.robot();
        let q = world.configuration();
        let poses = robot.link_poses(&q);
        let bodies: Vec<Option<usize>> = robot
            .frame_names()
            .iter()
            .map(|n| robot.body_of(n).ok())
            .collect();
        // A point on each joint's axis: a frame carried by the joint that stays put when
        // only that joint turns (the joint's child link frame).
        let axis_point = |j: usize| {
            let mut dq = Joints::zeros();
            dq[j] = 0.5;
            let turned = robot.link_poses(&(q + dq));
            (0..poses.len())
                .find(|&f| {
                    bodies[f] == Some(j + 1)
                        && (poses[f].translation.vector - turned[f].translation.vector).norm()
                            < 1e-9
                })
                .map(|f| nalgebra::Point3::from(poses[f].translation.vector))
        };
        let Some(origins) = (0..DOF).map(axis_point).collect::<Option<Vec<_>>>() else {
            return Self([FALLBACK_REACH; DOF]);
        };
        let base_inv = world.base().inverse();
        let mut rho = [f64::NEG_INFINITY; DOF];
        for (body, centre, radius) in world.robot_bounding_spheres() {
            if (1..=DOF).contains(&body) {
                let c = base_inv * centre;
                rho[body - 1] = rho[body - 1].max((c - origins[body - 1]).norm() + radius);
            }
        }
        let mut reach = [0.0; DOF];
        for (j, r) in reach.iter_mut().enumerate() {
            let mut chain = 0.0;
            for b in j..DOF {
                if b > j {
                    chain += (origins[b] - origins[b - 1]).norm();
                }
                *r = f64::max(*r, chain + rho[b]);
            }
        }
        Self(reach)
    }

    /// Bound on how far any collider point moves along the straight joint-space step
    /// `dq` (m).
    pub(crate) fn displacement(&self, dq: &Joints) -> f64 {
        dq.iter().zip(self.0).map(|(d, r)| d.abs() * r).sum()
    }
}
