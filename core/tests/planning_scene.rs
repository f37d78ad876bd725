//! The joint-space planner on the synthetic table-top scene: the Comau robot, the table
//! and the wall as known obstacles, and the 8.9K obstacle voxels of the reduced map after
//! the mid-range sweep. Every returned path is re-checked by an independent checker
//! (parry's compound broad phase over all voxels) at a five times finer resolution.

mod support;

use nalgebra::Point3;
use nbv_core::kinematics::{DOF, Joints};
use nbv_core::nbv::{Candidate, NextBestView, VisitedViews};
use nbv_core::occupancy::{OccupancyGrid, ReducedMap};
use nbv_core::planning::{
    CollisionTarget, CollisionWorld, MotionPlanner, PlannedPath, PlannerConfig, PlanningError,
};
use proptest::prelude::*;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use support::brute_force::BruteForce;
use support::scene;

/// Resolution (m) of the independent re-check (the planner's is 0.01 m).
const RECHECK: f64 = 0.002;

struct Fixture {
    grid: OccupancyGrid,
    map: ReducedMap,
    planner: MotionPlanner,
    brute: BruteForce,
    candidates: Vec<Candidate>,
}

fn fixture() -> Fixture {
    let (grid, map, object) = scene::mapped_scene(1);
    let robot = scene::robot();
    let world = CollisionWorld::new(&robot, &scene::known_obstacles())
        .unwrap()
        .with_reduced_map(&map);
    let planner = MotionPlanner::new(world, PlannerConfig::default()).unwrap();
    let brute = BruteForce::new(&robot, &scene::known_boxes(), Some(&map));
    let candidates = NextBestView::new(scene::paper_nbv(), &scene::dinast())
        .unwrap()
        .candidates_around(
            &robot,
            &map,
            &scene::centroid(&object),
            &VisitedViews::default(),
        )
        .unwrap()
        .candidates;
    Fixture {
        grid,
        map,
        planner,
        brute,
        candidates,
    }
}

/// Endpoints, limits, and an independent collision re-check of a planned path.
fn check_path(f: &Fixture, p: &PlannedPath, start: &Joints, goals: &[Joints]) {
    let w = &p.path.waypoints;
    assert!(w.len() >= 2);
    assert_eq!(w[0], *start);
    let goal = goals[p.goal_index];
    let end = w[w.len() - 1];
    // Joints wider than 2π may differ by whole turns.
    for k in 0..DOF {
        let turns = (end[k] - goal[k]) / std::f64::consts::TAU;
        assert!((turns - turns.round()).abs() < 1e-9 && (k >= 3 || turns.round() == 0.0));
    }
    let limits = f.planner.world().robot().limits();
    assert!(w.iter().all(|q| (0..DOF).all(|k| limits[k].contains(q[k]))));
    assert_eq!(f.brute.first_collision_on_path(w, RECHECK), None);
    assert!(p.stats.length_after_shortcut <= p.stats.length_before_shortcut + 1e-12);
}

fn goals_of(c: &Candidate) -> Vec<Joints> {
    c.viewpoint.solutions.iter().map(|s| s.joints).collect()
}

#[test]
fn queries_from_home_to_the_best_viewpoints() {
    let f = fixture();
    let home = scene::home();
    assert!(!f.brute.collides(&home));
    let mut ok = 0;
    for (i, c) in f.candidates.iter().take(12).enumerate() {
        let goals = goals_of(c);
        match f.planner.plan(&home, &goals, i as u64) {
            Ok(p) => {
                check_path(&f, &p, &home, &goals);
                ok += 1;
            }
            Err(PlanningError::NoGoalCollisionFree { in_collision, .. }) => {
                // Only when every IK solution collides, by the independent checker too.
                assert_eq!(in_collision, goals.len());
                assert!(goals.iter().all(|g| f.brute.collides(g)));
            }
            Err(e) => panic!("viewpoint {i}: {e}"),
        }
    }
    assert!(ok >= 8, "{ok} of 12");
}

