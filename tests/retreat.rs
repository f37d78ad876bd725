//! The retreat of the exploration (core/src/pipeline/exploration.rs): when no viewpoint of
//! an object can be planned to from where the arm stands, it goes back along the paths it
//! executed since phase 1 and samples again. In paper-env1 at seed 4 the mallet's twelfth
//! view is reachable only that way (found with `nbv explore --scene paper-env1 --seed 4`:
//! seven viewpoints fail to plan from the eleventh view's pose, then the retreat, then
//! three more views, no collision. Seed 1, seed 4 with a cap of ten views per object, and
//! the short-only baseline at seed 4 do not retreat.)
//!
//! The numbers (views, gains) may move with the registration and the twin's error model;
//! the tests assert what a retreat means, not the counts. The second test, with a tight
//! planner budget (retreats on all three objects at the scene's seed), leans less on one
//! particular episode than the first.

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

/// The scene as it is, at seed 4: the mallet retreats once, then is viewed until its gain
/// falls below the threshold.
#[test]
fn paper_env1_seed_4_retreats_and_then_views_the_object() {
    let dir = tempfile::tempdir().unwrap();
    retreats_then_views(&dir.path().join("run"), &["--seed", "4"]);
}

/// A planner with a small budget (100 RRT iterations instead of 4000) fails from where
/// the arm stands after a view more often, so retreats are common — at the scene's seed,
/// four, on every object — and the test does not rest on one near-tie of one episode.
/// From the pose after the sweep the same budget plans again, which is what the retreat is
/// for.
#[test]
fn a_tight_planner_budget_retreats_on_several_objects() {
    let dir = tempfile::tempdir().unwrap();
    let r = retreats_then_views(
        &dir.path().join("run"),
        &["--set", "planner.max_iterations=100"],
    );
    let retreated = r["objects"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|o| o["retreats"].as_u64().unwrap() >= 1)
        .count();
    assert!(retreated >= 2, "{retreated} object(s) retreated");
}
