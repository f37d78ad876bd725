//! A sweep's results: one [`EpisodeRow`] per finished episode (its parameters and metrics,
//! from the episode's report), `results.csv` from all rows, and the machine-readable
//! [`Summary`](crate::engine::Summary) — aggregates, the best settings by F-score, by
//! coverage gain per view and by registration error, and the per-object registration
//! table (the paper's Table III on the twin).

use crate::error::{Context, Result};
use crate::grid::Episode;
use crate::report::ExploreReport;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::Path;

/// One episode's parameters and metrics (a row of `results.csv`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EpisodeRow {
    /// Position in the grid's expansion.
    pub index: usize,
    /// Stable episode id.
    pub id: String,
    /// Scene label.
    pub scene: String,
    /// Mode.
    pub mode: String,
    /// The episode's seed.
    pub seed: u64,
    /// Swept parameters, as text, in the grid's key order.
    pub params: Vec<(String, String)>,
    /// Objects in the scene.
    pub objects: usize,
    /// Scene objects no cluster matched.
    pub missed: usize,
    /// Scene objects more than one explored cluster matched (0 in older rows).
    #[serde(default)]
    pub split: usize,
    /// Clusters explored that are no scene object and no unknown obstacle (0 in older
    /// rows).
    #[serde(default)]
    pub phantoms: usize,
    /// Clusters dropped after their first view or as slivers of a known face (0 in older
    /// rows).
    #[serde(default)]
    pub dropped: usize,
    /// The error level (`errors.scale` when swept, else 1).
    #[serde(default = "one")]
    pub level: f64,
    /// Short-range views taken.
    pub views: usize,
    /// Viewpoints that failed.
    pub failed_viewpoints: usize,
    /// Collisions in truth.
    pub collisions: usize,
    /// Mean F-score of the models over the matched objects, at the report's quality
    /// tolerance (0 in rows written before it existed).
    #[serde(default)]
    pub f_score: f64,
    /// Smallest object F-score (0 without a matched object).
    #[serde(default)]
    pub f_score_min: f64,
    /// Mean F-score of the views as acquired (no registration).
    #[serde(default)]
    pub f_score_unregistered: f64,
    /// Mean Chamfer distance of the models to the true surfaces (m).
    #[serde(default)]
    pub chamfer: f64,
    /// Mean F-score at 2 mm of the fused surfaces (`model_mesh.ply`) over the matched
    /// objects with one (0 without).
    #[serde(default)]
    pub mesh_f_score_2mm: f64,
    /// The same at 5 mm.
    #[serde(default)]
    pub mesh_f_score_5mm: f64,
    /// Mean Chamfer distance of the fused surfaces (m).
    #[serde(default)]
    pub mesh_chamfer: f64,
    /// Mean surface coverage over the matched objects (the model).
    pub coverage: f64,
    /// Smallest object coverage.
    pub coverage_min: f64,
    /// Mean model precision over the matched objects: the share of model points within
    /// the coverage tolerance of the true surface (0 in rows written before it existed).
    #[serde(default)]
    pub precision: f64,
    /// Mean coverage of the laser clusters alone.
    pub coverage_mid_range: f64,
    /// (coverage − coverage_mid_range) / (views per object): what a view adds.
    pub coverage_gain_per_view: f64,
    /// Mean alignment error of the model's registration (the MAP) over the registered
    /// objects (m). Read as `error_gpa` from rows written before it had its name.
    #[serde(alias = "error_gpa")]
    pub error_map: f64,
    /// Mean alignment error of sequential ICP (m).
    pub error_icp: f64,
    /// Mean alignment error of the views as acquired (m).
    pub error_unregistered: f64,
    /// The model's registrations (the MAP) that failed (not accepted). Read as
    /// `failed_gpa` from older rows.
    #[serde(alias = "failed_gpa")]
    pub failed_map: usize,
    /// Sequential-ICP registrations that failed.
    pub failed_icp: usize,
    /// Per object: (name, GPA alignment, ICP alignment, GPA failed, ICP failed).
    pub registrations: Vec<ObjectRegistrationRow>,
    /// Mean coverage of the matched objects after 0, 1, … short-range views (an object
    /// that stopped keeps its last value); empty in older rows.
    #[serde(default)]
    pub coverage_by_view: Vec<f64>,
    /// Joint-space length (rad) of the planned paths to the views (0 in older rows).
    #[serde(default)]
    pub joint_distance: f64,
    /// Next-best-view scoring time per view (s; 0 in older rows).
    #[serde(default)]
    pub nbv_time_per_view: f64,
    /// Views that raised their object's coverage by less than 0.5 point, all objects.
    #[serde(default)]
    pub wasted_views: usize,
    /// The most views an object took after its coverage last rose by 0.5 point.
    #[serde(default)]
    pub views_after_rise_max: usize,
    /// Mean ground-truth ceiling of the matched objects (0 without the oracle).
    #[serde(default)]
    pub ceiling: f64,
    /// Smallest coverage / ceiling over the matched objects (0 without the oracle).
    #[serde(default)]
    pub coverage_of_ceiling: f64,
    /// Mean coverage / ceiling (0 without the oracle).
    #[serde(default)]
    pub coverage_of_ceiling_mean: f64,
    /// Objects that never reached 95 % of their ceiling (0 without the oracle).
    #[serde(default)]
    pub below_95: usize,
    /// Mean views the objects that reached 95 % of their ceiling took to it.
    #[serde(default)]
    pub views_to_95: f64,
    /// Mean greedy views to 95 % of the ceiling (the oracle's).
    #[serde(default)]
    pub oracle_views_to_95: f64,
    /// Largest ratio, over the objects that reached 95 % of their ceiling, of their views
    /// to it and the oracle's (at least one view counted for the oracle).
    #[serde(default)]
    pub views_to_95_ratio_max: f64,
    /// Mean greedy curve of the matched objects after 0, 1, … views (empty without the
    /// oracle).
    #[serde(default)]
    pub greedy_by_view: Vec<f64>,
    /// Wall time of the episode (s); the only column that differs between identical runs.
    pub time_s: f64,
}

