//! The view-objective comparison of a sweep over `nbv.objective` (`summary.json`'s
//! `objectives`, `examples/sweeps/objectives.toml`): per objective, over all episodes and
//! per scene group (each paper scene, the generated scenes), the mean coverage after
//! 0, 1, … views, the views to reach 80 % and 90 %, final coverage and precision, the
//! joint-space distance travelled and the scoring time per view.

use crate::rows::{EpisodeRow, mean_curve};
use serde::Serialize;
use std::collections::BTreeMap;

/// The swept key this table reads.
pub const OBJECTIVE_KEY: &str = "nbv.objective";

/// One objective over one scene group.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ObjectiveLine {
    /// The objective's name.
    pub objective: String,
    /// `all`, a paper scene's name, or `generated`.
    pub scenes: String,
    /// Episodes.
    pub episodes: usize,
    /// Mean over episodes of the mean object coverage after k = 0, 1, … views per object
    /// (each curve carried forward at its last value).
    pub coverage_by_view: Vec<f64>,
    /// Mean, over the episodes whose mean object coverage reaches 80 %, of the views per
    /// object it took (`None` if none reached it).
    pub views_to_80: Option<f64>,
    /// Episodes that reached 80 %.
    pub reached_80: usize,
    /// The same for 90 %.
    pub views_to_90: Option<f64>,
    /// Episodes that reached 90 %.
    pub reached_90: usize,
    /// Mean final coverage.
    pub coverage: f64,
    /// Mean model precision.
    pub precision: f64,
    /// Mean F-score.
    pub f_score: f64,
    /// Mean short-range views per episode.
    pub views: f64,
    /// Mean joint-space distance travelled to the views per episode (rad).
    pub joint_distance: f64,
    /// Mean scoring time per view (s).
    pub nbv_time_per_view: f64,
    /// Collisions, all episodes.
    pub collisions: usize,
}

/// The first k at which `curve` reaches `level`.
///
/// ```
/// use nbv_sweep::objectives::views_to_reach;
/// assert_eq!(views_to_reach(&[0.5, 0.79, 0.85, 0.95], 0.8), Some(2));
/// assert_eq!(views_to_reach(&[0.5, 0.6], 0.8), None);
/// ```
pub fn views_to_reach(curve: &[f64], level: f64) -> Option<usize> {
    curve.iter().position(|&c| c >= level)
}

fn scene_group(scene: &str) -> String {
    if scene.starts_with("paper-") {
        scene.to_string()
    } else {
        "generated".into()
    }
}

fn line(objective: &str, scenes: &str, rows: &[&EpisodeRow]) -> ObjectiveLine {
    let n = rows.len().max(1) as f64;
    let mean = |pick: fn(&EpisodeRow) -> f64| rows.iter().map(|r| pick(r)).sum::<f64>() / n;
    let reach = |level: f64| {
        let ks: Vec<f64> = rows
            .iter()
            .filter_map(|r| views_to_reach(&r.coverage_by_view, level))
            .map(|k| k as f64)
            .collect();
        let m = (!ks.is_empty()).then(|| ks.iter().sum::<f64>() / ks.len() as f64);
        (m, ks.len())
    };
    let (views_to_80, reached_80) = reach(0.8);
    let (views_to_90, reached_90) = reach(0.9);
    ObjectiveLine {
        objective: objective.to_string(),
        scenes: scenes.to_string(),
        episodes: rows.len(),
        coverage_by_view: mean_curve(rows.iter().map(|r| r.coverage_by_view.as_slice())),
        views_to_80,
        reached_80,
        views_to_90,
        reached_90,
        coverage: mean(|r| r.coverage),
        precision: mean(|r| r.precision),
        f_score: mean(|r| r.f_score),
        views: mean(|r| r.views as f64),
        joint_distance: mean(|r| r.joint_distance),
        nbv_time_per_view: mean(|r| r.nbv_time_per_view),
        collisions: rows.iter().map(|r| r.collisions).sum(),
    }
}

/// The table: for each objective (in the order first met), its line over all episodes,
/// then one per scene group. Empty when `nbv.objective` is not swept.
pub fn objective_table(rows: &[EpisodeRow]) -> Vec<ObjectiveLine> {
    let mut order: Vec<String> = Vec::new();
    let mut by: BTreeMap<(String, String), Vec<&EpisodeRow>> = BTreeMap::new();
    for r in rows {
        let Some((_, o)) = r.params.iter().find(|(k, _)| k == OBJECTIVE_KEY) else {
            continue;
        };
        let o = o.trim_matches('"').to_string();
        if !order.contains(&o) {
            order.push(o.clone());
        }
        by.entry((o.clone(), "all".into())).or_default().push(r);
        by.entry((o, scene_group(&r.scene))).or_default().push(r);
    }
    let mut out = Vec::new();
    for o in &order {
        for ((obj, scenes), v) in &by {
            if obj == o && scenes == "all" {
                out.push(line(o, scenes, v));
            }
        }
        for ((obj, scenes), v) in &by {
            if obj == o && scenes != "all" {
                out.push(line(o, scenes, v));
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rows::tests::row;

    #[test]
    fn per_objective_and_scene_group() {
        let mut rows = vec![
            row(0, "4", 0.9, 0.001),
            row(1, "4", 0.7, 0.001),
            row(2, "4", 0.95, 0.001),
        ];
        for (r, (o, scene)) in rows.iter_mut().zip([
            ("\"paper\"", "paper-env1"),
            ("\"paper\"", "generated-1"),
            ("\"rear-side-entropy\"", "paper-env1"),
        ]) {
            r.params = vec![(OBJECTIVE_KEY.into(), o.into())];
            r.scene = scene.into();
        }
        let t = objective_table(&rows);
        let names: Vec<_> = t
            .iter()
            .map(|l| (l.objective.as_str(), l.scenes.as_str()))
            .collect();
        assert_eq!(
            names,
            vec![
                ("paper", "all"),
                ("paper", "generated"),
                ("paper", "paper-env1"),
                ("rear-side-entropy", "all"),
                ("rear-side-entropy", "paper-env1"),
            ]
        );
        // Curves [0.4, 0.65, 0.9] and [0.4, 0.55, 0.7]: 80 % reached by one, at 2 views.
        let paper = &t[0];
        assert_eq!(
            (paper.episodes, paper.reached_80, paper.views_to_80),
            (2, 1, Some(2.0))
        );
        assert_eq!((paper.reached_90, paper.views_to_90), (1, Some(2.0)));
        assert!((paper.coverage - 0.8).abs() < 1e-12);
        assert!((paper.coverage_by_view[1] - 0.6).abs() < 1e-12);
        assert!(objective_table(&rows[..0]).is_empty());
        let mut unswept = rows.clone();
        unswept[0].params.clear();
        assert_eq!(objective_table(&unswept[..1]).len(), 0);
    }
}
