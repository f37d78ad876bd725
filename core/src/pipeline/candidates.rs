//! The candidate step of Algorithm 1 (Algorithm 2 around the object): the reduced map, a
//! planner over it, and the scored viewpoints around the object's viewing centre whose
//! goals are free of collision — what the object loop tries in order, and what `nbv views`
//! lists.

use super::{AcquiredView, ExplorationMap, ExploreConfig, ObjectRegion, PipelineError};
use crate::cloud::PointCloud;
use crate::kinematics::{IkSolution, Joints, Robot};
use crate::nbv::{NextBestView, ViewpointList, VisitedViews, apply_movement_cost};
use crate::planning::{CollisionWorld, MotionPlanner};
use nalgebra::Point3;

/// The viewpoints to try next, and the planner to reach them with.
pub struct ViewCandidates {
    /// A planner over the robot, the known obstacles and the reduced map.
    pub planner: MotionPlanner,
    /// The candidates, best first.
    pub list: ViewpointList,
}

/// Algorithm 2 around `centre` on `map`: the viewpoints not yet `visited`, scored by the
/// objective (eq. (4) on the reduced map by default; an information gain on the grid),
/// each with the inverse-kinematics solutions that are free of self-collision,
/// the known obstacles and the map (MoveIt's collision-aware IK: a viewpoint none of whose
/// solutions is free is unreachable, and the next roll about the optical axis is tried).
/// With a movement-cost weight and the arm's joints `start`, ranked by Isler's utility.
pub fn view_candidates(
    robot: &Robot,
    config: &ExploreConfig,
    nbv: &NextBestView,
    map: &ExplorationMap,
    start: Option<&Joints>,
    centre: &Point3<f64>,
    visited: &VisitedViews,
) -> Result<ViewCandidates, PipelineError> {
    let reduced = &map.reduced;
    let world = CollisionWorld::new(robot, &config.obstacles)?.with_reduced_map(reduced);
    let planner = MotionPlanner::new(world, config.planner)?;
    let usable = |s: &IkSolution| !planner.world().in_collision(&s.joints);
    let mut list =
        nbv.candidates_scored(robot, reduced, Some(&map.gains()), centre, visited, &usable)?;
    if let Some(start) = start
        && nbv.params.cost_weight > 0.0
    {
        apply_movement_cost(&mut list.candidates, start, nbv.params.cost_weight);
    }
    Ok(ViewCandidates { planner, list })
}

/// Where Algorithm 2 centres its sphere for an object: the centroid of everything seen of
/// it so far — its phase-1 `cluster` and its `views` — at the object's middle height when
/// it rests on a table (`region`). `None` when nothing was seen.
pub fn viewing_centre(
    cluster: &PointCloud,
    views: &[AcquiredView],
    region: &ObjectRegion,
) -> Option<Point3<f64>> {
    let mut all = PointCloud::from_points(cluster.points.clone());
    for v in views {
        all.extend(&PointCloud::from_points(v.cloud.points.clone()));
    }
    all.centroid().map(|c| region.viewing_centre(&c))
}
