//! [`ExploreReport`]: what `nbv explore` writes to `report.json` — the exploration
//! measured against the twin's ground truth.

use crate::error::Result;
use crate::matching::{cluster_truth, true_object};
use nbv_core::cloud::PointCloud;
use nbv_core::evaluation::{
    MeshQuality, ModelQuality, ToleranceScores, alignment_error, mesh_quality, model_quality,
    point_error, quality_samples, surface_coverage, surface_coverage_curve, tolerance_scores,
};
use nbv_core::math::Pose;
use nbv_core::mesh::TriMesh;
use nbv_core::perception::WorkcellAlignment;
use nbv_core::pipeline::{Exploration, ExploreConfig, ObjectExploration, ObjectStop, StepTimes};
use nbv_scenes::Scene;
use serde::Serialize;

/// Distance (m) within which a true surface sample counts as covered by the model.
pub const COVERAGE_TOLERANCE: f64 = 0.01;
/// The tolerance τ (m) of the model-quality figures (precision, completeness, F-score):
/// the coverage's, so completeness is the coverage. 1 cm is the Dinast's noise at range
/// after the frames are averaged, and about twice the pose error the scenes declare; the
/// Tanks and Temples benchmark uses 3–10 mm for objects and rooms of this size.
pub const QUALITY_TOLERANCE: f64 = COVERAGE_TOLERANCE;
/// Surface samples per object for the coverage.
pub const COVERAGE_SAMPLES: usize = 20_000;
/// A short-range view adds nothing when it raises its object's coverage by less than this
/// (0.5 point): [`ObjectEntry::wasted_views`].
pub const WASTED_VIEW_GAIN: f64 = 0.005;
/// Mean alignment error (m) above which a registration counts as failed.
pub const FAILED_REGISTRATION_ERROR: f64 = 0.01;

/// Times per step (seconds), as the paper's Table I.
#[derive(Debug, Clone, Serialize)]
pub struct Times {
    motion: f64,
    acquisition: f64,
    segmentation: f64,
    mapping: f64,
    nbv: f64,
    planning: f64,
    registration: f64,
    meshing: f64,
    total: f64,
}

impl Times {
    /// The next-best-view step's time (s): candidates, their IK goals and their scores.
    pub fn nbv(&self) -> f64 {
        self.nbv
    }
}

impl From<&StepTimes> for Times {
    fn from(t: &StepTimes) -> Self {
        Self {
            motion: t.motion,
            acquisition: t.acquisition,
            segmentation: t.segmentation,
            mapping: t.mapping,
            nbv: t.nbv,
            planning: t.planning,
            registration: t.registration,
            meshing: t.meshing,
            total: t.total(),
        }
    }
}

/// The error of registered points against their true positions.
#[derive(Debug, Clone, Serialize)]
pub struct RegistrationScore {
    /// Mean point error (m): registered points against the true points they sampled,
    /// sensor noise included.
    pub mean: f64,
    /// Standard deviation of the point error (m).
    pub std: f64,
    /// Mean alignment error (m): how far each view's rigid misalignment displaces its true
    /// points, free of sensor noise (`nbv_core::evaluation::alignment_error`).
    pub alignment: f64,
    /// Standard deviation of the alignment error (m).
    pub alignment_std: f64,
    /// Whether the method reported convergence.
    pub converged: bool,
    /// Whether the pipeline kept the result: converged and every view's correction within
    /// `[registration] max_correction_deg` / `max_correction_m` (else the model keeps the
    /// reported poses).
    pub accepted: bool,
    /// Not converged, or a mean alignment error above the failure threshold.
    pub failed: bool,
}

/// One short-range view.
#[derive(Debug, Clone, Serialize)]
pub struct ViewEntry {
    /// Sensor position (m) and roll/pitch/yaw (rad) of the viewpoint.
    pub viewpoint: [f64; 6],
    /// The objective's value G(v) when chosen (eq. (4) by default).
    pub score: f64,
    /// Predicted |O_v| unknown, occupied.
    pub predicted_unknown: usize,
    /// Predicted occupied voxels.
    pub predicted_occupied: usize,
    /// Eq. (5) gain.
    pub gain: f64,
    /// Bernoulli KL divergence over O_v.
    pub gain_kl: f64,
    /// Points in the frame, and on the object.
    pub frame_points: usize,
    /// Points kept for the object.
    pub object_points: usize,
    /// Viewpoints that failed before this one.
    pub failures_before: usize,
    /// The new surface it added: the object's voxels it saw first, as a share of those seen
    /// before it (`nbv_core::nbv::SurfaceSides`: no ground truth, what the new-surface stop
    /// rule reads).
    pub new_surface: f64,
}