/// One object's registration outcome in an episode.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ObjectRegistrationRow {
    /// Object name.
    pub object: String,
    /// The model's registration (MAP): mean alignment error (m).
    #[serde(alias = "gpa")]
    pub map: f64,
    /// Sequential-ICP mean alignment error (m); `None` when the episode ran without the
    /// baselines (`registration.baselines = false`).
    #[serde(default)]
    pub icp: Option<f64>,
    /// The model's registration failed.
    #[serde(alias = "gpa_failed")]
    pub map_failed: bool,
    /// Sequential ICP failed.
    pub icp_failed: bool,
    /// The error level of the episode (`errors.scale`, 1 unless swept).
    #[serde(default = "one")]
    pub level: f64,
    /// Mean alignment error of the views as acquired (m).
    #[serde(default)]
    pub acquired: f64,
    /// The paper's p-ICP-GPA: mean alignment error (m); `None` without the baselines.
    #[serde(default)]
    pub pgpa: Option<f64>,
    /// The paper's p-ICP-GPA failed.
    #[serde(default)]
    pub pgpa_failed: bool,
    /// The model's registration converged.
    #[serde(default)]
    pub converged: bool,
    /// The model's F-score.
    #[serde(default)]
    pub f_score: f64,
    /// The F-score of the views as acquired.
    #[serde(default)]
    pub f_score_acquired: f64,
}

fn one() -> f64 {
    1.0
}

fn mean(v: &[f64]) -> f64 {
    if v.is_empty() {
        0.0
    } else {
        v.iter().sum::<f64>() / v.len() as f64
    }
}

fn std_dev(v: &[f64]) -> f64 {
    let m = mean(v);
    mean(&v.iter().map(|x| (x - m).powi(2)).collect::<Vec<_>>()).sqrt()
}

