//! Plan and execute (Algorithm 1): a collision-free path to a viewpoint's goals, dropping
//! the unknown voxels the arm itself stands in; the inverse-kinematics goals of a camera
//! pose over its rolls; and the retreat along the paths executed since phase 1.

use crate::kinematics::{Joints, Robot};
use crate::math::Pose;
use crate::nbv::view_pose_rolled;
use crate::planning::{MotionPlanner, PlannedPath, PlanningError};
use crate::rig::JointPath;

/// Plans from `start` to any of `goals`; when the start touches only map voxels (unknown
/// space around the arm that no ray cleared), those voxels are dropped from the planner's
/// world and it plans again.
pub fn plan_clearing_start(
    planner: &mut MotionPlanner,
    start: &Joints,
    goals: &[Joints],
    seed: u64,
) -> Result<PlannedPath, PlanningError> {
    match planner.plan(start, goals, seed) {
        Err(PlanningError::StartInCollision(c)) if c.is_voxel() => {
            planner.clear_way(std::slice::from_ref(start));
            planner.plan(start, goals, seed)
        }
        other => other,
    }
}

/// The joint goals that put `frame` at `target`, over `rolls` rolls about the optical
/// axis (at least one), those `free` accepts.
pub fn goals_at(
    robot: &Robot,
    frame: &str,
    target: &Pose,
    rolls: usize,
    free: &dyn Fn(&Joints) -> bool,
) -> Vec<Joints> {
    let rolls = rolls.max(1);
    (0..rolls)
        .flat_map(|r| {
            let pose = view_pose_rolled(target, std::f64::consts::TAU * r as f64 / rolls as f64);
            robot.ik(frame, &pose).unwrap_or_default()
        })
        .map(|s| s.joints)
        .filter(|q| free(q))
        .collect()
}

/// The executed paths of `trail` backwards, from `now` (the arm's configuration) to where
/// the first of them started.
pub(super) fn retrace(trail: &[JointPath], now: Joints) -> JointPath {
    let mut waypoints = vec![now];
    for path in trail.iter().rev() {
        waypoints.extend(path.waypoints.iter().rev().copied());
    }
    JointPath {
        waypoints,
        speed_fraction: trail.last().map_or(1.0, |p| p.speed_fraction),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn q(a: f64) -> Joints {
        Joints::from([a, 0.0, -1.5, 0.0, 1.5, 0.0])
    }

    #[test]
    fn retrace_goes_back_through_every_executed_waypoint_to_the_first_start() {
        let trail = vec![
            JointPath {
                waypoints: vec![q(0.0), q(0.1), q(0.2)],
                speed_fraction: 0.3,
            },
            JointPath {
                waypoints: vec![q(0.2), q(0.5)],
                speed_fraction: 0.3,
            },
        ];
        // The arm stopped a hair off the last waypoint.
        let back = retrace(&trail, q(0.501));
        let firsts: Vec<f64> = back.waypoints.iter().map(|w| w[0]).collect();
        assert_eq!(firsts, vec![0.501, 0.5, 0.2, 0.2, 0.1, 0.0]);
        assert_eq!(back.speed_fraction, 0.3);
    }
}