/// One object.
#[derive(Debug, Clone, Serialize)]
pub struct ObjectEntry {
    /// The true object's name (or `cluster-j` when the cluster is not one object).
    pub name: String,
    /// Phase-1 cluster index.
    pub cluster: usize,
    /// Points in the phase-1 cluster.
    pub cluster_points: usize,
    /// What the cluster is in truth: `object`, `unknown obstacle <name>` (an obstacle the
    /// robot was not told of: it may be explored, it matches none of the scene's
    /// objects), `known obstacle <name>`, `table` (both phantoms: pose error made them),
    /// `mixed` (no single thing has most of its points) or `unknown` (no truth labels: the
    /// real rig).
    pub truth: String,
    /// Short-range views taken.
    pub views: Vec<ViewEntry>,
    /// Viewpoints of `views` visited again for the self-calibration alone
    /// (`[registration] calibration_views`): in the registration, not in the exploration's
    /// views or its coverage by view.
    pub calibration_views: usize,
    /// Viewpoints tried (taken + failed).
    pub viewpoints_tried: usize,
    /// Viewpoints that failed, with the reasons.
    pub viewpoints_failed: Vec<String>,
    /// Candidates evaluated over all rounds.
    pub candidates_evaluated: usize,
    /// Times the arm went back to its pose after the sweep, no viewpoint being reachable
    /// from where it was.
    pub retreats: usize,
    /// Why exploration stopped.
    pub stop: String,
    /// The model (`objects/<name>/model.ply`) against the true surface at
    /// [`QUALITY_TOLERANCE`]: precision (share of its points within τ of the surface; table
    /// points, noise and misaligned views lower it), completeness (share of the surface
    /// above the table within τ of it), their F-score and the Chamfer distance
    /// ([`nbv_core::evaluation::model_quality`]).
    pub quality: Option<ModelQuality>,
    /// The same for the phase-1 laser cluster alone.
    pub quality_mid_range: Option<ModelQuality>,
    /// The same for the views as acquired (no registration): how far the rig's pose error
    /// alone leaves the model.
    pub quality_unregistered: Option<ModelQuality>,
    /// The model's points against the true surface at 2, 5 and 10 mm (beside `quality`'s
    /// 1 cm; [`nbv_core::evaluation::tolerance_scores`]).
    pub quality_fine: Option<ToleranceScores>,
    /// The fused surface (`model_mesh.ply`) against the true surface at 2, 5 and 10 mm
    /// ([`nbv_core::evaluation::mesh_quality`]); `None` without a mesh or a true object.
    pub mesh_quality: Option<MeshQuality>,
    /// Share of the true surface above the table within tolerance of the model (the model
    /// of the MAP registration, `objects/<name>/model.ply`), from 20,000 surface samples:
    /// the completeness of `quality` up to sampling. Misaligned views raise it.
    pub coverage: Option<f64>,
    /// Coverage of the phase-1 cluster alone.
    pub coverage_mid_range: Option<f64>,
    /// Coverage of the views as acquired (no registration).
    pub coverage_unregistered: Option<f64>,
    /// Coverage of the sequential-ICP model.
    pub coverage_icp: Option<f64>,
    /// Coverage after 0, 1, …, n short-range views: the model of the phase-1 cluster and
    /// the first k non-empty views, merged through the final registration's poses (as
    /// `coverage`, whose value the last entry is); empty for an unmatched cluster.
    pub coverage_by_view: Vec<f64>,
    /// Short-range views that raised `coverage_by_view` by less than [`WASTED_VIEW_GAIN`].
    pub wasted_views: usize,
    /// Views taken after the coverage last rose by [`WASTED_VIEW_GAIN`] or more (every view
    /// when none did).
    pub views_after_last_rise: usize,
    /// The exploration against the oracle's ceiling (`nbv explore --oracle`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub oracle: Option<OracleEntry>,
    /// Joint-space length (rad) of the planned paths to the views taken (after
    /// shortcutting; retreats not counted).
    pub joint_distance: f64,
    /// Mean point error of the views as acquired (no registration).
    pub error_unregistered: Option<RegistrationScore>,
    /// The method the model uses: the MAP registration (noise-weighted, with the rig's
    /// pose prior).
    pub error_map: Option<RegistrationScore>,
    /// The paper's p-ICP-GPA.
    pub error_pgpa: Option<RegistrationScore>,
    /// The MAP registration in detail: the verdict, per view the correction, its χ² and
    /// whether it was held at the prior.
    pub registration: Option<nbv_core::registration::MapReport>,
    /// Whether `registration` is a calibrated pass: its priors centred on the poses the
    /// rig's self-calibration (`hand_eye`) predicts, not on the reported ones.
    pub registration_calibrated: bool,
    /// Sequential ICP.
    pub error_icp: Option<RegistrationScore>,
    /// Registration failure message, if any.
    pub registration_error: Option<String>,
    /// Times.
    pub times: Times,
}

/// Phase 1 in numbers.
#[derive(Debug, Clone, Serialize)]
pub struct PhaseOneEntry {
    /// Scan lines.
    pub lines: usize,
    /// Camera frames of the short-only survey.
    pub survey_frames: usize,
    /// Points in the mid-range cloud.
    pub points: usize,
    /// Clusters found.
    pub clusters: usize,
    /// Voxels: occupied, empty, unknown (after phase 1).
    pub occupied: usize,
    /// Empty voxels.
    pub empty: usize,
    /// Unknown voxels.
    pub unknown: usize,
    /// Reduced map: occupied + unknown-with-empty-neighbour voxels.
    pub reduced_occupied: usize,
    /// Unknown voxels in the reduced map.
    pub reduced_unknown: usize,
    /// Point counts of segmentation, with its merged parts and dropped slivers.
    pub segmentation: nbv_core::perception::SegmentationCounts,
    /// Clusters that segmentation dropped as slivers of a known obstacle's face.
    pub slivers: Vec<SliverEntry>,
    /// Times.
    pub times: Times,
}

