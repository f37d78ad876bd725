//! The candidate step of Algorithm 1 (Algorithm 2 around the object): the reduced map, a
//! planner over it, and the scored viewpoints around the object's viewing centre whose
//! goals are free of collision — what the object loop tries in order, and what `nbv views`
//! lists.

use super::{AcquiredView, ExplorationMap, ExploreConfig, ObjectRegion, PipelineError};
use crate::cloud::PointCloud;
use crate::kinematics::{IkSolution, Joints, Robot};
use crate::math::Pose;
use crate::nbv::{
    Candidate, HullSurface, MissedVoxels, NextBestView, Objective, ScoreWeights, SurfaceSides,
    ViewpointList, VisitedViews, apply_movement_cost, sort_best_first,
};
use crate::occupancy::{GridGeometry, OccupancyGrid, ReducedMap, VoxelState};
use crate::planning::{CollisionWorld, MotionPlanner};
use nalgebra::Point3;

/// The viewpoints to try next, and the planner to reach them with.
pub struct ViewCandidates {
    /// A planner over the robot, the known obstacles and the reduced map.
    pub planner: MotionPlanner,
    /// The candidates, best first.
    pub list: ViewpointList,
    /// The area (m²) of the object's hull, when the hull scores the candidates.
    pub hull_area: Option<f64>,
}

/// Algorithm 2 around `centre` on `map`: the viewpoints not yet `visited`, scored by the
/// objective (eq. (4) on the reduced map by default; an information gain on the grid),
/// each with the inverse-kinematics solutions that are free of self-collision,
/// the known obstacles and the map (MoveIt's collision-aware IK: a viewpoint none of whose
/// solutions is free is unreachable, and the next roll about the optical axis is tried).
/// With [`NbvParams::object_surface`] and the object's `surface` so far, eq. (4) counts
/// the object's surface ([`object_surface_score`]). With a movement-cost weight and the
/// arm's joints `start`, ranked by Isler's utility.
///
/// [`NbvParams::object_surface`]: crate::nbv::NbvParams::object_surface
#[allow(clippy::too_many_arguments)]
pub fn view_candidates(
    robot: &Robot,
    config: &ExploreConfig,
    nbv: &NextBestView,
    map: &ExplorationMap,
    start: Option<&Joints>,
    centre: &Point3<f64>,
    visited: &VisitedViews,
    surface: Option<ObjectSurface<'_>>,
) -> Result<ViewCandidates, PipelineError> {
    let reduced = &map.reduced;
    let mut world = CollisionWorld::new(robot, &config.obstacles)?.with_reduced_map(reduced);
    world.ignore_voxels(&map.unknown_above_objects());
    let surface =
        surface.filter(|_| nbv.params.object_surface && nbv.params.objective == Objective::Paper);
    // Eq. (4) over the object's surface sees the map with the unknown space around the
    // object taken as free; the planner keeps the map as it is.
    let seen_map = match &surface {
        Some(s) => Some(object_view_map(&map.grid, s.region)?),
        None => None,
    };
    let scored_on = seen_map.as_ref().unwrap_or(reduced);
    let planner = MotionPlanner::new(world, config.planner)?;
    let usable = |s: &IkSolution| !planner.world().in_collision(&s.joints);
    // The hull's mode for this round; after a stall in it the candidates come from the
    // sphere at half its steps: what is left is a strip or a patch the coarse sphere's
    // views see only past the grazing cut.
    let hull_mode = surface.as_ref().is_some_and(|s| s.hull);
    let refined;
    let nbv = if hull_mode && surface.as_ref().is_some_and(|s| s.stalled) {
        let mut finer = nbv.clone();
        finer.params.sphere = nbv.params.sphere.refined();
        refined = finer;
        &refined
    } else {
        nbv
    };
    let mut list = nbv.candidates_scored(
        robot,
        scored_on,
        Some(&map.gains()),
        centre,
        visited,
        &usable,
    )?;
    let mut hull_area = None;
    if let Some(surface) = surface {
        let geometry = reduced.geometry();
        let region = surface.region;
        let flat = region
            .table
            .is_some_and(|t| region.top - t < HullSurface::FLAT_HEIGHT);
        let hull = (hull_mode && !flat)
            .then(|| HullSurface::new(surface.points, region.table, &map.grid))
            .flatten()
            .map(|h| {
                let poses: Vec<Pose> = surface.views.iter().map(|v| v.sensor_pose).collect();
                h.without_seen_through(|q| surface.views.iter().any(|v| v.free_space.contains(q)))
                    .without_missed(&poses, &nbv.camera, scored_on)
            });
        hull_area = hull.as_ref().map(HullSurface::total_area);
        let own = |v: usize| in_region(geometry, surface.region, v);
        for c in &mut list.candidates {
            c.score = match &hull {
                Some(h) => h.seen_from(&c.viewpoint.pose, &nbv.camera, scored_on, &own),
                None => object_surface_score(c, &nbv.params.weights, geometry, &surface),
            };
            c.utility = c.score;
        }
        sort_best_first(&mut list.candidates);
    }
    if let Some(start) = start
        && nbv.params.cost_weight > 0.0
    {
        apply_movement_cost(&mut list.candidates, start, nbv.params.cost_weight);
    }
    Ok(ViewCandidates {
        planner,
        list,
        hull_area,
    })
}