/// Pairs of collision-free viewpoint configurations on opposite sides of the object whose
/// straight joint-space segment is blocked.
fn blocked_pairs(f: &Fixture, n: usize) -> Vec<(Joints, Joints)> {
    let free: Vec<_> = f
        .candidates
        .iter()
        .filter_map(|c| {
            let q = goals_of(c)
                .into_iter()
                .find(|q| !f.planner.world().in_collision(q))?;
            Some((c.viewpoint.sample, q))
        })
        .collect();
    let mut out = Vec::new();
    for (i, (a, qa)) in free.iter().enumerate() {
        for (b, qb) in &free[i + 1..] {
            let dphi = (a.phi - b.phi).abs();
            if a.theta > 0.7
                && b.theta > 0.7
                && (2.0..=4.3).contains(&dphi)
                && !f.planner.path_is_free(&[*qa, *qb])
            {
                out.push((*qa, *qb));
            }
            if out.len() == n {
                return out;
            }
        }
    }
    out
}

#[test]
fn queries_around_the_object_need_the_trees() {
    let f = fixture();
    let pairs = blocked_pairs(&f, 8);
    assert_eq!(pairs.len(), 8);
    let mut ok = 0;
    for (i, (a, b)) in pairs.iter().enumerate() {
        match f.planner.plan(a, &[*b], 100 + i as u64) {
            Ok(p) => {
                assert!(p.stats.iterations >= 1);
                check_path(&f, &p, a, &[*b]);
                ok += 1;
            }
            Err(e) => println!("pair {i}: {e}"),
        }
    }
    assert!(ok >= 7, "{ok} of 8");
}

#[test]
fn random_collision_free_pairs() {
    let f = fixture();
    let limits = *f.planner.world().robot().limits();
    let mut rng = ChaCha8Rng::seed_from_u64(2014);
    let mut configs = Vec::new();
    while configs.len() < 12 {
        let q = Joints::from_fn(|k, _| {
            let (lo, hi) = if k == 5 {
                (-std::f64::consts::PI, std::f64::consts::PI)
            } else {
                (limits[k].lower, limits[k].upper)
            };
            rng.random_range(lo..hi)
        });
        // The planner's world is padded by 5 mm: it reports a superset of the contacts.
        let colliding = f.planner.world().in_collision(&q);
        assert!(colliding || !f.brute.collides(&q), "{q:?}");
        if !colliding {
            configs.push(q);
        }
    }
    let mut ok = 0;
    for (i, pair) in configs.chunks(2).enumerate() {
        match f.planner.plan(&pair[0], &[pair[1]], i as u64) {
            Ok(p) => {
                check_path(&f, &p, &pair[0], &[pair[1]]);
                ok += 1;
            }
            Err(e) => println!("random pair {i}: {e}"),
        }
    }
    assert!(ok >= 5, "{ok} of 6");
}

#[test]
fn same_seed_same_path_whatever_the_threads() {
    let f = fixture();
    let (a, b) = blocked_pairs(&f, 1)[0];
    let plan = |threads| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| f.planner.plan(&a, &[b], 9))
            .unwrap()
    };
    let one = plan(1);
    assert_eq!(one, plan(2));
    assert_eq!(one, plan(1));
}

#[test]
fn goal_inside_the_table_and_tiny_budget() {
    let f = fixture();
    let home = scene::home();
    // The camera 10 cm under the table top, looking down.
    let inside =
        nbv_core::math::pose_from_xyz_rpy([0.8, -0.4, 0.15], [std::f64::consts::PI, 0.0, 0.0]);
    match f.planner.plan_to_pose(&home, "dinast", &inside, 0) {
        Err(PlanningError::NoGoalCollisionFree {
            goals,
            in_collision,
            first: Some(c),
            ..
        }) => {
            assert_eq!(in_collision, goals);
            assert_eq!(
                c.with,
                CollisionTarget::Obstacle {
                    name: "table".into()
                }
            );
        }
        other => panic!("{other:?}"),
    }
    let (a, b) = blocked_pairs(&f, 1)[0];
    let tiny = MotionPlanner::new(
        f.planner.world().clone(),
        // One short step: the trees stay next to the blocked segment and cannot meet.
        PlannerConfig {
            max_iterations: 1,
            step: 0.01,
            ..PlannerConfig::default()
        },
    )
    .unwrap();
    assert!(matches!(
        tiny.plan(&a, &[b], 0),
        Err(PlanningError::BudgetExhausted { iterations: 1, .. })
    ));
}