/// A cluster dropped as a sliver of a known obstacle's face.
#[derive(Debug, Clone, Serialize)]
pub struct SliverEntry {
    /// The known obstacle.
    pub obstacle: String,
    /// Points of the cluster.
    pub points: usize,
    /// Its centroid (m).
    pub centroid: [f64; 3],
    /// Its thickness (4σ, m).
    pub thickness: f64,
    /// How far in front of the obstacle's face (its exclusion box) it lies (m).
    pub distance: f64,
}

/// The whole report.
#[derive(Debug, Clone, Serialize)]
pub struct ExploreReport {
    /// Scene name.
    pub scene: String,
    /// Mode.
    pub mode: String,
    /// Seed.
    pub seed: u64,
    /// Phase 1.
    pub phase_one: PhaseOneEntry,
    /// Objects, in cluster order.
    pub objects: Vec<ObjectEntry>,
    /// Scene objects that no cluster was matched to.
    pub missed_objects: Vec<String>,
    /// Scene objects that more than one cluster was matched to (explored in parts).
    pub split_objects: Vec<String>,
    /// Clusters explored that are no scene object and no unknown obstacle (phantoms of the
    /// known workcell or mixtures), dropped ones not counted.
    pub phantom_clusters: usize,
    /// Clusters dropped after their first short-range view (not objects).
    pub dropped_clusters: usize,
    /// The laser sweep's correction from the known workcell, when it ran.
    pub workcell_alignment: Option<WorkcellEntry>,
    /// The depth camera's hand-eye correction estimated from the registrations, beside
    /// the twin's injected error.
    pub hand_eye: Option<HandEyeEntry>,
    /// Totals.
    pub totals: Totals,
    /// The configuration used (the scene file's sections).
    pub config: serde_json::Value,
}

/// The sweep's correction from the workcell ([`nbv_core::perception::align_to_workcell`]).
#[derive(Debug, Clone, Serialize)]
pub struct WorkcellEntry {
    /// Whether it was applied.
    pub accepted: bool,
    /// Its rotation (degrees).
    pub rotation_deg: f64,
    /// Displacement of the laser's mean position (m).
    pub translation: f64,
    /// Points on known surfaces.
    pub inliers: usize,
    /// RMS residual of those points (m).
    pub rms: f64,
    /// χ² under the sweep's prior.
    pub chi2: f64,
}

/// The hand-eye estimate and the truth it estimates.
#[derive(Debug, Clone, Serialize)]
pub struct HandEyeEntry {
    /// The estimate (sensor frame): rotation vector (rad), translation (m), σ, views.
    pub estimate: nbv_core::calibration::HandEyeEstimate,
    /// What the estimate estimates: the twin's injected hand-eye error with the last
    /// joint's injected offset folded in (that joint turns the camera like the mount does,
    /// so no calibration can tell the two apart): rotation vector (rad) and translation
    /// (m).
    pub truth: Option<[f64; 6]>,
    /// Angle (degrees) between estimate and truth.
    pub rotation_error_deg: Option<f64>,
    /// Distance (m) between estimate and truth.
    pub translation_error: Option<f64>,
    /// The twin's injected hand-eye error alone: rotation vector (rad) and translation (m).
    pub injected_mount: Option<[f64; 6]>,
    /// Angle (degrees) between the estimate and the injected mount alone.
    pub mount_rotation_error_deg: Option<f64>,
    /// Distance (m) between the estimate and the injected mount alone.
    pub mount_translation_error: Option<f64>,
    /// The twin's injected joint offsets (rad).
    pub joint_offsets_truth: Option<[f64; 6]>,
    /// The calibration as the camera views see it: per view, the angle (degrees) between
    /// the correction the estimate predicts at the view's joints and the one the injected
    /// errors imply; median and largest over the views (joint offsets and mount
    /// together).
    pub view_rotation_error_deg: Option<[f64; 2]>,
    /// As `view_rotation_error_deg`, for the sensor origin's displacement (m).
    pub view_translation_error: Option<[f64; 2]>,
}

/// Totals over the objects.
#[derive(Debug, Clone, Serialize)]
pub struct Totals {
    /// Short-range views.
    pub views: usize,
    /// Viewpoints that failed.
    pub failed_viewpoints: usize,
    /// Collisions the twin detected on executed paths (must be 0).
    pub collisions: usize,
    /// Mean F-score of the models over the matched objects (0 without one).
    pub mean_f_score: f64,
    /// Mean F-score of the views as acquired over the matched objects.
    pub mean_f_score_unregistered: f64,
    /// Mean coverage over the matched objects.
    pub mean_coverage: f64,
    /// Joint-space length (rad) of the planned paths to all views taken.
    pub joint_distance: f64,
    /// Mean alignment error of the model's registration over objects (m).
    pub mean_error_map: Option<f64>,
    /// Mean sequential ICP error (m).
    pub mean_error_icp: Option<f64>,
    /// Registrations that failed, per method.
    pub failed_map: usize,
    /// Failed sequential ICP registrations.
    pub failed_icp: usize,
    /// Short-range views that added less than [`WASTED_VIEW_GAIN`] of coverage, over the
    /// objects.
    pub wasted_views: usize,
    /// Smallest `coverage / ceiling` over the objects (with the oracle).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub min_coverage_of_ceiling: Option<f64>,
    /// Mean `coverage / ceiling` over the objects (with the oracle).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mean_coverage_of_ceiling: Option<f64>,
    /// Times summed over phase 1 and the objects.
    pub times: Times,
}

