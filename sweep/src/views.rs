//! What `nbv views` lists: phase 1 on a scene in the twin, then each object's sorted
//! next-best-view candidates from the pipeline's own candidate step (Algorithm 2), with
//! what the robot can do about them: whether a collision-free IK solution exists, whether
//! the planner reaches it from where phase 1 left the arm, and whether the planned path,
//! executed in the twin, touches anything in truth.

use crate::error::{Context, Result};
use crate::matching::true_object_of;
use nbv_core::math::pose_to_xyz_rpy;
use nbv_core::nbv::{NextBestView, VisitedViews};
use nbv_core::pipeline::{
    ExplorationMap, ExploreMode, NoObserver, ObjectRegion, ViewCandidates, plan_clearing_start,
    view_candidates, viewing_centre,
};
use nbv_core::rig::{Arm, DepthCamera, RigError};
use nbv_sim::rig::SimRig;
use serde::Serialize;

/// What [`list_views`] does beyond scoring.
#[derive(Debug, Clone, Default)]
pub struct ViewsOptions {
    /// Only this object (its name in the scene); every cluster when `None`.
    pub object: Option<String>,
    /// Plan a path to each reachable candidate.
    pub plan: bool,
    /// Execute each planned path in the twin (the arm is put back after each).
    pub check: bool,
}

/// One candidate viewpoint.
#[derive(Debug, Clone, Serialize)]
pub struct CandidateRow {
    /// Sensor pose: x, y, z (m), roll, pitch, yaw (degrees).
    pub pose: [f64; 6],
    /// Inclination and azimuth indices on the sphere.
    pub sample: [usize; 2],
    /// |O_v| unknown.
    pub unknown: usize,
    /// |O_v| occupied.
    pub occupied: usize,
    /// Eq. (4).
    pub score: f64,
    /// A collision-free IK solution exists.
    pub reachable: bool,
    /// The planner found a path (None: not planned).
    pub planned: Option<bool>,
    /// The executed path touched something in truth (None: not executed).
    pub collision: Option<bool>,
    /// Why planning failed, if it did.
    pub failure: Option<String>,
}

/// One object's list.
#[derive(Debug, Clone, Serialize)]
pub struct ObjectViews {
    /// The object's name in the scene (or `cluster-N`).
    pub name: String,
    /// The centre of its viewing sphere (m): the cluster's centroid at the object's middle height.
    pub centre: [f64; 3],
    /// Samples on the sphere.
    pub samples: usize,
    /// Samples without a collision-free IK solution at any roll (not listed).
    pub unreachable: usize,
    /// Rays cast per candidate.
    pub rays_per_view: usize,
    /// Candidates, best first.
    pub candidates: Vec<CandidateRow>,
}

/// Phase 1, then every (selected) object's candidates, planned and checked.
pub fn list_views(scene: &nbv_scenes::Scene, options: &ViewsOptions) -> Result<Vec<ObjectViews>> {
    let config = scene.explore_config(ExploreMode::Hybrid)?;
    let mut rig = SimRig::from_scene(scene).context("building the twin")?;
    let (phase, segmentation) = rig.phase_one(&config, &mut NoObserver)?;
    let (robot, _) = rig.robot_and_base();
    let mut map =
        ExplorationMap::after_phase_one(phase.grid.clone(), &phase.cloud, config.nbv.objective)
            .context("the map after phase 1")?;
    let regions = ObjectRegion::of_segmentation(&segmentation, config.object_margin);
    map.set_free_above(&regions, config.nbv.free_above_objects);
    let nbv = NextBestView::new(config.nbv, rig.camera.spec())?;
    let start = rig.arm.joints()?;
    let mut out = Vec::new();
    let mut query: u64 = 0;
    for (j, cluster) in segmentation.clusters.iter().enumerate() {
        let cloud = cluster.cloud(&segmentation.filtered);
        let name = true_object_of(&cloud, scene)
            .map_or(format!("cluster-{j}"), |i| scene.objects[i].name.clone());
        if options.object.as_ref().is_some_and(|n| n != &name) {
            continue;
        }
        // The pipeline's own candidate step, as for the object's first view.
        let region = regions[j];
        let centre = viewing_centre(&cloud, &[], &region).context("an empty cluster")?;
        let ViewCandidates { mut planner, list } = view_candidates(
            &robot,
            &config,
            &nbv,
            &map,
            Some(&start),
            &centre,
            &VisitedViews::default(),
            Some(nbv_core::pipeline::ObjectSurface {
                region: &region,
                sides: &nbv_core::nbv::SurfaceSides::of_cloud(map.reduced.geometry(), &cloud),
                missed: &nbv_core::nbv::MissedVoxels::default(),
            }),
        )?;
        let mut rows = Vec::new();
        for c in &list.candidates {
            let goals: Vec<_> = c.viewpoint.solutions.iter().map(|s| s.joints).collect();
            let mut row = CandidateRow {
                pose: pose_in_degrees(&c.viewpoint.pose),
                sample: [c.viewpoint.sample.i_theta, c.viewpoint.sample.i_phi],
                unknown: c.visible.unknown.len(),
                occupied: c.visible.occupied.len(),
                score: c.score,
                reachable: !goals.is_empty(),
                planned: None,
                collision: None,
                failure: None,
            };
            if row.reachable && options.plan {
                query += 1;
                match plan_clearing_start(&mut planner, &start, &goals, config.seed ^ query) {
                    Ok(p) => {
                        row.planned = Some(true);
                        if options.check {
                            row.collision = Some(check_in_truth(&mut rig, &p.path, &start)?);
                        }
                    }
                    Err(e) => {
                        row.planned = Some(false);
                        row.failure = Some(e.to_string());
                    }
                }
            }
            rows.push(row);
        }
        out.push(ObjectViews {
            name,
            centre: [centre.x, centre.y, centre.z],
            samples: list.samples,
            unreachable: list.unreachable,
            rays_per_view: list.rays_per_view,
            candidates: rows,
        });
    }
    Ok(out)
}

/// A sensor pose as `nbv views` and `nbv oracle` print it: x, y, z (m), roll, pitch, yaw
/// (degrees).
pub(crate) fn pose_in_degrees(pose: &nbv_core::math::Pose) -> [f64; 6] {
    let (xyz, rpy) = pose_to_xyz_rpy(pose);
    let [r, p, y] = rpy.map(f64::to_degrees);
    [xyz[0], xyz[1], xyz[2], r, p, y]
}

/// Executes `path` in the twin and puts the arm back at `start`; whether it collided.
fn check_in_truth(
    rig: &mut SimRig,
    path: &nbv_core::rig::JointPath,
    start: &nbv_core::kinematics::Joints,
) -> Result<bool> {
    let collided = match rig.arm.execute(path) {
        Ok(_) => false,
        Err(RigError::Collision { .. }) => true,
        Err(e) => return Err(e).context("executing a planned path in the twin"),
    };
    rig.arm
        .teleport(*start)
        .context("putting the arm back after a check")?;
    Ok(collided)
}
