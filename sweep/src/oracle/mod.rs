//! The ground-truth ceiling of each object's exploration (`nbv oracle`): what the arm could
//! see of an object at best, and how few views get there.
//!
//! Candidate camera poses: Algorithm 2's (the scene's `[nbv]` sphere, rolls and steps,
//! around the object's true centre at mid height) and a dense set ([`DensePoses`]: several
//! radii within the camera's range, fine steps, rolls), each kept only if an inverse
//! kinematics solution within the joint limits puts the camera there without any contact
//! in the true world (objects, obstacles, table, the arm itself). From each kept pose the
//! Dinast is cast at the true scene, occluders included, without noise and without
//! dropouts (same range limits, field of view and grazing cut-off: a pixel counts when the
//! camera model's dropout probability there is below one), and its points are scored by the
//! report's own coverage ([`crate::report::coverage`]: the same 20,000 seeded surface
//! samples above the table, the same 1 cm). The base every view adds to is where the
//! exploration starts: phase 1 run in the twin as the episode runs it (the laser sweep at
//! the scene's seed, its noise and pose errors, the cloud aligned and segmented), its
//! object clusters — the report's coverage after 0 views.
//!
//! The **ceiling** is the union over all poses; the **greedy** set cover ([`CoverSets`])
//! gives the best-known coverage after 1, 2, … views; the samples no pose sees are told
//! apart by cause ([`UnseenCauses`]).

mod cache;
mod candidate_poses;
mod set_cover;
mod unseen;
mod view_coverage;

pub use cache::OracleCache;
pub use candidate_poses::{DensePose, DensePoses};
pub use set_cover::{CoverSets, GreedyCover};
pub use unseen::{TABLE_BAND, UnseenCause, UnseenCauses, unseen_cause};
pub use view_coverage::{FLOOR_ABOVE_TABLE, SurfaceSamples, camera_points};

use crate::error::{Context, Result, SweepError};
use nalgebra::Point3;
use nbv_core::kinematics::{Joints, Robot};
use nbv_core::math::Pose;
use nbv_core::nbv::{NextBestView, VisitedViews};
use nbv_core::pipeline::{ExploreMode, NoObserver, run_phase_one};
use nbv_scenes::Scene;
use nbv_sim::rig::SimRig;
use nbv_sim::sensors::CameraModel;
use nbv_sim::world::TwinWorld;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Share of the ceiling an exploration is held to ([`OracleObject::views_to_95`]).
pub const CEILING_SHARE: f64 = 0.95;

/// Casts scored together (their points held at once, their coverage in parallel).
const BATCH: usize = 16;

/// What [`oracle`] computes.
#[derive(Debug, Clone, Default)]
pub struct OracleOptions {
    /// Only this object (its name in the scene); every object when `None`.
    pub object: Option<String>,
    /// The dense pose set.
    pub dense: DensePoses,
    /// Views an exploration took, per object name: the camera pose and the arm's joints
    /// of each, in order. Each object's are cast like the oracle's poses
    /// ([`OracleObject::views_noise_free`]).
    pub views: Vec<(String, Vec<(Pose, Joints)>)>,
    /// Where oracles are kept and looked up ([`OracleCache`]; every object only): a stored
    /// oracle of the same world, sensors, sweep and sphere is read instead of computed,
    /// and only the `views` are cast.
    pub cache: Option<OracleCache>,
}

/// The oracle of a scene: `oracle.json`.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct OracleReport {
    /// The scene's name.
    pub scene: String,
    /// The scene's seed (the laser sweep's noise and pose errors, and the surface samples).
    pub seed: u64,
    /// The dense pose set's parameters.
    pub dense: serde_json::Value,
    /// One entry per object, in the scene's order.
    pub objects: Vec<OracleObject>,
    /// Wall-clock seconds.
    pub seconds: f64,
}

/// Candidate poses, evaluated and kept.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct PoseCounts {
    /// Poses evaluated: Algorithm 2's samples × rolls and the dense set.
    pub evaluated: usize,
    /// Of them, reachable without contact (and so cast).
    pub reachable: usize,
    /// Algorithm 2's samples (one per sphere sample, any roll).
    pub algorithm2: usize,
    /// Of them, reachable without contact at some roll.
    pub algorithm2_reachable: usize,
}

