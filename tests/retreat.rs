//! The retreat of the exploration (core/src/pipeline/exploration.rs): when no viewpoint of
//! an object can be planned to from where the arm stands, it goes back along the paths it
//! executed since phase 1 and samples again. With a tight planner budget it happens on
//! every paper-env1 object. (A natural case, paper-env1 at seed 4, retreated before the
//! twin's pose error became one per standstill and the laser sweep was aligned to the
//! workcell; it no longer does, and its test was removed.)
//!
//! The test asserts what a retreat means, not the counts.

mod common;

use serde_json::Value;
use std::path::Path;

/// Whether the object got a short-range view after its last retreat, from the report.
///
/// The report does not interleave views and retreats, but the pipeline's loop does tell:
/// a retreat happens only in a round where the stop rule did not fire (the latest gain was
/// above the threshold, or there was none yet) and fewer views than the cap were taken;
/// afterwards, without a new view, the gain and the view count stay the same, so the only
/// way out is "no viewpoint left". An object that stopped by its gain or its view cap was
/// therefore given a view after its last retreat; and `retreated` is reset only by a
/// view, so two retreats have a view between them.
fn viewed_after_a_retreat(o: &Value) -> bool {
    let retreats = o["retreats"].as_u64().unwrap();
    let stop = o["stop"].as_str().unwrap();
    retreats >= 2 || (retreats == 1 && stop != "no viewpoint left")
}

/// Explores paper-env1 with `extra` and asserts that an object retreated and got a view
/// after its last retreat, with no collision; the report.
fn retreats_then_views(dir: &Path, extra: &[&str]) -> Value {
    let mut args = vec!["--no-pictures"];
    args.extend_from_slice(extra);
    let r = common::explore("paper-env1", dir, &args);
    let objects = r["objects"].as_array().unwrap();
    let summary: Vec<String> = objects
        .iter()
        .map(|o| {
            format!(
                "{}: {} views, {} retreats, stop: {}",
                o["name"],
                o["views"].as_array().unwrap().len(),
                o["retreats"],
                o["stop"]
            )
        })
        .collect();
    assert_eq!(r["totals"]["collisions"], 0, "{summary:#?}");
    let after: Vec<&Value> = objects
        .iter()
        .filter(|o| viewed_after_a_retreat(o))
        .collect();
    assert!(
        !after.is_empty(),
        "no object retreated and then got a view: {summary:#?}"
    );
    for o in after {
        // The viewpoints that failed before the retreat are reported, and the view after
        // it counts them (failures are reset only by a view).
        assert!(
            !o["viewpoints_failed"].as_array().unwrap().is_empty(),
            "{o:#}"
        );
        assert!(
            o["views"]
                .as_array()
                .unwrap()
                .iter()
                .any(|v| v["failures_before"].as_u64().unwrap() > 0),
            "{o:#}"
        );
        assert!(o["coverage"].as_f64().unwrap() > o["coverage_mid_range"].as_f64().unwrap());
    }
    r
}

/// A planner with a small budget (100 RRT iterations instead of 4000, at OpenRAVE's
/// 0.04 rad step instead of 0.2) fails from where
/// the arm stands after a view more often, so retreats are common — at the scene's seed,
/// four, on every object — and the test does not rest on one near-tie of one episode.
/// From the pose after the sweep the same budget plans again, which is what the retreat is
/// for.
#[test]
fn a_tight_planner_budget_retreats_on_several_objects() {
    let dir = tempfile::tempdir().unwrap();
    let r = retreats_then_views(
        &dir.path().join("run"),
        // The baselines (p-ICP-GPA, ICP) run after the exploration and tell nothing about a
        // retreat: without them the episode takes a third of the time in the dev profile.
        // The views are ranked by eq. (4) as printed and stopped by the gain alone: the
        // object-surface score and the new-surface rule end objects in fewer views, before
        // this budget boxes the arm in; and every unknown voxel is an obstacle, as in the
        // paper (with the space above the objects free the arm is seldom boxed in).
        &[
            "--set",
            "planner.max_iterations=100",
            "--set",
            "planner.step_rad=0.04",
            "--set",
            "registration.baselines=false",
            "--set",
            "nbv.object_surface=false",
            "--set",
            "nbv.new_surface=0",
            "--set",
            "nbv.free_above_objects=false",
        ],
    );
    let retreated = r["objects"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|o| o["retreats"].as_u64().unwrap() >= 1)
        .count();
    assert!(retreated >= 2, "{retreated} object(s) retreated");
}