impl EpisodeRow {
    /// The row of an episode from its report.
    pub fn new(episode: &Episode, report: &ExploreReport, time_s: f64) -> Self {
        let objects = &report.objects;
        let cov: Vec<f64> = objects.iter().filter_map(|o| o.coverage).collect();
        let mid: Vec<f64> = objects
            .iter()
            .filter_map(|o| o.coverage_mid_range)
            .collect();
        let views: usize = objects.iter().map(|o| o.views.len()).sum();
        let per_object_views = views as f64 / objects.len().max(1) as f64;
        let alignment = |pick: &dyn Fn(&crate::report::ObjectEntry) -> Option<f64>| {
            mean(&objects.iter().filter_map(pick).collect::<Vec<_>>())
        };
        let level = episode
            .params
            .iter()
            .find(|(k, _)| k == "errors.scale")
            .and_then(|(_, v)| v.as_float().or_else(|| v.as_integer().map(|i| i as f64)))
            .unwrap_or(1.0);
        let registrations = objects
            .iter()
            .filter(|o| o.truth == "object")
            .filter_map(|o| {
                // The baselines are absent when the episode skipped them.
                let (g, a) = (o.error_map.as_ref()?, o.error_unregistered.as_ref()?);
                let (i, p) = (o.error_icp.as_ref(), o.error_pgpa.as_ref());
                Some(ObjectRegistrationRow {
                    object: o.name.clone(),
                    map: g.alignment,
                    icp: i.map(|i| i.alignment),
                    map_failed: g.failed,
                    icp_failed: i.is_some_and(|i| i.failed),
                    level,
                    acquired: a.alignment,
                    pgpa: p.map(|p| p.alignment),
                    pgpa_failed: p.is_some_and(|p| p.failed),
                    converged: g.converged,
                    f_score: o.quality.map_or(0.0, |q| q.f_score),
                    f_score_acquired: o.quality_unregistered.map_or(0.0, |q| q.f_score),
                })
            })
            .collect::<Vec<_>>();
        let (coverage, coverage_mid_range) = (mean(&cov), mean(&mid));
        let quality = |pick: &dyn Fn(&crate::report::ObjectEntry) -> Option<f64>| {
            objects.iter().filter_map(pick).collect::<Vec<_>>()
        };
        let f_scores = quality(&|o| o.quality.map(|q| q.f_score));
        Self {
            index: episode.index,
            id: episode.id.clone(),
            scene: episode.scene.label(),
            mode: episode.mode.name().to_string(),
            seed: report.seed,
            params: episode
                .params
                .iter()
                .map(|(k, v)| (k.clone(), v.to_string()))
                .collect(),
            objects: objects
                .iter()
                .filter(|o| o.truth == "object")
                .map(|o| o.name.as_str())
                .collect::<std::collections::BTreeSet<_>>()
                .len()
                + report.missed_objects.len(),
            missed: report.missed_objects.len(),
            split: report.split_objects.len(),
            phantoms: report.phantom_clusters,
            dropped: report.dropped_clusters + report.phase_one.slivers.len(),
            level,
            views,
            failed_viewpoints: report.totals.failed_viewpoints,
            collisions: report.totals.collisions,
            f_score: mean(&f_scores),
            f_score_min: f_scores.iter().copied().reduce(f64::min).unwrap_or(0.0),
            f_score_unregistered: mean(&quality(&|o| o.quality_unregistered.map(|q| q.f_score))),
            chamfer: mean(&quality(&|o| o.quality.map(|q| q.chamfer))),
            mesh_f_score_2mm: mean(&quality(&|o| {
                o.mesh_quality.as_ref().map(|m| m.scores.f_score[0])
            })),
            mesh_f_score_5mm: mean(&quality(&|o| {
                o.mesh_quality.as_ref().map(|m| m.scores.f_score[1])
            })),
            mesh_chamfer: mean(&quality(&|o| {
                o.mesh_quality.as_ref().map(|m| m.scores.chamfer)
            })),
            coverage,
            coverage_min: cov.iter().copied().fold(f64::INFINITY, f64::min).min(1.0),
            precision: mean(&quality(&|o| o.quality.map(|q| q.precision))),
            coverage_mid_range,
            coverage_gain_per_view: if per_object_views > 0.0 {
                (coverage - coverage_mid_range) / per_object_views
            } else {
                0.0
            },
            error_map: alignment(&|o| o.error_map.as_ref().map(|e| e.alignment)),
            error_icp: alignment(&|o| o.error_icp.as_ref().map(|e| e.alignment)),
            error_unregistered: alignment(&|o| o.error_unregistered.as_ref().map(|e| e.alignment)),
            failed_map: registrations.iter().filter(|r| r.map_failed).count(),
            failed_icp: registrations.iter().filter(|r| r.icp_failed).count(),
            registrations,
            coverage_by_view: mean_curve(
                objects
                    .iter()
                    .filter(|o| !o.coverage_by_view.is_empty())
                    .map(|o| o.coverage_by_view.as_slice()),
            ),
            joint_distance: report.totals.joint_distance,
            nbv_time_per_view: if views > 0 {
                report.totals.times.nbv() / views as f64
            } else {
                0.0
            },
            wasted_views: report.totals.wasted_views,
            views_after_rise_max: objects
                .iter()
                .map(|o| o.views_after_last_rise)
                .max()
                .unwrap_or(0),
            ceiling: mean(&quality(&|o| o.oracle.as_ref().map(|e| e.ceiling))),
            coverage_of_ceiling: report.totals.min_coverage_of_ceiling.unwrap_or(0.0),
            coverage_of_ceiling_mean: report.totals.mean_coverage_of_ceiling.unwrap_or(0.0),
            below_95: objects
                .iter()
                .filter(|o| o.oracle.as_ref().is_some_and(|e| e.views_to_95.is_none()))
                .count(),
            views_to_95: mean(&quality(&|o| {
                o.oracle
                    .as_ref()
                    .and_then(|e| e.views_to_95.map(|v| v as f64))
            })),
            oracle_views_to_95: mean(&quality(&|o| {
                o.oracle.as_ref().map(|e| e.oracle_views_to_95 as f64)
            })),
            views_to_95_ratio_max: quality(&|o| {
                let e = o.oracle.as_ref()?;
                Some(e.views_to_95? as f64 / e.oracle_views_to_95.max(1) as f64)
            })
            .into_iter()
            .fold(0.0, f64::max),
            greedy_by_view: mean_curve(
                objects
                    .iter()
                    .filter_map(|o| o.oracle.as_ref().map(|e| e.greedy.as_slice())),
            ),
            time_s,
        }
    }

    /// Reads a row file.
    pub fn load(path: &Path) -> Result<Self> {
        let text =
            std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
        serde_json::from_str(&text)
            .with_context(|| format!("{}: not an episode row", path.display()))
    }
}

/// The pointwise mean of curves of different lengths, each carried forward at its last
/// value (empty without a curve).
///
/// ```
/// let m = nbv_sweep::rows::mean_curve([&[0.2, 0.6][..], &[0.4, 0.5, 0.9][..]]);
/// assert_eq!(m, vec![0.30000000000000004, 0.55, 0.75]);
/// ```
pub fn mean_curve<'a>(curves: impl IntoIterator<Item = &'a [f64]>) -> Vec<f64> {
    let curves: Vec<&[f64]> = curves.into_iter().filter(|c| !c.is_empty()).collect();
    let len = curves.iter().map(|c| c.len()).max().unwrap_or(0);
    (0..len)
        .map(|k| {
            let at = |c: &&[f64]| c.get(k).or(c.last()).copied().unwrap_or(0.0);
            curves.iter().map(at).sum::<f64>() / curves.len() as f64
        })
        .collect()
}