#[test]
fn start_enveloped_by_unknown_voxels() {
    let f = fixture();
    let best = goals_of(&f.candidates[0])
        .into_iter()
        .find(|q| !f.planner.world().in_collision(q))
        .unwrap();
    // Mark a 5×5×5 block of voxels around the camera window as unknown, inside seen free
    // space: its outer shell joins M̄ as crust and envelops the camera.
    let robot = f.planner.world().robot();
    let window = robot.fk(&best, "dinast").unwrap() * Point3::origin();
    let g = *f.grid.geometry();
    let centre = g.voxel_of(&window).unwrap();
    let mut values = f.grid.log_odds().to_vec();
    for dz in 0..5 {
        for dy in 0..5 {
            for dx in 0..5 {
                let v = [centre[0] + dx - 2, centre[1] + dy - 2, centre[2] + dz - 2];
                values[g.linear(v).unwrap()] = 0.0;
            }
        }
    }
    let grid = OccupancyGrid::from_log_odds(g, *f.grid.params(), values).unwrap();
    let map = ReducedMap::from_grid(&grid);
    let mut world = f.planner.world().clone();
    world.set_reduced_map(&map);
    let planner = MotionPlanner::new(world, PlannerConfig::default()).unwrap();
    let home = scene::home();
    let err = planner.plan(&best, &[home], 0).unwrap_err();
    let PlanningError::StartInCollision(c) = &err else {
        panic!("{err:?}");
    };
    assert!(c.is_voxel(), "{c}");
    assert!(err.to_string().contains("map voxel"));
    // The caller's choice: clear the voxels the arm sits in, and plan again.
    let mut world = planner.world().clone();
    let touching = world.colliding_voxels(&best);
    assert!(!touching.is_empty() && touching.iter().all(|&l| map.contains(l)));
    assert_eq!(world.ignore_voxels(&touching), touching.len());
    assert!(!world.in_collision(&best));
    let planner = MotionPlanner::new(world, PlannerConfig::default()).unwrap();
    let p = planner.plan(&best, &[home], 0).unwrap();
    assert_eq!(p.path.waypoints[0], best);
    assert!(planner.path_is_free(&p.path.waypoints));
    let _ = &f.map;
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// The planner's checker (bitset broad phase, bounding-sphere pruning, exact parry
    /// tests) agrees with the independent one at random configurations.
    #[test]
    fn collision_checker_agrees_with_the_independent_one(
        q in prop::array::uniform6(-1.0f64..1.0),
    ) {
        thread_local! {
            static F: (CollisionWorld, BruteForce) = {
                let (_, map, _) = scene::mapped_scene(1);
                let robot = scene::robot();
                (
                    CollisionWorld::new(&robot, &scene::known_obstacles()).unwrap().with_reduced_map(&map),
                    BruteForce::new(&robot, &scene::known_boxes(), Some(&map)),
                )
            };
        }
        F.with(|(world, brute)| {
            let limits = world.robot().limits();
            // Scale [-1, 1] onto each joint's range (J6 onto ±π).
            let q = Joints::from_fn(|k, _| {
                let (lo, hi) = if k == 5 { (-3.1, 3.1) } else { (limits[k].lower, limits[k].upper) };
                lo + (q[k] + 1.0) * 0.5 * (hi - lo)
            });
            prop_assert_eq!(world.in_collision(&q), brute.collides(&q));
            Ok(())
        })?;
    }
}