/// An object's exploration against its ground-truth ceiling ([`crate::oracle`]).
#[derive(Debug, Clone, Serialize)]
pub struct OracleEntry {
    /// The share of the surface the laser and every reachable view see together.
    pub ceiling: f64,
    /// `coverage / ceiling`.
    pub coverage_of_ceiling: f64,
    /// Short-range views the exploration took to reach [`CEILING_SHARE`] of the ceiling
    /// (by `coverage_by_view`); `None` when it never did.
    ///
    /// [`CEILING_SHARE`]: crate::oracle::CEILING_SHARE
    pub views_to_95: Option<usize>,
    /// The greedy set cover's views to the same coverage.
    pub oracle_views_to_95: usize,
    /// The greedy set cover's coverage after 0, 1, … views.
    pub greedy: Vec<f64>,
    /// The exploration's own views seen as the oracle sees them (no noise, no dropouts,
    /// the true scene) after 0, 1, … views: what its choice of views reached, apart from
    /// what the sensor and the pipeline lost.
    pub noise_free_by_view: Vec<f64>,
}

impl ExploreReport {
    /// Measures each matched object against its entry of `oracle` (same scene and seed):
    /// fills [`ObjectEntry::oracle`] and the totals' shares of the ceiling.
    pub fn attach_oracle(&mut self, oracle: &crate::oracle::OracleReport) {
        for entry in &mut self.objects {
            let (Some(o), Some(coverage)) = (
                oracle.objects.iter().find(|o| o.name == entry.name),
                entry.coverage,
            ) else {
                continue;
            };
            let target = crate::oracle::CEILING_SHARE * o.ceiling;
            entry.oracle = Some(OracleEntry {
                ceiling: o.ceiling,
                coverage_of_ceiling: if o.ceiling > 0.0 {
                    coverage / o.ceiling
                } else {
                    1.0
                },
                views_to_95: entry
                    .coverage_by_view
                    .iter()
                    .position(|&c| c >= target - 1e-12),
                oracle_views_to_95: o.views_to_95,
                greedy: o.greedy.clone(),
                noise_free_by_view: o.views_noise_free.clone(),
            });
        }
        let shares: Vec<f64> = self
            .objects
            .iter()
            .filter_map(|o| o.oracle.as_ref().map(|e| e.coverage_of_ceiling))
            .collect();
        self.totals.min_coverage_of_ceiling = shares.iter().copied().reduce(f64::min);
        self.totals.mean_coverage_of_ceiling =
            (!shares.is_empty()).then(|| shares.iter().sum::<f64>() / shares.len() as f64);
    }
}

/// `(wasted, after_last_rise)` of a coverage-by-view curve (entry 0 before the first
/// view): the views that raised it by less than [`WASTED_VIEW_GAIN`], and the views after
/// the last one that raised it by at least that.
///
/// ```
/// use nbv_sweep::report::view_gains;
/// assert_eq!(view_gains(&[0.5, 0.7, 0.702, 0.8, 0.801, 0.802]), (3, 2));
/// assert_eq!(view_gains(&[0.5]), (0, 0));
/// assert_eq!(view_gains(&[0.5, 0.5]), (1, 1));
/// ```
pub fn view_gains(curve: &[f64]) -> (usize, usize) {
    let views = curve.len().saturating_sub(1);
    let rises: Vec<bool> = curve
        .windows(2)
        .map(|w| w[1] - w[0] >= WASTED_VIEW_GAIN - 1e-12)
        .collect();
    let wasted = rises.iter().filter(|&&r| !r).count();
    let last = rises.iter().rposition(|&r| r).map_or(0, |k| k + 1);
    (wasted, views - last)
}

/// The share of an object's true surface (`mesh`, above the table) that `model` covers
/// within [`COVERAGE_TOLERANCE`]: the report's coverage.
pub fn coverage(
    scene: &Scene,
    mesh: &nbv_core::mesh::TriMesh,
    model: &nbv_core::cloud::PointCloud,
) -> f64 {
    surface_coverage(
        mesh,
        model,
        COVERAGE_TOLERANCE,
        scene.table.top() + 0.005,
        COVERAGE_SAMPLES,
        scene.seed,
    )
    .share()
}