/// The CSV columns after the parameters (`time_s` last).
const METRICS: [&str; 38] = [
    "objects",
    "missed",
    "split",
    "phantoms",
    "dropped",
    "level",
    "views",
    "failed_viewpoints",
    "collisions",
    "f_score",
    "f_score_min",
    "f_score_unregistered",
    "chamfer",
    "mesh_f_score_2mm",
    "mesh_f_score_5mm",
    "mesh_chamfer",
    "precision",
    "coverage",
    "coverage_min",
    "coverage_mid_range",
    "coverage_gain_per_view",
    "error_map",
    "error_icp",
    "error_unregistered",
    "failed_map",
    "failed_icp",
    "joint_distance",
    "wasted_views",
    "views_after_rise_max",
    "ceiling",
    "coverage_of_ceiling",
    "coverage_of_ceiling_mean",
    "below_95",
    "views_to_95",
    "oracle_views_to_95",
    "views_to_95_ratio_max",
    "nbv_time_per_view",
    "time_s",
];

/// `results.csv`: a header and one row per episode, by index.
pub fn csv_text(rows: &[EpisodeRow]) -> Result<String> {
    let keys: Vec<String> = rows
        .first()
        .map(|r| r.params.iter().map(|(k, _)| k.clone()).collect())
        .unwrap_or_default();
    let mut w = csv::Writer::from_writer(Vec::new());
    let mut header = vec!["index", "id", "scene", "mode", "seed"];
    header.extend(keys.iter().map(String::as_str));
    header.extend(METRICS);
    w.write_record(&header)?;
    for r in rows {
        let mut rec = vec![
            r.index.to_string(),
            r.id.clone(),
            r.scene.clone(),
            r.mode.clone(),
            r.seed.to_string(),
        ];
        rec.extend(r.params.iter().map(|(_, v)| v.clone()));
        rec.extend([
            r.objects.to_string(),
            r.missed.to_string(),
            r.split.to_string(),
            r.phantoms.to_string(),
            r.dropped.to_string(),
            r.level.to_string(),
            r.views.to_string(),
            r.failed_viewpoints.to_string(),
            r.collisions.to_string(),
            format!("{:.6}", r.f_score),
            format!("{:.6}", r.f_score_min),
            format!("{:.6}", r.f_score_unregistered),
            format!("{:.6}", r.chamfer),
            format!("{:.6}", r.mesh_f_score_2mm),
            format!("{:.6}", r.mesh_f_score_5mm),
            format!("{:.6}", r.mesh_chamfer),
            format!("{:.6}", r.precision),
            format!("{:.6}", r.coverage),
            format!("{:.6}", r.coverage_min),
            format!("{:.6}", r.coverage_mid_range),
            format!("{:.6}", r.coverage_gain_per_view),
            format!("{:.6}", r.error_map),
            format!("{:.6}", r.error_icp),
            format!("{:.6}", r.error_unregistered),
            r.failed_map.to_string(),
            r.failed_icp.to_string(),
            format!("{:.6}", r.joint_distance),
            r.wasted_views.to_string(),
            r.views_after_rise_max.to_string(),
            format!("{:.6}", r.ceiling),
            format!("{:.6}", r.coverage_of_ceiling),
            format!("{:.6}", r.coverage_of_ceiling_mean),
            r.below_95.to_string(),
            format!("{:.6}", r.views_to_95),
            format!("{:.6}", r.oracle_views_to_95),
            format!("{:.6}", r.views_to_95_ratio_max),
            format!("{:.6}", r.nbv_time_per_view),
            format!("{:.3}", r.time_s),
        ]);
        w.write_record(&rec)?;
    }
    let bytes = w
        .into_inner()
        .map_err(|e| crate::error::invalid!("csv: {e}"))?;
    Ok(String::from_utf8(bytes)?)
}

/// Aggregates over all episodes (the metrics `--require` can gate on).
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct Aggregate {
    /// Smallest per-episode mean F-score.
    pub f_score: f64,
    /// Mean of the per-episode mean F-scores.
    pub f_score_mean: f64,
    /// Mean of the per-episode mean F-scores of the views as acquired.
    pub f_score_unregistered_mean: f64,
    /// Mean of the per-episode mean F-scores of the fused surfaces at 5 mm.
    pub mesh_f_score_5mm_mean: f64,
    /// Smallest per-episode mean coverage.
    pub coverage: f64,
    /// Mean of the per-episode mean coverages.
    pub coverage_mean: f64,
    /// Collisions in truth, all episodes.
    pub collisions: usize,
    /// Views, all episodes.
    pub views: usize,
    /// Failed p-ICP-GPA registrations, all episodes.
    pub failed_registrations: usize,
    /// Largest per-episode mean alignment error of the model's registration (m).
    pub error_map: f64,
    /// Mean per-episode alignment error of the model's registration (m).
    pub error_map_mean: f64,
    /// Mean per-episode sequential-ICP alignment error (m).
    pub error_icp_mean: f64,
    /// Scene objects no cluster matched, all episodes.
    pub missed: usize,
    /// Objects split into several explored clusters, over all episodes.
    pub split: usize,
    /// Phantom clusters explored, over all episodes.
    pub phantoms: usize,
    /// Episodes per hour at the measured episode times (one job).
    pub episodes_per_hour: f64,
    /// Mean short-range views per object.
    pub views_per_object: f64,
    /// Views that added less than 0.5 point of coverage, all episodes.
    pub wasted_views: usize,
    /// The most views an object took after its coverage last rose by 0.5 point.
    pub views_after_rise: usize,
    /// Smallest coverage / ceiling of an object (with the oracle; 0 without).
    pub coverage_of_ceiling: f64,
    /// Mean of the per-episode mean coverage / ceiling.
    pub coverage_of_ceiling_mean: f64,
    /// Objects that never reached 95 % of their ceiling, all episodes.
    pub below_95: usize,
    /// Largest ratio of an object's views to 95 % of its ceiling to the oracle's.
    pub views_to_95_ratio: f64,
}

