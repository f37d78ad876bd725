//! Planning benchmarks on the synthetic table-top scene (the Comau robot, the table and
//! the wall as known obstacles, the reduced map's 8.9K obstacle voxels): one collision
//! check, a query from the raised home pose to the best viewpoint of the object, and a
//! query between two viewpoints on opposite sides of the object whose straight segment is
//! blocked (RRT-Connect and shortcutting at work).

#[path = "../tests/support/scene.rs"]
mod scene;

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use nbv_core::kinematics::Joints;
use nbv_core::nbv::{NextBestView, VisitedViews};
use nbv_core::planning::{CollisionWorld, MotionPlanner, PlannerConfig};

fn bench(c: &mut Criterion) {
    let (_, map, object) = scene::mapped_scene(1);
    let robot = scene::robot();
    let world = CollisionWorld::new(&robot, &scene::known_obstacles())
        .unwrap()
        .with_reduced_map(&map);
    let planner = MotionPlanner::new(world, PlannerConfig::default()).unwrap();
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
    let free: Vec<_> = candidates
        .iter()
        .filter_map(|c| {
            let q = c
                .viewpoint
                .solutions
                .iter()
                .map(|s| s.joints)
                .find(|q| !planner.world().in_collision(q))?;
            Some((c.viewpoint.sample, q))
        })
        .collect();
    let home = scene::home();
    let best_goals: Vec<Joints> = candidates[0]
        .viewpoint
        .solutions
        .iter()
        .map(|s| s.joints)
        .collect();
    // The first pair on opposite sides whose straight segment is blocked.
    let (a, b) = free
        .iter()
        .enumerate()
        .flat_map(|(i, x)| free[i + 1..].iter().map(move |y| (x, y)))
        .find(|((sa, qa), (sb, qb))| {
            sa.theta > 0.7
                && sb.theta > 0.7
                && (2.0..=4.3).contains(&(sa.phi - sb.phi).abs())
                && !planner.path_is_free(&[*qa, *qb])
        })
        .map(|((_, qa), (_, qb))| (*qa, *qb))
        .unwrap();
    for (name, start, goals) in [
        ("home_to_best_view", home, best_goals.clone()),
        ("around_the_object", a, vec![b]),
    ] {
        let p = planner.plan(&start, &goals, 1).unwrap();
        eprintln!(
            "{name}: {} voxels, {} iterations, {} nodes, {} collision checks, length {:.3} -> {:.3} rad, {} waypoints",
            planner.world().voxel_count(),
            p.stats.iterations,
            p.stats.nodes,
            p.stats.collision_checks,
            p.stats.length_before_shortcut,
            p.stats.length_after_shortcut,
            p.path.waypoints.len()
        );
    }

    let near = free[0].1;
    c.bench_function("planning/collision_check_home", |bch| {
        bch.iter(|| black_box(planner.world().in_collision(&home)))
    });
    c.bench_function("planning/collision_check_at_viewpoint", |bch| {
        bch.iter(|| black_box(planner.world().in_collision(&near)))
    });
    c.bench_function("planning/query_home_to_best_view", |bch| {
        bch.iter(|| black_box(planner.plan(&home, &best_goals, 1).unwrap()))
    });
    c.bench_function("planning/query_around_the_object", |bch| {
        bch.iter(|| black_box(planner.plan(&a, &[b], 1).unwrap()))
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
