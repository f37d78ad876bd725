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
    /// Measure each reachable candidate against the truth
    /// ([`crate::oracle::single_view_coverage`]).
    pub oracle: bool,
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
    /// With `--oracle`: the object's true coverage by the laser sweep and this view alone,
    /// cast without noise (None: not measured, or unreachable).
    pub truth: Option<f64>,
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
    /// With `--oracle`: the score against the truth.
    pub truth: Option<TruthRanking>,
}

/// How an objective's ranking of the reachable candidates compares with what each one
/// truly sees ([`CandidateRow::truth`]).
#[derive(Debug, Clone, Serialize)]
pub struct TruthRanking {
    /// The laser sweep's coverage, before any view.
    pub laser: f64,
    /// The best candidate's true coverage.
    pub best: f64,
    /// The rank (1 = first) the objective gave the truly best candidate.
    pub best_rank: usize,
    /// The true coverage of the objective's first choice.
    pub chosen: f64,
    /// Spearman's rank correlation between score and true coverage.
    pub spearman: f64,
}

/// Spearman's rank correlation of `a` and `b` (average ranks for ties; 0 when either is
/// constant or there are fewer than 2 values).
fn spearman(a: &[f64], b: &[f64]) -> f64 {
    fn ranks(x: &[f64]) -> Vec<f64> {
        let mut idx: Vec<usize> = (0..x.len()).collect();
        idx.sort_by(|&i, &j| x[i].total_cmp(&x[j]));
        let mut r = vec![0.0; x.len()];
        let mut k = 0;
        while k < idx.len() {
            let mut e = k;
            while e + 1 < idx.len() && x[idx[e + 1]] == x[idx[k]] {
                e += 1;
            }
            for &i in &idx[k..=e] {
                r[i] = (k + e) as f64 / 2.0;
            }
            k = e + 1;
        }
        r
    }
    let (ra, rb) = (ranks(a), ranks(b));
    let n = a.len() as f64;
    let mean = (n - 1.0) / 2.0;
    let cov: f64 = ra
        .iter()
        .zip(&rb)
        .map(|(x, y)| (x - mean) * (y - mean))
        .sum();
    let va: f64 = ra.iter().map(|x| (x - mean).powi(2)).sum();
    let vb: f64 = rb.iter().map(|y| (y - mean).powi(2)).sum();
    if va == 0.0 || vb == 0.0 {
        0.0
    } else {
        cov / (va * vb).sqrt()
    }
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
        let ViewCandidates {
            mut planner, list, ..
        } = view_candidates(
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
                points: &cloud.points,
                views: &[],
                stalled: false,
                hull: nbv.params.hull_score.applies(false),
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
                truth: None,
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
        let truth = if options.oracle {
            Some(measure_truth(scene, &name, &list.candidates, &mut rows)?)
        } else {
            None
        };
        out.push(ObjectViews {
            name,
            centre: [centre.x, centre.y, centre.z],
            samples: list.samples,
            unreachable: list.unreachable,
            rays_per_view: list.rays_per_view,
            candidates: rows,
            truth,
        });
    }
    Ok(out)
}

/// Casts every candidate of object `name` as the oracle does, fills each row's `truth` and
/// ranks the objective against it.
fn measure_truth(
    scene: &nbv_scenes::Scene,
    name: &str,
    candidates: &[nbv_core::nbv::Candidate],
    rows: &mut [CandidateRow],
) -> Result<TruthRanking> {
    let views: Vec<_> = candidates
        .iter()
        .filter_map(|c| {
            c.viewpoint
                .solutions
                .first()
                .map(|s| (c.viewpoint.pose, s.joints))
        })
        .collect();
    let (laser, seen) = crate::oracle::single_view_coverage(scene, name, &views)?;
    let mut seen = seen.into_iter();
    for (row, c) in rows.iter_mut().zip(candidates) {
        if !c.viewpoint.solutions.is_empty() {
            row.truth = seen.next();
        }
    }
    let measured: Vec<(usize, f64, f64)> = rows
        .iter()
        .enumerate()
        .filter_map(|(k, r)| r.truth.map(|t| (k, r.score, t)))
        .collect();
    let (best_rank, best) =
        measured
            .iter()
            .enumerate()
            .fold((0, f64::NEG_INFINITY), |acc, (rank, &(_, _, t))| {
                if t > acc.1 { (rank + 1, t) } else { acc }
            });
    let scores: Vec<f64> = measured.iter().map(|m| m.1).collect();
    let truths: Vec<f64> = measured.iter().map(|m| m.2).collect();
    Ok(TruthRanking {
        laser,
        best: best.max(laser),
        best_rank,
        chosen: truths.first().copied().unwrap_or(laser),
        spearman: spearman(&scores, &truths),
    })
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

#[cfg(test)]
mod tests {
    use super::spearman;

    #[test]
    fn spearman_of_rankings_worked_out_by_hand() {
        assert_eq!(spearman(&[1.0, 2.0, 3.0], &[10.0, 20.0, 30.0]), 1.0);
        assert_eq!(spearman(&[1.0, 2.0, 3.0], &[3.0, 2.0, 1.0]), -1.0);
        // Ranks (0, 1, 2, 3) against (1, 0, 3, 2): 1 − 6·4 / (4·15) = 0.6.
        assert!((spearman(&[1.0, 2.0, 3.0, 4.0], &[2.0, 1.0, 4.0, 3.0]) - 0.6).abs() < 1e-12);
        // Ties take their average rank; a constant side has no correlation.
        assert!(
            (spearman(&[1.0, 1.0, 2.0], &[1.0, 2.0, 3.0]) - 0.866_025_403_784_438_6).abs() < 1e-12
        );
        assert_eq!(spearman(&[1.0, 1.0], &[1.0, 2.0]), 0.0);
        assert_eq!(spearman(&[], &[]), 0.0);
    }
}