/// Measures `exploration` against the scene's truth.
pub fn evaluate(
    scene: &Scene,
    config: &ExploreConfig,
    exploration: &Exploration,
) -> Result<ExploreReport> {
    let meshes = scene.object_meshes()?;
    let mut tally = ClusterTally::new(scene);
    let objects: Vec<ObjectEntry> = exploration
        .objects
        .iter()
        .map(|object| object_entry(scene, &meshes, object, &mut tally))
        .collect::<Result<_>>()?;
    let totals = totals(&objects, exploration);
    let p = &exploration.phase_one;
    Ok(ExploreReport {
        scene: scene.name.clone(),
        mode: exploration.mode.name().into(),
        seed: scene.seed,
        phase_one: phase_one_entry(scene, exploration),
        objects,
        missed_objects: tally.objects_matched(scene, |m| m == 0),
        split_objects: tally.objects_matched(scene, |m| m > 1),
        phantom_clusters: tally.phantoms,
        dropped_clusters: tally.dropped,
        workcell_alignment: p.workcell.as_ref().map(|a| workcell_entry(a, &p.cloud)),
        hand_eye: exploration
            .hand_eye
            .as_ref()
            .map(|e| hand_eye_entry(scene, e, exploration)),
        totals,
        config: config_json(scene, config),
    })
}

/// What the clusters explored are in truth, counted over the episode: how many clusters
/// each scene object was matched to, the phantoms and the dropped clusters.
struct ClusterTally {
    /// Per scene object, the clusters matched to it (dropped ones not counted).
    matched_by: Vec<usize>,
    /// Clusters explored that are no scene object and no unknown obstacle.
    phantoms: usize,
    /// Clusters dropped as not objects.
    dropped: usize,
}

impl ClusterTally {
    /// Nothing counted yet.
    fn new(scene: &Scene) -> Self {
        Self {
            matched_by: vec![0; scene.objects.len()],
            phantoms: 0,
            dropped: 0,
        }
    }

    /// Counts `object`: the scene object it is (if any) and what it is in truth
    /// ([`ObjectEntry::truth`]).
    fn count(
        &mut self,
        object: &ObjectExploration,
        scene: &Scene,
        meshes: &[TriMesh],
    ) -> (Option<usize>, String) {
        let truth = true_object(object, scene, meshes);
        let dropped = matches!(object.stop, ObjectStop::NotAnObject { .. });
        if let Some(i) = truth
            && !dropped
        {
            self.matched_by[i] += 1;
        }
        let what = cluster_truth(&object.cluster, scene, truth);
        if !dropped && truth.is_none() && !what.starts_with("unknown obstacle") {
            self.phantoms += 1;
        }
        self.dropped += usize::from(dropped);
        (truth, what)
    }

    /// The names of the scene objects whose number of matched clusters passes `keep`.
    fn objects_matched(&self, scene: &Scene, keep: impl Fn(usize) -> bool) -> Vec<String> {
        scene
            .objects
            .iter()
            .zip(&self.matched_by)
            .filter(|(_, m)| keep(**m))
            .map(|(o, _)| o.name.clone())
            .collect()
    }
}

/// One explored cluster measured against the true object it is (`meshes[i]` for the
/// scene's object `i`), if any.
fn object_entry(
    scene: &Scene,
    meshes: &[TriMesh],
    object: &ObjectExploration,
    tally: &mut ClusterTally,
) -> Result<ObjectEntry> {
    let (truth, what) = tally.count(object, scene, meshes);
    let name = truth.map_or(format!("cluster-{}", object.index), |i| {
        scene.objects[i].name.clone()
    });
    let surface = TrueSurface {
        scene,
        mesh: truth.map(|i| &meshes[i]),
    };
    let scores = RegistrationScores::of(object);
    let map_report = object
        .registration
        .as_ref()
        .and_then(|r| match &r.map.report {
            nbv_core::registration::MethodReport::Map(m) => Some((**m).clone()),
            _ => None,
        });
    let model = object.model()?;
    let unregistered = object.unregistered_model();
    let coverage_by_view = surface.coverage_by_view(object)?;
    let (wasted_views, views_after_last_rise) = view_gains(&coverage_by_view);
    Ok(ObjectEntry {
        name,
        cluster: object.index,
        cluster_points: object.cluster.len(),
        truth: what,
        views: object.views.iter().map(view_entry).collect(),
        calibration_views: object.calibration_views.len(),
        viewpoints_tried: object.views.len() + object.failures.len(),
        viewpoints_failed: object.failures.iter().map(|f| f.reason.clone()).collect(),
        candidates_evaluated: object.candidates_evaluated,
        retreats: object.retreats,
        stop: object.stop.to_string(),
        quality: surface.quality(&model),
        quality_mid_range: surface.quality(&object.cluster),
        quality_unregistered: surface.quality(&unregistered),
        quality_fine: surface.quality_fine(&model),
        mesh_quality: object
            .surface
            .as_ref()
            .and_then(|m| surface.mesh_quality(&m.mesh)),
        coverage: surface.coverage(&model),
        coverage_mid_range: surface.coverage(&object.cluster),
        coverage_unregistered: surface.coverage(&unregistered),
        coverage_icp: object.icp_model()?.and_then(|m| surface.coverage(&m)),
        coverage_by_view,
        wasted_views,
        views_after_last_rise,
        oracle: None,
        joint_distance: object
            .views
            .iter()
            .map(|v| v.plan.length_after_shortcut)
            .sum(),
        error_unregistered: scores.unregistered,
        error_map: scores.map,
        error_pgpa: scores.pgpa,
        registration: map_report,
        registration_calibrated: object.registration.as_ref().is_some_and(|r| r.calibrated),
        error_icp: scores.icp,
        registration_error: object.registration_error.clone(),
        times: Times::from(&object.times),
    })
}