/// The oracle of one object.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct OracleObject {
    /// The object's name in the scene.
    pub name: String,
    /// Surface samples above the table (the report's).
    pub samples: usize,
    /// Share of the samples phase 1's clusters and every reachable view see together: no
    /// exploration's coverage can exceed it.
    pub ceiling: f64,
    /// Share phase 1's laser clusters cover: the greedy curve's start, and the
    /// exploration's (its coverage after 0 views).
    pub laser: f64,
    /// Share phase 1's clusters and Algorithm 2's reachable candidates see together (the
    /// scene's one viewing sphere; below `ceiling` where it does not fit the object).
    pub algorithm2_ceiling: f64,
    /// Coverage after 0, 1, 2, … greedy views (`greedy[0]` = `laser`; the last =
    /// `ceiling`).
    pub greedy: Vec<f64>,
    /// The greedy views' camera poses: x, y, z (m), roll, pitch, yaw (degrees).
    pub greedy_views: Vec<[f64; 6]>,
    /// Greedy views to reach [`CEILING_SHARE`] of the ceiling.
    pub views_to_95: usize,
    /// Poses evaluated and kept.
    pub poses: PoseCounts,
    /// The unseen rest by cause (shares of the samples).
    pub unseen: UnseenCauses,
    /// Coverage after 0, 1, … of the views given in [`OracleOptions::views`], seen as the
    /// oracle sees (phase 1's base, no noise, no dropouts): beside the exploration's own
    /// coverage it tells what the sensor's noise and the pipeline lost from what the choice
    /// of views lost. Empty without views.
    #[serde(default)]
    pub views_noise_free: Vec<f64>,
}

impl OracleObject {
    /// The greedy views to reach `share` of the ceiling (0 if phase 1 alone does).
    pub fn views_to(&self, share: f64) -> usize {
        views_to(&self.greedy, share * self.ceiling)
    }
}

/// The first index `k` with `curve[k] >= target` (up to rounding), or the last index.
pub fn views_to(curve: &[f64], target: f64) -> usize {
    curve
        .iter()
        .position(|&c| c >= target - 1e-12)
        .unwrap_or(curve.len().saturating_sub(1))
}

/// The oracle of `scene` (its seed; the twin's truth). Needs the robot base at the world
/// origin, as the pipeline does.
pub fn oracle(scene: &Scene, options: &OracleOptions) -> Result<OracleReport> {
    let start = std::time::Instant::now();
    check_options(scene, options)?;
    let config = scene.explore_config(ExploreMode::Hybrid)?;
    let meshes = scene.object_meshes()?;
    let clusters = phase_one_points(scene, &config)?;
    let mut caster = Caster::new(scene, &config)?;
    let table_top = caster.table_top;
    let cache = match &options.cache {
        Some(c) if options.object.is_none() => Some((c, OracleCache::key(scene, &options.dense)?)),
        _ => None,
    };
    let stored = cache.as_ref().and_then(|(c, key)| c.load(key));
    let mut objects = Vec::new();
    for (i, (object, mesh)) in scene.objects.iter().zip(&meshes).enumerate() {
        if options.object.as_ref().is_some_and(|n| n != &object.name) {
            continue;
        }
        let Some(samples) = SurfaceSamples::of(mesh, table_top, scene.seed) else {
            continue;
        };
        let taken = options
            .views
            .iter()
            .find(|(name, _)| name == &object.name)
            .map(|(_, taken)| taken.as_slice());
        let known = stored
            .as_ref()
            .and_then(|r| r.objects.iter().find(|o| o.name == object.name));
        let found = match known {
            Some(known) => {
                let mut o = known.clone();
                let base = samples.covered_by(&clusters);
                let base_count = base.iter().filter(|&&b| b).count();
                o.views_noise_free = match taken {
                    Some(taken) => caster.noise_free_curve(taken, &samples, base, base_count),
                    None => Vec::new(),
                };
                caster.world.set_configuration(caster.home);
                o
            }
            None => {
                caster.object_oracle(i, &object.name, &samples, &clusters, &options.dense, taken)?
            }
        };
        objects.push(found);
    }
    let report = OracleReport {
        scene: scene.name.clone(),
        seed: scene.seed,
        dense: serde_json::to_value(&options.dense)?,
        objects,
        seconds: start.elapsed().as_secs_f64(),
    };
    if let Some((cache, key)) = &cache
        && stored.is_none()
    {
        let mut kept = report.clone();
        kept.objects
            .iter_mut()
            .for_each(|o| o.views_noise_free.clear());
        cache.store(key, &kept)?;
    }
    Ok(report)
}

