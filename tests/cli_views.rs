//! `nbv views` on both paper scenes: every object gets a non-empty list sorted by eq. (4)
//! whose best view sees unknown voxels; at least 95% of the planning queries to reachable
//! viewpoints succeed over the two scenes (≥ 100 queries with the paper's sphere) and no
//! planned path collides in truth (eq. (4) as printed: `nbv.object_surface = false`; the
//! twin's object-surface score ranks the same candidates, its scores are checked against
//! their bounds). Plus the errors for a bad object name.

mod common;

use common::{nbv, text};
use serde_json::Value;

fn views(scene: &str, extra: &[&str]) -> Vec<Value> {
    let mut args = vec!["views", "--scene", scene, "--json"];
    args.extend_from_slice(extra);
    let out = nbv(&args);
    assert!(out.status.success(), "{}", text(&out.stderr));
    serde_json::from_slice::<Value>(&out.stdout)
        .unwrap()
        .as_array()
        .unwrap()
        .clone()
}

#[test]
fn paper_scenes_give_sorted_lists_and_plans_that_hold_in_truth() {
    let (mut queries, mut planned, mut boxed_in) = (0, 0, 0);
    for scene in ["paper-env1", "paper-env2"] {
        // With every unknown voxel an obstacle, as in the paper, the arm reaches fewer.
        let paper_map = views(
            scene,
            &[
                "--no-plan",
                "--set",
                "nbv.object_surface=false",
                "--set",
                "nbv.free_above_objects=false",
            ],
        );
        boxed_in += paper_map
            .iter()
            .map(|o| o["candidates"].as_array().unwrap().len())
            .sum::<usize>();
        let objects = views(scene, &["--set", "nbv.object_surface=false"]);
        assert_eq!(objects.len(), 3, "{scene}");
        for o in &objects {
            let c = o["candidates"].as_array().unwrap();
            assert!(!c.is_empty(), "{scene} {}", o["name"]);
            assert!(
                c[0]["unknown"].as_u64().unwrap() > 0,
                "{scene} {}",
                o["name"]
            );
            let scores: Vec<f64> = c.iter().map(|c| c["score"].as_f64().unwrap()).collect();
            assert!(scores.windows(2).all(|w| w[0] >= w[1]), "{scores:?}");
            // Eq. (4) with the defaults (4, 1).
            for v in c {
                let s = 4.0 * v["unknown"].as_f64().unwrap() + v["occupied"].as_f64().unwrap();
                assert_eq!(v["score"].as_f64().unwrap(), s);
                assert_eq!(v["reachable"], true);
                queries += 1;
                if v["planned"] == true {
                    planned += 1;
                    assert_eq!(v["collision"], false, "{scene} {}: {v}", o["name"]);
                } else {
                    assert!(v["failure"].as_str().is_some_and(|f| !f.is_empty()));
                }
            }
        }
    }
    // 541 reachable candidates over the six objects on the twin's sphere with the unknown
    // space above the objects free for the planner (505 at r = 0.45 m, 36 more at the
    // near radius where 0.45 m is out of reach); 296 (265 and 31) with every unknown
    // voxel an obstacle.
    assert_eq!(queries, 541, "{queries} queries");
    assert_eq!(boxed_in, 296, "{boxed_in} candidates with the paper's map");
    assert!(
        planned as f64 >= 0.95 * queries as f64,
        "{planned} of {queries} planned"
    );
}

#[test]
fn table_output_and_bad_object() {
    let out = nbv(&[
        "views",
        "--scene",
        "paper-env1",
        "--object",
        "mallet",
        "--no-plan",
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let s = text(&out.stdout);
    assert!(s.starts_with("mallet: sphere centre"), "{s}");
    assert!(!s.contains("jug"), "{s}");
    let out = nbv(&["views", "--scene", "paper-env1", "--object", "teapot"]);
    assert_eq!(out.status.code(), Some(1));
    let e = text(&out.stderr);
    assert!(e.contains("teapot") && e.contains("jug, mallet"), "{e}");
}

#[test]
fn the_object_surface_score_counts_part_of_each_view() {
    // The twin's default: eq. (4) over the object's surface. Each counted voxel is a voxel
    // of O_v on the map the score sees (α_u for new surface, α_o for seen surface), so the
    // score lies between 0 and α_u·|O_v|; the list is sorted by it, and the best view of
    // each object sees some of it.
    for o in views("paper-env1", &[]) {
        let c = o["candidates"].as_array().unwrap();
        let scores: Vec<f64> = c.iter().map(|c| c["score"].as_f64().unwrap()).collect();
        assert!(scores.windows(2).all(|w| w[0] >= w[1]), "{scores:?}");
        assert!(scores[0] > 0.0, "{}", o["name"]);
        for v in c {
            let seen = v["unknown"].as_f64().unwrap() + v["occupied"].as_f64().unwrap();
            let s = v["score"].as_f64().unwrap();
            assert!((0.0..=4.0 * seen).contains(&s), "{}: {v}", o["name"]);
        }
    }
}

/// The hull score (`nbv.hull_score`) ranks the candidates by the unseen area of the
/// object's convex hull each would see. Against the truth (`--oracle`: each reachable
/// candidate cast without noise) on paper-env1, the first choice gains at least 0.7 of what
/// the truly best candidate gains over the laser, on average over the objects (1.0, 0.62,
/// 0.83 here; the twin's eq. (4) over the surface: 0.54, 0.46, 0.39), and the score's rank
/// correlation with the truth is at least 0.5 on average (0.76; eq. (4): 0.25).
#[test]
fn the_hull_score_chooses_nearly_the_best_first_view() {
    let objects = views(
        "paper-env1",
        &["--no-plan", "--oracle", "--set", "nbv.hull_score=always"],
    );
    assert_eq!(objects.len(), 3);
    let (mut share, mut rho) = (0.0, 0.0);
    for o in &objects {
        let t = &o["truth"];
        let get = |k: &str| t[k].as_f64().unwrap();
        let gain = get("best") - get("laser");
        assert!(gain > 0.1, "{}: {t}", o["name"]);
        share += (get("chosen") - get("laser")) / gain / 3.0;
        rho += get("spearman") / 3.0;
    }
    assert!(
        share >= 0.7,
        "first choice's share of the best gain {share:.2}"
    );
    assert!(rho >= 0.5, "Spearman {rho:.2}");
}