/// The true surface of the object a cluster is (`None`: it is none of the scene's
/// objects, and nothing is measured).
struct TrueSurface<'a> {
    /// The scene (its table and seed).
    scene: &'a Scene,
    /// The object's mesh.
    mesh: Option<&'a TriMesh>,
}

impl TrueSurface<'_> {
    /// The surface above this height (m) is measured: the table top and 5 mm.
    fn floor(&self) -> f64 {
        self.scene.table.top() + 0.005
    }

    /// The quality of `cloud` at [`QUALITY_TOLERANCE`].
    fn quality(&self, cloud: &PointCloud) -> Option<ModelQuality> {
        self.mesh.and_then(|mesh| {
            model_quality(
                mesh,
                cloud,
                QUALITY_TOLERANCE,
                self.floor(),
                quality_samples(mesh, QUALITY_TOLERANCE),
                self.scene.seed,
            )
        })
    }

    /// The quality of a point model at 2, 5 and 10 mm ([`tolerance_scores`]).
    fn quality_fine(&self, cloud: &PointCloud) -> Option<ToleranceScores> {
        self.mesh
            .and_then(|mesh| tolerance_scores(mesh, &cloud.points, self.floor(), self.scene.seed))
    }

    /// The quality of a reconstructed surface mesh ([`mesh_quality`]).
    fn mesh_quality(&self, reconstruction: &TriMesh) -> Option<MeshQuality> {
        self.mesh
            .and_then(|mesh| mesh_quality(mesh, reconstruction, self.floor(), self.scene.seed))
    }

    /// The coverage of `model` ([`coverage`]).
    fn coverage(&self, model: &PointCloud) -> Option<f64> {
        self.mesh.map(|mesh| coverage(self.scene, mesh, model))
    }

    /// [`ObjectEntry::coverage_by_view`]: empty for a cluster that is no object.
    fn coverage_by_view(&self, object: &ObjectExploration) -> Result<Vec<f64>> {
        let Some(mesh) = self.mesh else {
            return Ok(Vec::new());
        };
        let parts = parts_by_view(object)?;
        let parts: Vec<&PointCloud> = parts.iter().collect();
        Ok(surface_coverage_curve(
            mesh,
            &parts,
            COVERAGE_TOLERANCE,
            self.floor(),
            COVERAGE_SAMPLES,
            self.scene.seed,
        )
        .iter()
        .map(nbv_core::evaluation::Coverage::share)
        .collect())
    }
}

/// An object's views registered by each method, scored against their true points.
struct RegistrationScores {
    /// The views as acquired (identity corrections).
    unregistered: Option<RegistrationScore>,
    /// The MAP registration (the model's).
    map: Option<RegistrationScore>,
    /// p-ICP-GPA.
    pgpa: Option<RegistrationScore>,
    /// Sequential ICP.
    icp: Option<RegistrationScore>,
}

impl RegistrationScores {
    /// The scores of `object`'s registrations (none without one).
    fn of(object: &ObjectExploration) -> Self {
        let Some(r) = &object.registration else {
            return Self {
                unregistered: None,
                map: None,
                pgpa: None,
                icp: None,
            };
        };
        Self {
            unregistered: registration_score(
                &r.points,
                &vec![Pose::identity(); r.points.len()],
                true,
                true,
            ),
            map: registration_score(&r.points, &r.map.poses, r.map.converged, r.map_accepted),
            pgpa: r
                .gpa
                .as_ref()
                .and_then(|g| registration_score(&r.points, &g.poses, g.converged, r.gpa_accepted)),
            icp: r
                .icp
                .as_ref()
                .and_then(|i| registration_score(&r.points, &i.poses, i.converged, r.icp_accepted)),
        }
    }
}

/// The point and alignment errors of `views` corrected by `poses` (`None` without a true
/// point); failed when not converged or misaligned by more than
/// [`FAILED_REGISTRATION_ERROR`].
fn registration_score(
    views: &[PointCloud],
    poses: &[Pose],
    converged: bool,
    accepted: bool,
) -> Option<RegistrationScore> {
    let e = point_error(views, poses);
    let a = alignment_error(views, poses);
    (e.points > 0).then_some(RegistrationScore {
        mean: e.mean,
        std: e.std,
        alignment: a.mean,
        alignment_std: a.std,
        converged,
        accepted,
        failed: !converged || a.mean > FAILED_REGISTRATION_ERROR,
    })
}