/// What each of `views` (camera pose, arm joints) sees of the object `name` alone, cast as
/// the oracle casts: the coverage of phase 1's clusters and this one view together, one
/// entry per view (in order), beside the clusters' own. `nbv views --oracle`
/// ranks Algorithm 2's candidates by it to measure an objective against the truth. An
/// error when the scene has no object `name`.
pub fn single_view_coverage(
    scene: &Scene,
    name: &str,
    views: &[(Pose, Joints)],
) -> Result<(f64, Vec<f64>)> {
    let i = scene
        .objects
        .iter()
        .position(|o| o.name == name)
        .ok_or_else(|| SweepError::Invalid(format!("{}: no object named `{name}`", scene.name)))?;
    let config = scene.explore_config(ExploreMode::Hybrid)?;
    let meshes = scene.object_meshes()?;
    let clusters = phase_one_points(scene, &config)?;
    let mut caster = Caster::new(scene, &config)?;
    let Some(samples) = SurfaceSamples::of(&meshes[i], caster.table_top, scene.seed) else {
        return Ok((0.0, vec![0.0; views.len()]));
    };
    let base = samples.covered_by(&clusters);
    let n = samples.len() as f64;
    let share =
        |mask: &[bool]| mask.iter().zip(&base).filter(|&(&m, &b)| m || b).count() as f64 / n;
    let mut out = Vec::with_capacity(views.len());
    caster.each_mask(views, &samples, |m| out.push(share(&m)));
    caster.world.set_configuration(caster.home);
    Ok((share(&vec![false; base.len()]), out))
}

/// Checks the options against the scene: a valid dense pose set, an object it has.
fn check_options(scene: &Scene, options: &OracleOptions) -> Result<()> {
    options
        .dense
        .validate()
        .map_err(|e| SweepError::Invalid(format!("the oracle's dense pose set: {e}")))?;
    if let Some(name) = &options.object
        && !scene.objects.iter().any(|o| &o.name == name)
    {
        let names: Vec<_> = scene.objects.iter().map(|o| o.name.as_str()).collect();
        return Err(SweepError::Invalid(format!(
            "{}: no object named `{name}` (objects: {})",
            scene.name,
            names.join(", ")
        )));
    }
    Ok(())
}

/// The true world the oracle casts in: the twin's world with the arm moved to each pose,
/// the noise-free camera, Algorithm 2's viewpoints, the arm's home to go back to, and the
/// table's top.
struct Caster {
    world: TwinWorld,
    robot: Robot,
    camera: CameraModel,
    /// The camera's frame, left out of its own casts.
    camera_frame: usize,
    nbv: NextBestView,
    home: Joints,
    table_top: f64,
}

impl Caster {
    /// The twin of `scene`, its robot base at the world origin.
    fn new(scene: &Scene, config: &nbv_core::pipeline::ExploreConfig) -> Result<Self> {
        let world = TwinWorld::from_scene(scene).context("building the twin world")?;
        let base = *world.base();
        if base.translation.vector.norm() > 1e-12 || base.rotation.angle() > 1e-12 {
            return Err(SweepError::Invalid(format!(
                "{}: the oracle needs the robot base at the world origin, as the pipeline does",
                scene.name
            )));
        }
        let camera = CameraModel::from_scene(&scene.sensors.short_range);
        let robot = world.robot().clone();
        let camera_frame = robot.frame_index(&camera.spec.frame).ok_or_else(|| {
            SweepError::Invalid(format!(
                "{}: the camera frame `{}` is not a link of the robot",
                scene.name, camera.spec.frame
            ))
        })?;
        let nbv = NextBestView::new(config.nbv, &camera.spec)?;
        let home = world.configuration();
        Ok(Self {
            world,
            robot,
            camera,
            camera_frame,
            nbv,
            home,
            table_top: scene.table.top(),
        })
    }