impl Aggregate {
    /// The aggregate of `rows`.
    pub fn of(rows: &[EpisodeRow]) -> Self {
        let cov: Vec<f64> = rows.iter().map(|r| r.coverage).collect();
        let f: Vec<f64> = rows.iter().map(|r| r.f_score).collect();
        let gpa: Vec<f64> = rows.iter().map(|r| r.error_map).collect();
        let time: f64 = rows.iter().map(|r| r.time_s).sum();
        Self {
            // No episode: a gate on the F-score then fails.
            f_score: if f.is_empty() {
                0.0
            } else {
                f.iter().copied().fold(f64::INFINITY, f64::min)
            },
            f_score_mean: mean(&f),
            f_score_unregistered_mean: mean(
                &rows
                    .iter()
                    .map(|r| r.f_score_unregistered)
                    .collect::<Vec<_>>(),
            ),
            mesh_f_score_5mm_mean: mean(
                &rows.iter().map(|r| r.mesh_f_score_5mm).collect::<Vec<_>>(),
            ),
            // No episode covers nothing: a gate on coverage then fails.
            coverage: if cov.is_empty() {
                0.0
            } else {
                cov.iter().copied().fold(f64::INFINITY, f64::min)
            },
            coverage_mean: mean(&cov),
            collisions: rows.iter().map(|r| r.collisions).sum(),
            views: rows.iter().map(|r| r.views).sum(),
            failed_registrations: rows.iter().map(|r| r.failed_map).sum(),
            error_map: gpa.iter().copied().fold(0.0, f64::max),
            error_map_mean: mean(&gpa),
            error_icp_mean: mean(&rows.iter().map(|r| r.error_icp).collect::<Vec<_>>()),
            missed: rows.iter().map(|r| r.missed).sum(),
            split: rows.iter().map(|r| r.split).sum(),
            phantoms: rows.iter().map(|r| r.phantoms).sum(),
            episodes_per_hour: if time > 0.0 {
                3600.0 * rows.len() as f64 / time
            } else {
                0.0
            },
            views_per_object: {
                let objects: usize = rows.iter().map(|r| r.objects).sum();
                let views: usize = rows.iter().map(|r| r.views).sum();
                views as f64 / objects.max(1) as f64
            },
            wasted_views: rows.iter().map(|r| r.wasted_views).sum(),
            views_after_rise: rows
                .iter()
                .map(|r| r.views_after_rise_max)
                .max()
                .unwrap_or(0),
            coverage_of_ceiling: rows
                .iter()
                .map(|r| r.coverage_of_ceiling)
                .reduce(f64::min)
                .unwrap_or(0.0),
            coverage_of_ceiling_mean: mean(
                &rows
                    .iter()
                    .map(|r| r.coverage_of_ceiling_mean)
                    .collect::<Vec<_>>(),
            ),
            below_95: rows.iter().map(|r| r.below_95).sum(),
            views_to_95_ratio: rows
                .iter()
                .map(|r| r.views_to_95_ratio_max)
                .fold(0.0, f64::max),
        }
    }

    /// A gateable metric by name.
    pub fn metric(&self, name: &str) -> Option<f64> {
        Some(match name {
            "f_score" => self.f_score,
            "f_score_mean" => self.f_score_mean,
            "f_score_unregistered_mean" => self.f_score_unregistered_mean,
            "mesh_f_score_5mm_mean" => self.mesh_f_score_5mm_mean,
            "coverage" => self.coverage,
            "coverage_mean" => self.coverage_mean,
            "collisions" => self.collisions as f64,
            "views" => self.views as f64,
            "failed_registrations" => self.failed_registrations as f64,
            // `error_gpa*`: the names older CI scripts gate on.
            "error_map" | "error_gpa" => self.error_map,
            "error_map_mean" | "error_gpa_mean" => self.error_map_mean,
            "error_icp_mean" => self.error_icp_mean,
            "missed" => self.missed as f64,
            "split" => self.split as f64,
            "phantoms" => self.phantoms as f64,
            "views_per_object" => self.views_per_object,
            "wasted_views" => self.wasted_views as f64,
            "views_after_rise" => self.views_after_rise as f64,
            "coverage_of_ceiling" => self.coverage_of_ceiling,
            "coverage_of_ceiling_mean" => self.coverage_of_ceiling_mean,
            "below_95" => self.below_95 as f64,
            "views_to_95_ratio" => self.views_to_95_ratio,
            _ => return None,
        })
    }