/// The totals over the objects' entries (the ceiling's shares left to
/// [`ExploreReport::attach_oracle`]).
fn totals(objects: &[ObjectEntry], exploration: &Exploration) -> Totals {
    let mut total_times = exploration.phase_one.times;
    for o in &exploration.objects {
        total_times.add(&o.times);
    }
    let mean = |v: Vec<f64>| (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64);
    let coverages: Vec<f64> = objects.iter().filter_map(|o| o.coverage).collect();
    let f_scores = |pick: fn(&ObjectEntry) -> Option<ModelQuality>| {
        mean(
            objects
                .iter()
                .filter_map(|o| pick(o).map(|q| q.f_score))
                .collect(),
        )
        .unwrap_or(0.0)
    };
    Totals {
        views: objects.iter().map(|o| o.views.len()).sum(),
        failed_viewpoints: objects.iter().map(|o| o.viewpoints_failed.len()).sum(),
        collisions: exploration.collisions,
        mean_f_score: f_scores(|o| o.quality),
        mean_f_score_unregistered: f_scores(|o| o.quality_unregistered),
        mean_coverage: mean(coverages).unwrap_or(0.0),
        joint_distance: objects.iter().map(|o| o.joint_distance).sum(),
        mean_error_map: mean(
            objects
                .iter()
                .filter_map(|o| o.error_map.as_ref().map(|e| e.mean))
                .collect(),
        ),
        mean_error_icp: mean(
            objects
                .iter()
                .filter_map(|o| o.error_icp.as_ref().map(|e| e.mean))
                .collect(),
        ),
        failed_map: objects
            .iter()
            .filter(|o| o.error_map.as_ref().is_some_and(|e| e.failed))
            .count(),
        failed_icp: objects
            .iter()
            .filter(|o| o.error_icp.as_ref().is_some_and(|e| e.failed))
            .count(),
        wasted_views: objects.iter().map(|o| o.wasted_views).sum(),
        min_coverage_of_ceiling: None,
        mean_coverage_of_ceiling: None,
        times: Times::from(&total_times),
    }
}

/// Phase 1 in numbers: the sweep, the grid after it, the segmentation and its slivers
/// (named by the scene's known obstacles).
fn phase_one_entry(scene: &Scene, exploration: &Exploration) -> PhaseOneEntry {
    let p = &exploration.phase_one;
    let counts = p.grid.state_counts();
    PhaseOneEntry {
        lines: p.lines,
        survey_frames: p.survey_frames,
        points: p.cloud.len(),
        clusters: exploration.objects.len(),
        occupied: counts.occupied,
        empty: counts.empty,
        unknown: counts.unknown,
        reduced_occupied: p.reduced.occupied,
        reduced_unknown: p.reduced.unknown_crust,
        segmentation: p.segmentation,
        slivers: p
            .slivers
            .iter()
            .map(|s| SliverEntry {
                obstacle: scene
                    .obstacles
                    .iter()
                    .filter(|o| o.known)
                    .nth(s.obstacle)
                    .map_or_else(|| format!("obstacle {}", s.obstacle), |o| o.name.clone()),
                points: s.points,
                centroid: s.centroid.coords.into(),
                thickness: s.thickness,
                distance: s.distance,
            })
            .collect(),
        times: Times::from(&p.times),
    }
}

/// The sweep's correction from the workcell; its translation is the displacement of the
/// laser's first origin in `cloud` (of the origin without one).
fn workcell_entry(a: &WorkcellAlignment, cloud: &PointCloud) -> WorkcellEntry {
    let laser = cloud.origins.as_ref().and_then(|o| o.first().copied());
    WorkcellEntry {
        accepted: a.accepted,
        rotation_deg: a.estimate.rotation.angle().to_degrees(),
        translation: laser.map_or(a.estimate.translation.vector.norm(), |o| {
            (a.estimate * o - o).norm()
        }),
        inliers: a.inliers,
        rms: a.rms,
        chi2: a.chi2,
    }
}

/// What each short-range view adds to the object's model (see
/// [`ObjectEntry::coverage_by_view`]): the phase-1 cluster, then per taken view its
/// registered cloud (empty for a view that saw nothing), through the MAP poses when
/// accepted (as [`ObjectExploration::model`]); the model after `k` views is the union of
/// the first `k + 1` parts.
///
/// [`ObjectExploration::model`]: nbv_core::pipeline::ObjectExploration::model
fn parts_by_view(
    object: &nbv_core::pipeline::ObjectExploration,
) -> Result<Vec<nbv_core::cloud::PointCloud>> {
    let empty = nbv_core::cloud::PointCloud::default;
    let Some(r) = &object.registration else {
        let mut parts = vec![object.model()?];
        parts.resize_with(object.views.len() + 1, empty);
        return Ok(parts);
    };
    let part = |k: usize| {
        let Some(v) = r.points.get(k) else {
            return empty();
        };
        let pose = if r.map_accepted {
            r.map.poses.get(k).copied().unwrap_or_else(Pose::identity)
        } else {
            Pose::identity()
        };
        let mut v = v.clone();
        v.transform(&pose);
        v
    };
    let mut parts = vec![part(0)];
    let mut registered = 0;
    for v in &object.views {
        if v.cloud.is_empty() {
            parts.push(empty());
        } else {
            registered += 1;
            parts.push(part(registered));
        }
    }
    Ok(parts)
}

fn view_entry(v: &nbv_core::pipeline::AcquiredView) -> ViewEntry {
    let ([x, y, z], [r, p, w]) = nbv_core::math::pose_to_xyz_rpy(&v.viewpoint);
    ViewEntry {
        viewpoint: [x, y, z, r, p, w],
        score: v.score,
        predicted_unknown: v.predicted.0,
        predicted_occupied: v.predicted.1,
        gain: v.gain.total,
        gain_kl: v.gain.bernoulli_kl,
        frame_points: v.frame_points,
        object_points: v.cloud.len(),
        failures_before: v.failures_before,
        new_surface: v.new_surface,
    }
}