    /// The oracle of the scene's object `i` named `name` from its surface `samples`, phase
    /// 1's `clusters` (their points), the `dense` pose set and the views an exploration
    /// `taken` (if given); the arm is back home afterwards.
    fn object_oracle(
        &mut self,
        i: usize,
        name: &str,
        samples: &SurfaceSamples,
        clusters: &[Point3<f64>],
        dense: &DensePoses,
        taken: Option<&[(Pose, Joints)]>,
    ) -> Result<OracleObject> {
        let table_top = self.table_top;
        let centre = samples.centre(table_top);
        let base_mask = samples.covered_by(clusters);
        let base_covered: Vec<usize> = (0..samples.len()).filter(|&k| base_mask[k]).collect();
        let mut sets = CoverSets::new(samples.len(), &base_covered);
        let (goals, counts) = self.reachable_goals(&centre, dense)?;
        self.score_goals(&goals, samples, &mut sets);
        let n = samples.len() as f64;
        let views_noise_free = match taken {
            Some(taken) => self.noise_free_curve(taken, samples, base_mask, sets.base_count()),
            None => Vec::new(),
        };
        self.world.set_configuration(self.home);

        let greedy = sets.greedy();
        let alg2 = sets.count_with(0..counts.algorithm2_reachable) as f64 / n;
        let ceiling = sets.union_count() as f64 / n;
        let causes: Vec<UnseenCause> = sets
            .uncovered()
            .into_iter()
            .map(|k| {
                let (p, normal) = (&samples.points[k], &samples.normals[k]);
                unseen_cause(&self.world, i as u32, p, normal, table_top)
            })
            .collect();
        let curve: Vec<f64> = greedy.covered.iter().map(|&c| c as f64 / n).collect();
        Ok(OracleObject {
            name: name.to_owned(),
            samples: samples.len(),
            ceiling,
            laser: sets.base_count() as f64 / n,
            algorithm2_ceiling: alg2,
            views_to_95: views_to(&curve, CEILING_SHARE * ceiling),
            greedy: curve,
            greedy_views: greedy
                .picks
                .iter()
                .map(|&k| crate::views::pose_in_degrees(&goals[k].0))
                .collect(),
            poses: counts,
            unseen: UnseenCauses::of(&causes, samples.len()),
            views_noise_free,
        })
    }

    /// The camera poses around `centre` the arm reaches without contact, each with its
    /// first free solution: Algorithm 2's candidates first, then the `dense` set; and the
    /// counts of poses evaluated and kept.
    fn reachable_goals(
        &mut self,
        centre: &Point3<f64>,
        dense: &DensePoses,
    ) -> Result<(Vec<(Pose, Joints)>, PoseCounts)> {
        let mut counts = PoseCounts::default();
        let set = self
            .nbv
            .viewpoints(&self.robot, centre, &VisitedViews::default())?;
        counts.algorithm2 = set.samples;
        let mut goals: Vec<(Pose, Joints)> = Vec::new();
        for v in &set.viewpoints {
            counts.evaluated += 1;
            if let Some(q) = first_free(&mut self.world, v.solutions.iter().map(|s| s.joints)) {
                goals.push((v.pose, q));
            }
        }
        // Rolls without a solution count as evaluated too.
        counts.evaluated += set.unreachable * self.nbv.params.roll_candidates;
        counts.algorithm2_reachable = goals.len();
        let dense = dense
            .poses(centre)
            .map_err(|e| SweepError::Invalid(format!("the oracle's dense pose set: {e}")))?;
        counts.evaluated += dense.len();
        let (robot, frame) = (&self.robot, &self.camera.spec.frame);
        let solutions: Vec<Vec<Joints>> = dense
            .par_iter()
            .map(|d| {
                [d.pose, d.turned]
                    .iter()
                    .flat_map(|p| ik_joints(robot, frame, p))
                    .collect()
            })
            .collect();
        for (d, qs) in dense.iter().zip(solutions) {
            if let Some(q) = first_free(&mut self.world, qs.into_iter()) {
                goals.push((d.pose, q));
            }
        }
        counts.reachable = goals.len();
        Ok((goals, counts))
    }