    /// The names [`metric`](Self::metric) knows.
    pub const METRICS: [&'static str; 22] = [
        "f_score",
        "f_score_mean",
        "f_score_unregistered_mean",
        "mesh_f_score_5mm_mean",
        "coverage",
        "coverage_mean",
        "collisions",
        "views",
        "failed_registrations",
        "error_map",
        "error_map_mean",
        "error_icp_mean",
        "missed",
        "split",
        "phantoms",
        "views_per_object",
        "wasted_views",
        "views_after_rise",
        "coverage_of_ceiling",
        "coverage_of_ceiling_mean",
        "below_95",
        "views_to_95_ratio",
    ];
}

/// A parameter setting and its mean metric over the episodes that used it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BestSetting {
    /// Mode and parameter values.
    pub setting: BTreeMap<String, String>,
    /// Mean of the metric over the setting's episodes (all scenes and seeds).
    pub value: f64,
    /// Episodes averaged.
    pub episodes: usize,
}

/// The setting (mode + parameters) with the best mean of `metric`.
pub fn best_setting(
    rows: &[EpisodeRow],
    metric: impl Fn(&EpisodeRow) -> f64,
    larger_is_better: bool,
) -> Option<BestSetting> {
    let mut groups: BTreeMap<Vec<(String, String)>, Vec<f64>> = BTreeMap::new();
    for r in rows {
        let mut key = vec![("mode".to_string(), r.mode.clone())];
        key.extend(r.params.iter().cloned());
        groups.entry(key).or_default().push(metric(r));
    }
    groups
        .into_iter()
        .map(|(k, v)| BestSetting {
            setting: k.into_iter().collect(),
            value: mean(&v),
            episodes: v.len(),
        })
        .reduce(|a, b| {
            let better = if larger_is_better {
                b.value > a.value
            } else {
                b.value < a.value
            };
            if better { b } else { a }
        })
}

/// One object's line of the registration table (Table III).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RegistrationLine {
    /// Error level (`errors.scale`).
    pub level: f64,
    /// Object name.
    pub object: String,
    /// Registrations (episodes that registered it).
    pub experiments: usize,
    /// The model's registration (the MAP): mean and standard deviation of the alignment
    /// error (m).
    pub map: (f64, f64),
    /// Sequential ICP mean and standard deviation (m); `None` when no episode ran it.
    pub icp: Option<(f64, f64)>,
    /// The model's registration's failures.
    pub map_failures: usize,
    /// Sequential-ICP failures.
    pub icp_failures: usize,
    /// Median and 95th percentile of the alignment error as acquired (m).
    pub acquired_quantiles: (f64, f64),
    /// … of the model's registration (MAP).
    pub map_quantiles: (f64, f64),
    /// … of the paper's p-ICP-GPA (`None` when no episode ran the baselines).
    pub pgpa_quantiles: Option<(f64, f64)>,
    /// … of sequential ICP.
    pub icp_quantiles: Option<(f64, f64)>,
    /// The paper's p-ICP-GPA failures.
    pub pgpa_failures: usize,
    /// The model's registrations that did not converge.
    pub unconverged: usize,
    /// The model's registrations that end worse than as acquired by more than 0.5 mm.
    pub worse_than_acquired: usize,
    /// Median F-score of the views as acquired and of the model.
    pub f_score_medians: (f64, f64),
}

/// One error level of a robustness sweep: what phase 1 made of the scenes' objects and
/// how good the models are, over every episode at that level.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RobustnessLine {
    /// The error level (`errors.scale`).
    pub level: f64,
    /// Episodes.
    pub episodes: usize,
    /// Scene objects over the episodes.
    pub objects: usize,
    /// Objects no cluster matched.
    pub missed: usize,
    /// Objects explored as several clusters.
    pub split: usize,
    /// Phantom clusters explored.
    pub phantoms: usize,
    /// Clusters dropped as not objects.
    pub dropped: usize,
    /// Collisions.
    pub collisions: usize,
    /// Per object: median and 5th percentile of the F-score of the views as acquired.
    pub f_score_acquired: (f64, f64),
    /// … of the model.
    pub f_score_model: (f64, f64),
}

/// The robustness table: per error level over every episode.
pub fn robustness_table(rows: &[EpisodeRow]) -> Vec<RobustnessLine> {
    let mut by: BTreeMap<i64, Vec<&EpisodeRow>> = BTreeMap::new();
    for r in rows {
        by.entry((r.level * 1000.0).round() as i64)
            .or_default()
            .push(r);
    }
    by.into_iter()
        .map(|(level, v)| {
            let per_object = |pick: fn(&ObjectRegistrationRow) -> f64| {
                let f = sorted(
                    &v.iter()
                        .flat_map(|r| r.registrations.iter().map(pick))
                        .collect::<Vec<_>>(),
                );
                (nearest_rank(&f, 0.5), nearest_rank(&f, 0.05))
            };
            RobustnessLine {
                level: level as f64 / 1000.0,
                episodes: v.len(),
                objects: v.iter().map(|r| r.objects).sum(),
                missed: v.iter().map(|r| r.missed).sum(),
                split: v.iter().map(|r| r.split).sum(),
                phantoms: v.iter().map(|r| r.phantoms).sum(),
                dropped: v.iter().map(|r| r.dropped).sum(),
                collisions: v.iter().map(|r| r.collisions).sum(),
                f_score_acquired: per_object(|o| o.f_score_acquired),
                f_score_model: per_object(|o| o.f_score),
            }
        })
        .collect()
}

