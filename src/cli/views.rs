//! `nbv views`: phase 1 on a scene in the twin, then each object's sorted next-best-view
//! candidates (Algorithm 2) with what the robot can do about them: whether a collision-free
//! IK solution exists, whether the planner reaches it from where phase 1 left the arm, and
//! whether the planned path, executed in the twin, touches anything in truth.

use super::explore_report::true_object_of;
use anyhow::{Context, Result, bail};
use clap::Args;
use nbv_core::math::pose_to_xyz_rpy;
use nbv_core::nbv::{NextBestView, VisitedViews};
use nbv_core::occupancy::ReducedMap;
use nbv_core::pipeline::{
    ExploreMode, NoObserver, ObjectRegion, ViewCandidates, plan_clearing_start, view_candidates,
    viewing_centre,
};
use nbv_core::rig::{Arm, DepthCamera, RigError};
use nbv_sim::rig::SimRig;
use serde::Serialize;

/// Arguments of `nbv views`.
#[derive(Debug, Args)]
#[command(after_help = "\
For every candidate, best first: the sensor pose (x y z in m, roll pitch yaw in degrees),
the predicted unknown and occupied voxels |O_v|, the score of eq. (4), `reachable` (an IK
solution free of self-collision, the known obstacles and the reduced map, at the first of
the scene's `[nbv] rolls` about the optical axis that has one; samples without are counted,
not listed), `planned` (the
RRT-Connect planner found a path from the arm's configuration after phase 1) and, with
--check (default), `collision`: the path executed in the twin touched something in truth
(the arm is put back after each check).")]
pub struct ViewsArgs {
    /// Scene file, or the name of a built-in scene (paper-env1, paper-env2).
    #[arg(long)]
    pub scene: String,
    /// Only this object (its name in the scene); by default every cluster.
    #[arg(long)]
    pub object: Option<String>,
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Do not plan (reachability and scores only).
    #[arg(long)]
    pub no_plan: bool,
    /// Do not execute the planned paths in the twin.
    #[arg(long)]
    pub no_check: bool,
    /// Overrides the scene's seed.
    #[arg(long)]
    pub seed: Option<u64>,
    /// Sets a scene parameter for this run: a dotted key of the scene file and a TOML
    /// value, e.g. `--set nbv.radius=0.45 --set nbv.gain_threshold=2.5` (repeatable; the
    /// keys a sweep's `[params]` takes).
    #[arg(long = "set", value_name = "KEY=VALUE", value_parser = super::scene::parse_override)]
    pub set: Vec<(String, toml::Value)>,
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

/// Runs `nbv views`.
pub fn run(args: ViewsArgs) -> Result<()> {
    let scene = super::scene::load_for_run(&args.scene, &args.set, args.seed)?;
    if let Some(name) = &args.object
        && !scene.objects.iter().any(|o| &o.name == name)
    {
        let names: Vec<_> = scene.objects.iter().map(|o| o.name.as_str()).collect();
        bail!(
            "{}: no object named `{name}` (objects: {})",
            args.scene,
            names.join(", ")
        );
    }
    let objects = list_views(&scene, &args)?;
    if args.json {
        println!("{}", serde_json::to_string_pretty(&objects)?);
    } else {
        for o in &objects {
            print!("{}", table(o));
        }
    }
    Ok(())
}

/// Phase 1, then every (selected) object's candidates, planned and checked.
fn list_views(scene: &nbv_scenes::Scene, args: &ViewsArgs) -> Result<Vec<ObjectViews>> {
    let config = scene.explore_config(ExploreMode::Hybrid)?;
    let mut rig = SimRig::from_scene(scene).context("building the twin")?;
    let (phase, segmentation) = rig.phase_one(&config, &mut NoObserver)?;
    let (robot, _) = rig.robot_and_base();
    let reduced = ReducedMap::from_grid(&phase.grid);
    let nbv = NextBestView::new(config.nbv, rig.camera.spec())?;
    let start = rig.arm.joints()?;
    let mut out = Vec::new();
    let mut query: u64 = 0;
    for (j, cluster) in segmentation.clusters.iter().enumerate() {
        let cloud = cluster.cloud(&segmentation.filtered);
        let name = true_object_of(&cloud, scene)
            .map_or(format!("cluster-{j}"), |i| scene.objects[i].name.clone());
        if args.object.as_ref().is_some_and(|n| n != &name) {
            continue;
        }
        // The pipeline's own candidate step, as for the object's first view.
        let region =
            ObjectRegion::of_cluster(cluster, segmentation.table.as_ref(), config.object_margin);
        let centre = viewing_centre(&cloud, &[], &region).context("an empty cluster")?;
        let ViewCandidates { mut planner, list } = view_candidates(
            &robot,
            &config,
            &nbv,
            &reduced,
            &centre,
            &VisitedViews::default(),
        )?;
        let mut rows = Vec::new();
        for c in &list.candidates {
            let goals: Vec<_> = c.viewpoint.solutions.iter().map(|s| s.joints).collect();
            let (xyz, rpy) = pose_to_xyz_rpy(&c.viewpoint.pose);
            let mut row = CandidateRow {
                pose: [
                    xyz[0],
                    xyz[1],
                    xyz[2],
                    rpy[0].to_degrees(),
                    rpy[1].to_degrees(),
                    rpy[2].to_degrees(),
                ],
                sample: [c.viewpoint.sample.i_theta, c.viewpoint.sample.i_phi],
                unknown: c.visible.unknown.len(),
                occupied: c.visible.occupied.len(),
                score: c.score,
                reachable: !goals.is_empty(),
                planned: None,
                collision: None,
                failure: None,
            };
            if row.reachable && !args.no_plan {
                query += 1;
                match plan_clearing_start(&mut planner, &start, &goals, config.seed ^ query) {
                    Ok(p) => {
                        row.planned = Some(true);
                        if !args.no_check {
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

fn table(o: &ObjectViews) -> String {
    let mut s = format!(
        "{}: sphere centre ({:.3}, {:.3}, {:.3}); {} samples, {} unreachable, {} candidates, {} rays each\n",
        o.name,
        o.centre[0],
        o.centre[1],
        o.centre[2],
        o.samples,
        o.unreachable,
        o.candidates.len(),
        o.rays_per_view
    );
    s += "   #   x      y      z      roll   pitch   yaw    unknown occupied  score  reachable planned collision\n";
    let yn = |b: Option<bool>| match b {
        Some(true) => "yes",
        Some(false) => "no",
        None => "-",
    };
    for (k, c) in o.candidates.iter().enumerate() {
        s += &format!(
            "{:>4} {:>6.3} {:>6.3} {:>6.3} {:>6.1} {:>6.1} {:>6.1} {:>7} {:>8} {:>7.0}  {:>9} {:>7} {:>9}\n",
            k + 1,
            c.pose[0],
            c.pose[1],
            c.pose[2],
            c.pose[3],
            c.pose[4],
            c.pose[5],
            c.unknown,
            c.occupied,
            c.score,
            yn(Some(c.reachable)),
            yn(c.planned),
            yn(c.collision)
        );
    }
    s
}