/// The scene sections that drive the run, as JSON.
fn config_json(scene: &Scene, config: &ExploreConfig) -> serde_json::Value {
    serde_json::json!({
        "nbv": scene.nbv,
        "planner": scene.planner,
        "registration": scene.registration,
        "mapping": scene.mapping,
        "segmentation": scene.segmentation,
        "errors": scene.errors,
        "mode": config.mode.name(),
        "max_views_per_object": config.max_views_per_object,
        "object_margin": config.object_margin,
        "coverage_tolerance": COVERAGE_TOLERANCE,
        "quality_tolerance": QUALITY_TOLERANCE,
        "failed_registration_error": FAILED_REGISTRATION_ERROR,
    })
}

/// The hand-eye estimate beside the scene's injected error (the twin's truth), with the
/// last joint's offset folded into the mount as the estimate has it
/// ([`identifiable_mount`](nbv_core::calibration::identifiable_mount)); the comparisons
/// with that are `None` where the robot's model does not load.
fn hand_eye_entry(
    scene: &Scene,
    estimate: &nbv_core::calibration::HandEyeEstimate,
    exploration: &Exploration,
) -> HandEyeEntry {
    let (xyz, rpy) = scene.errors.scaled_hand_eye();
    let mount = nbv_core::math::pose_from_xyz_rpy(xyz, rpy);
    let offsets = scene.errors.scaled_joint_offsets();
    let robot = nbv_core::kinematics::Robot::from_urdf_file(&scene.robot.urdf).ok();
    let frame = &scene.sensors.short_range.frame;
    let folded = robot
        .as_ref()
        .and_then(|r| nbv_core::calibration::identifiable_mount(r, frame, &mount, offsets));
    // A pose as a rotation vector (rad) and a translation (m).
    let six = |p: &Pose| {
        let (w, t) = (p.rotation.scaled_axis(), p.translation.vector);
        [w.x, w.y, w.z, t.x, t.y, t.z]
    };
    // Angle (degrees) and distance (m) of the estimate from `p`.
    let est_rotation =
        nalgebra::UnitQuaternion::from_scaled_axis(nalgebra::Vector3::from(estimate.rotation));
    let off = |p: &Pose| {
        (
            est_rotation.angle_to(&p.rotation).to_degrees(),
            (nalgebra::Vector3::from(estimate.translation) - p.translation.vector).norm(),
        )
    };
    let views = robot
        .as_ref()
        .zip(folded.as_ref())
        .and_then(|(r, (truth, rest))| {
            let [wx, wy, wz, tx, ty, tz] = six(truth);
            let injected = nbv_core::calibration::HandEyeEstimate {
                rotation: [wx, wy, wz],
                translation: [tx, ty, tz],
                joint_offsets: *rest,
                ..estimate.clone()
            };
            view_errors(r, frame, estimate, &injected, exploration)
        });
    let truth_off = folded.as_ref().map(|(truth, _)| off(truth));
    let mount_off = off(&mount);
    HandEyeEntry {
        estimate: estimate.clone(),
        truth: folded.as_ref().map(|(truth, _)| six(truth)),
        rotation_error_deg: truth_off.map(|(r, _)| r),
        translation_error: truth_off.map(|(_, t)| t),
        injected_mount: Some(six(&mount)),
        mount_rotation_error_deg: Some(mount_off.0),
        mount_translation_error: Some(mount_off.1),
        joint_offsets_truth: Some(offsets),
        view_rotation_error_deg: views.map(|(r, _)| r.map(f64::to_degrees)),
        view_translation_error: views.map(|(_, t)| t),
    }
}

/// Median and largest, over the camera views of `exploration`, of the rotation (rad) and
/// translation (m) between the corrections `estimate` and `injected` predict at each
/// view of `robot`'s camera `frame` (the same linearisation for both); `None` without
/// views.
fn view_errors(
    robot: &nbv_core::kinematics::Robot,
    frame: &str,
    estimate: &nbv_core::calibration::HandEyeEstimate,
    injected: &nbv_core::calibration::HandEyeEstimate,
    exploration: &Exploration,
) -> Option<([f64; 2], [f64; 2])> {
    let (mut rotations, mut translations) = (Vec::new(), Vec::new());
    let views = exploration.objects.iter().flat_map(|o| &o.views);
    for v in views.filter(|v| !v.cloud.is_empty()) {
        let (a, _) = estimate.view_correction(robot, frame, &v.joints, &v.sensor_pose)?;
        let (b, _) = injected.view_correction(robot, frame, &v.joints, &v.sensor_pose)?;
        let d = a - b;
        rotations.push(d.fixed_rows::<3>(0).norm());
        translations.push(d.fixed_rows::<3>(3).norm());
    }
    let median_max = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        [v[v.len() / 2], v[v.len() - 1]]
    };
    (!rotations.is_empty()).then(|| (median_max(rotations), median_max(translations)))
}