/// Median and 95th percentile (nearest rank) of `v`.
pub(crate) fn quantiles(v: &[f64]) -> (f64, f64) {
    let s = sorted(v);
    (nearest_rank(&s, 0.5), nearest_rank(&s, 0.95))
}

fn sorted(v: &[f64]) -> Vec<f64> {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    s
}

/// The `q` quantile of sorted `s` by nearest rank (0 when empty).
fn nearest_rank(s: &[f64], q: f64) -> f64 {
    s.get(((q * s.len() as f64).ceil() as usize).saturating_sub(1))
        .copied()
        .unwrap_or(0.0)
}

/// Table III over the rows: per error level and object, over every episode that
/// registered it.
pub fn registration_table(rows: &[EpisodeRow]) -> Vec<RegistrationLine> {
    // Levels as integers in thousandths, so they order and group exactly.
    let mut by: BTreeMap<(i64, String), Vec<&ObjectRegistrationRow>> = BTreeMap::new();
    for r in rows {
        for o in &r.registrations {
            let level = (o.level * 1000.0).round() as i64;
            by.entry((level, o.object.clone())).or_default().push(o);
        }
    }
    by.into_iter()
        .map(|((level, object), v)| {
            let g: Vec<f64> = v.iter().map(|o| o.map).collect();
            let i: Vec<f64> = v.iter().filter_map(|o| o.icp).collect();
            let a: Vec<f64> = v.iter().map(|o| o.acquired).collect();
            let p: Vec<f64> = v.iter().filter_map(|o| o.pgpa).collect();
            let ran = |x: &[f64]| (!x.is_empty()).then(|| quantiles(x));
            let median = |pick: fn(&ObjectRegistrationRow) -> f64| {
                quantiles(&v.iter().map(|o| pick(o)).collect::<Vec<_>>()).0
            };
            RegistrationLine {
                f_score_medians: (median(|o| o.f_score_acquired), median(|o| o.f_score)),
                level: level as f64 / 1000.0,
                acquired_quantiles: quantiles(&a),
                map_quantiles: quantiles(&g),
                pgpa_quantiles: ran(&p),
                icp_quantiles: ran(&i),
                pgpa_failures: v.iter().filter(|o| o.pgpa_failed).count(),
                unconverged: v.iter().filter(|o| !o.converged).count(),
                worse_than_acquired: v.iter().filter(|o| o.map > o.acquired + 5e-4).count(),
                object,
                experiments: v.len(),
                map: (mean(&g), std_dev(&g)),
                icp: (!i.is_empty()).then(|| (mean(&i), std_dev(&i))),
                map_failures: v.iter().filter(|o| o.map_failed).count(),
                icp_failures: v.iter().filter(|o| o.icp_failed).count(),
            }
        })
        .collect()
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A row of made-up metrics.
    pub(crate) fn row(index: usize, alpha: &str, coverage: f64, gpa: f64) -> EpisodeRow {
        EpisodeRow {
            index,
            id: format!("{index:04}-0"),
            scene: "s".into(),
            mode: "hybrid".into(),
            seed: 1,
            params: vec![("nbv.alpha_u".into(), alpha.into())],
            objects: 1,
            missed: 0,
            split: 0,
            phantoms: 0,
            dropped: 0,
            level: 1.0,
            views: 2,
            failed_viewpoints: 0,
            collisions: 0,
            f_score: coverage - 0.1,
            f_score_min: coverage - 0.1,
            f_score_unregistered: coverage - 0.2,
            chamfer: 0.004,
            mesh_f_score_2mm: 0.7,
            mesh_f_score_5mm: 0.9,
            mesh_chamfer: 0.002,
            coverage,
            coverage_min: coverage,
            precision: 0.9,
            coverage_mid_range: 0.4,
            coverage_gain_per_view: (coverage - 0.4) / 2.0,
            error_map: gpa,
            error_icp: 2.0 * gpa,
            error_unregistered: gpa,
            failed_map: 0,
            failed_icp: 1,
            registrations: vec![ObjectRegistrationRow {
                object: "jug".into(),
                map: gpa,
                icp: Some(2.0 * gpa),
                map_failed: false,
                icp_failed: true,
                level: 1.0,
                acquired: 1.5 * gpa,
                pgpa: Some(3.0 * gpa),
                pgpa_failed: true,
                converged: true,
                f_score: coverage - 0.1,
                f_score_acquired: coverage - 0.2,
            }],
            coverage_by_view: vec![0.4, (0.4 + coverage) / 2.0, coverage],
            joint_distance: 3.0,
            nbv_time_per_view: 0.02,
            wasted_views: 1,
            views_after_rise_max: 1,
            ceiling: 0.95,
            coverage_of_ceiling: coverage / 0.95,
            coverage_of_ceiling_mean: coverage / 0.95,
            below_95: 0,
            views_to_95: 2.0,
            oracle_views_to_95: 1.0,
            views_to_95_ratio_max: 2.0,
            greedy_by_view: vec![0.4, 0.9, 0.95],
            time_s: 10.0,
        }
    }

    /// Rows written when the model's registration was named after p-ICP-GPA still load,
    /// and the gate still answers to the old metric names.
    #[test]
    fn rows_with_the_old_registration_names_still_load() {
        let r = row(0, "4", 0.9, 0.002);
        let old = serde_json::to_string(&r)
            .unwrap()
            .replace("\"error_map\"", "\"error_gpa\"")
            .replace("\"failed_map\"", "\"failed_gpa\"")
            .replace("\"map\"", "\"gpa\"")
            .replace("\"map_failed\"", "\"gpa_failed\"");
        assert!(
            old.contains("\"error_gpa\"") && old.contains("\"gpa_failed\""),
            "{old}"
        );
        let back: EpisodeRow = serde_json::from_str(&old).unwrap();
        assert_eq!(back, r);
        let a = Aggregate::of(&[r]);
        assert_eq!(a.metric("error_gpa"), a.metric("error_map"));
        assert_eq!(a.metric("error_gpa_mean"), Some(a.error_map_mean));
    }

    #[test]
    fn aggregates_best_and_table() {
        let rows = [
            row(0, "2.0", 0.8, 0.01),
            row(1, "2.0", 0.6, 0.02),
            row(2, "4.0", 0.9, 0.03),
        ];
        let a = Aggregate::of(&rows);
        assert_eq!(a.coverage, 0.6);
        assert_eq!(Aggregate::of(&[]).coverage, 0.0);
        assert!((a.f_score - 0.5).abs() < 1e-12);
        assert!((a.f_score_mean - 2.0 / 3.0).abs() < 1e-12);
        assert_eq!(Aggregate::of(&[]).f_score, 0.0);
        let best = best_setting(&rows, |r| r.f_score, true).unwrap();
        assert_eq!(
            (best.setting["nbv.alpha_u"].as_str(), best.episodes),
            ("4.0", 1)
        );
        assert!((a.coverage_mean - 2.3 / 3.0).abs() < 1e-12);
        assert_eq!(a.error_map, 0.03);
        assert_eq!(a.episodes_per_hour, 360.0);
        let best = best_setting(&rows, |r| r.coverage, true).unwrap();
        assert_eq!(best.setting["nbv.alpha_u"], "4.0");
        let best = best_setting(&rows, |r| r.error_map, false).unwrap();
        assert_eq!(
            (best.setting["nbv.alpha_u"].as_str(), best.episodes),
            ("2.0", 2)
        );
        let t = registration_table(&rows);
        assert_eq!(
            (t[0].experiments, t[0].map_failures, t[0].icp_failures),
            (3, 0, 3)
        );
        assert!((t[0].map.0 - 0.02).abs() < 1e-12);
        // Medians of F (0.7, 0.5, 0.8) and as acquired (0.6, 0.4, 0.7).
        assert!((t[0].f_score_medians.0 - 0.6).abs() < 1e-12);
        assert!((t[0].f_score_medians.1 - 0.7).abs() < 1e-12);
        let csv = csv_text(&rows).unwrap();
        assert!(csv.starts_with(
            "index,id,scene,mode,seed,nbv.alpha_u,objects,missed,split,phantoms,dropped,level,\
             views,failed_viewpoints,collisions,f_score,f_score_min,f_score_unregistered,chamfer,mesh_f_score_2mm,mesh_f_score_5mm,mesh_chamfer,precision,coverage,"
        ));
        assert_eq!(csv.lines().count(), 4);
        // One level: three objects, F per object as acquired (0.6, 0.4, 0.7), model
        // (0.7, 0.5, 0.8): medians and 5th percentiles.
        let r = robustness_table(&rows);
        assert_eq!(r.len(), 1);
        assert_eq!(
            (r[0].episodes, r[0].objects, r[0].missed, r[0].split),
            (3, 3, 0, 0)
        );
        let near = |a: (f64, f64), b: (f64, f64)| (a.0 - b.0).abs() + (a.1 - b.1).abs() < 1e-12;
        assert!(near(r[0].f_score_acquired, (0.6, 0.4)), "{:?}", r[0]);
        assert!(near(r[0].f_score_model, (0.7, 0.5)), "{:?}", r[0]);
        assert!(
            csv.lines()
                .all(|l| l.ends_with("time_s") || l.ends_with("10.000"))
        );
    }

    #[test]
    fn registration_table_without_the_baselines() {
        // Episodes run with `registration.baselines = false` have no p-ICP-GPA or ICP
        // figure: their registrations still make the table, the baselines show as absent.
        let mut rows = [row(0, "2.0", 0.8, 0.01), row(1, "2.0", 0.6, 0.03)];
        for r in &mut rows {
            for o in &mut r.registrations {
                (o.icp, o.pgpa, o.icp_failed, o.pgpa_failed) = (None, None, false, false);
            }
        }
        let t = registration_table(&rows);
        assert_eq!(t.len(), 1);
        assert_eq!((t[0].experiments, t[0].icp_failures), (2, 0));
        assert_eq!(
            (t[0].icp, t[0].icp_quantiles, t[0].pgpa_quantiles),
            (None, None, None)
        );
        assert_eq!(t[0].map_quantiles, (0.01, 0.03));
        // One episode with the baselines, one without: the baselines over the one.
        rows[1] = row(1, "2.0", 0.6, 0.03);
        let t = registration_table(&rows);
        assert_eq!(t[0].icp_quantiles, Some((0.06, 0.06)));
        let p = t[0].pgpa_quantiles.expect("one episode ran p-ICP-GPA");
        assert!((p.0 - 0.09).abs() < 1e-12 && (p.1 - 0.09).abs() < 1e-12);
    }
}