    /// The camera's noise-free points from `pose`, the arm at `q`.
    fn cast(&mut self, pose: &Pose, q: Joints) -> Vec<Point3<f64>> {
        self.world.set_configuration(q);
        camera_points(&self.world, &self.camera, Some(self.camera_frame), pose)
    }

    /// Casts from every goal and adds what each covers of `samples` to `sets`, a batch at
    /// a time.
    fn score_goals(
        &mut self,
        goals: &[(Pose, Joints)],
        samples: &SurfaceSamples,
        sets: &mut CoverSets,
    ) {
        self.each_mask(goals, samples, |m| sets.push_mask(&m));
    }

    /// Casts from every goal, in order, and hands `seen` which of `samples` each covers; a
    /// batch at a time (the points of a batch held at once, their coverage in parallel).
    fn each_mask(
        &mut self,
        goals: &[(Pose, Joints)],
        samples: &SurfaceSamples,
        mut seen: impl FnMut(Vec<bool>),
    ) {
        for batch in goals.chunks(BATCH) {
            let clouds: Vec<Vec<Point3<f64>>> =
                batch.iter().map(|(pose, q)| self.cast(pose, *q)).collect();
            let masks: Vec<Vec<bool>> = clouds.par_iter().map(|c| samples.covered_by(c)).collect();
            masks.into_iter().for_each(&mut seen);
        }
    }

    /// [`OracleObject::views_noise_free`]: the coverage of `samples` after 0, 1, … of the
    /// views `taken`, from phase 1's `covered` (`base_count` of them).
    fn noise_free_curve(
        &mut self,
        taken: &[(Pose, Joints)],
        samples: &SurfaceSamples,
        mut covered: Vec<bool>,
        base_count: usize,
    ) -> Vec<f64> {
        let n = samples.len() as f64;
        let mut curve = vec![base_count as f64 / n];
        for (pose, q) in taken {
            let mask = samples.covered_by(&self.cast(pose, *q));
            covered.iter_mut().zip(mask).for_each(|(c, m)| *c |= m);
            curve.push(covered.iter().filter(|&&c| c).count() as f64 / n);
        }
        curve
    }
}

/// The points of phase 1's object clusters: the laser sweep run in the twin as the episode
/// runs it (the scene's seed draws the same noise and pose errors), aligned to the
/// workcell and segmented — what the exploration's model starts from, before any view.
fn phase_one_points(
    scene: &Scene,
    config: &nbv_core::pipeline::ExploreConfig,
) -> Result<Vec<Point3<f64>>> {
    let mut sim = SimRig::from_scene(scene).context("building the twin")?;
    let mut rig = sim.rig();
    let (_, segmentation) = run_phase_one(&mut rig, config, &mut NoObserver)
        .map_err(|e| SweepError::Invalid(format!("{}: phase 1: {e}", scene.name)))?;
    Ok(segmentation.labelled_clusters().points)
}

/// The IK solutions (within the joint limits) that put the camera at `pose`.
fn ik_joints(robot: &Robot, frame: &str, pose: &Pose) -> Vec<Joints> {
    robot
        .ik(frame, pose)
        .map(|s| s.into_iter().map(|s| s.joints).collect())
        .unwrap_or_default()
}

/// The first of `solutions` at which the arm touches nothing in the true world.
fn first_free(
    world: &mut TwinWorld,
    mut solutions: impl Iterator<Item = Joints>,
) -> Option<Joints> {
    solutions.find(|&q| world.contacts_at(q).is_empty())
}