/// What is known of the surface of the object being explored: its region, the sides its
/// occupied voxels were seen from, the unknown voxels taken views missed.
#[derive(Debug, Clone, Copy)]
pub struct ObjectSurface<'a> {
    /// Where the object is.
    pub region: &'a ObjectRegion,
    /// The sides seen so far.
    pub sides: &'a SurfaceSides,
    /// The unknown voxels missed.
    pub missed: &'a MissedVoxels,
    /// Its points so far (world frame): the phase-1 cluster and the views.
    pub points: &'a [Point3<f64>],
    /// Its views so far: where each saw empty space and where it stood (the sensor's
    /// reported pose), which the hull score reads.
    pub views: &'a [AcquiredView],
    /// A view of the object added less than the new-surface share: by
    /// [`NbvParams::hull_score`](crate::nbv::NbvParams::hull_score), the unseen hull
    /// ([`HullSurface`]) scores the candidates, and in a hull mode they come from the
    /// sphere at half its steps ([`ViewSphere::refined`]).
    ///
    /// [`ViewSphere::refined`]: crate::nbv::ViewSphere::refined
    pub stalled: bool,
    /// The unseen hull scores this round's candidates (by
    /// [`NbvParams::hull_score`](crate::nbv::NbvParams::hull_score) and whether the hull
    /// handed the object to eq. (4) already).
    pub hull: bool,
}

/// Eq. (4) over the object's surface: of the candidate's O_v, only the voxels in the
/// object's region (grown by one voxel); an unknown voxel counts α_u unless a taken view
/// missed it, an occupied voxel α_u when no view has seen it from the candidate's side and
/// α_o otherwise. O_v itself (the information gain's domain) is left whole.
pub fn object_surface_score(
    c: &Candidate,
    weights: &ScoreWeights,
    geometry: &GridGeometry,
    surface: &ObjectSurface<'_>,
) -> f64 {
    let from = nalgebra::Point3::from(c.viewpoint.pose.translation.vector);
    let mine = |v: &&usize| in_region(geometry, surface.region, **v);
    let unknown = c
        .visible
        .unknown
        .iter()
        .filter(mine)
        .filter(|&&v| !surface.missed.ignored(v))
        .count() as f64;
    let (mut new, mut old) = (0.0, 0.0);
    for &v in c.visible.occupied.iter().filter(mine) {
        if surface.sides.unseen_from(geometry, v, &from) {
            new += 1.0;
        } else {
            old += 1.0;
        }
    }
    weights.unknown * (unknown + new) + weights.occupied * old
}

/// The reduced map of `grid` with every unknown voxel outside `region` (grown by one
/// voxel) taken as free: the object lies in its region, so the unknown space around it —
/// the laser's shadow behind it, the gaps beside it — hides no surface of it, and a view
/// from behind sees through that space to the object's unknown back instead of stopping at
/// the shadow's edge. Occupied voxels (the table, the neighbours) still block.
fn object_view_map(
    grid: &OccupancyGrid,
    region: &ObjectRegion,
) -> Result<ReducedMap, PipelineError> {
    let geometry = grid.geometry();
    let free = grid.params().clamp_min;
    let log_odds: Vec<f32> = grid
        .log_odds()
        .iter()
        .enumerate()
        .map(|(v, &o)| {
            let unknown = grid.state_linear(v) == Some(VoxelState::Unknown);
            if unknown && !in_region(geometry, region, v) {
                free
            } else {
                o
            }
        })
        .collect();
    let seen = OccupancyGrid::from_log_odds(*geometry, *grid.params(), log_odds)?;
    Ok(ReducedMap::from_grid(&seen))
}

/// Whether voxel `v`'s centre lies in `region` grown by one voxel across and above (its
/// floor stays: the table's voxels are out).
fn in_region(geometry: &GridGeometry, region: &ObjectRegion, v: usize) -> bool {
    let Some(idx) = geometry.unlinear(v) else {
        return false;
    };
    let c = geometry.center(idx);
    let g = geometry.resolution();
    c.x >= region.min.x - g
        && c.x <= region.max.x + g
        && c.y >= region.min.y - g
        && c.y <= region.max.y + g
        && c.z >= region.min.z
        && c.z <= region.max.z + g
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
