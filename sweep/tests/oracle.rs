//! The oracle's coverage on a hand-made scene whose answer is worked out by hand: a
//! 10 cm cube on the paper-env1 table, seen noise-free from straight above and from one
//! side. Above the floor (5 mm over the table) the cube shows 0.048 m² (top 0.01, four
//! sides 0.1 × 0.095); a view of a face covers that face and, within the 1 cm tolerance,
//! a 1 cm band of each face beside it.

use nalgebra::Point3;
use nbv_core::math::Pose;
use nbv_core::mesh::TriMesh;
use nbv_core::nbv::view_pose;
use nbv_scenes::schema::{ObjectSpec, PoseSpec};
use nbv_sim::sensors::CameraModel;
use nbv_sim::world::TwinWorld;
use nbv_sweep::oracle::{SurfaceSamples, camera_points};
use std::f64::consts::FRAC_PI_2;

const HALF: f64 = 0.05;
const AT: [f64; 3] = [0.8, 0.0, 0.25];

fn cube_scene(dir: &std::path::Path) -> nbv_scenes::Scene {
    let mut cube = TriMesh::cuboid([HALF; 3]);
    cube.vertices.iter_mut().for_each(|p| p.z += HALF);
    let path = dir.join("cube.stl");
    nbv_core::mesh::io::write_stl_file(&cube, &path).unwrap();
    let mut scene = nbv_scenes::builtin::load("paper-env1").unwrap();
    scene.objects = vec![ObjectSpec {
        name: "cube".into(),
        mesh: path,
        pose: PoseSpec {
            xyz: AT,
            rpy_deg: [0.0; 3],
        },
    }];
    scene.validate().unwrap();
    scene
}

/// Shares of the cube's samples the views from `poses` cover, each alone and together.
fn shares(poses: &[Pose]) -> (Vec<f64>, f64) {
    let dir = tempfile::tempdir().unwrap();
    let scene = cube_scene(dir.path());
    let world = TwinWorld::from_scene(&scene).unwrap();
    let camera = CameraModel::from_scene(&scene.sensors.short_range);
    let mesh = &scene.object_meshes().unwrap()[0];
    let samples = SurfaceSamples::of(mesh, scene.table.top(), scene.seed).unwrap();
    let masks: Vec<Vec<bool>> = poses
        .iter()
        .map(|p| samples.covered_by(&camera_points(&world, &camera, None, p)))
        .collect();
    let n = samples.len() as f64;
    let alone = masks
        .iter()
        .map(|m| m.iter().filter(|&&c| c).count() as f64 / n)
        .collect();
    let union = (0..samples.len())
        .filter(|&k| masks.iter().any(|m| m[k]))
        .count() as f64
        / n;
    (alone, union)
}

#[test]
fn a_cube_seen_from_above_and_from_one_side() {
    let centre = Point3::new(AT[0], AT[1], AT[2] + HALF);
    // Straight above, 0.35 m over the top: the top face (0.01 m²) and a 1 cm band of each
    // side below its rim (4 × 0.001 m²); the table beside the cube is hidden by it for
    // 1.4 cm, so it covers none of the sides' lowest samples.
    let above = view_pose(&centre, 0.4, 0.0, 0.0);
    // From +y at mid height: the +y face (0.1 × 0.095), a 1 cm band of the top (0.001) and
    // of the ±x faces (2 × 0.00095); the table in front is beyond the grazing cut-off.
    let side = view_pose(&centre, 0.4, FRAC_PI_2, FRAC_PI_2);
    let (alone, union) = shares(&[above, side]);
    let area = 0.048;
    let expect_above = (0.01 + 0.004) / area;
    let expect_side = (0.0095 + 0.001 + 0.0019) / area;
    // Together: the top view's band of the +y face lies on that face (−0.001), and its
    // bands of the ±x faces meet the side view's in a 1 × 1 cm corner each (−2 × 0.0001).
    let expect_union = (0.01 + 0.004 + 0.0095 + 0.0019 - 0.001 - 0.0002) / area;
    for (got, want) in [
        (alone[0], expect_above),
        (alone[1], expect_side),
        (union, expect_union),
    ] {
        // Sampling (16,000 samples: σ ≈ 0.4 point) and the last pixel before an edge.
        assert!((got - want).abs() < 0.015, "{got:.4} against {want:.4}");
    }
}

#[test]
fn a_view_from_under_the_table_sees_nothing_of_the_cube() {
    let centre = Point3::new(AT[0], AT[1], AT[2] + HALF);
    // θ = 180°: straight below, looking up through the table top.
    let below = view_pose(&centre, 0.4, std::f64::consts::PI, 0.0);
    let (alone, _) = shares(&[below]);
    assert_eq!(alone[0], 0.0);
}

#[test]
fn nbv_views_measures_each_candidate_against_the_truth() {
    use nbv_sweep::views::{ViewsOptions, list_views};
    let dir = tempfile::tempdir().unwrap();
    let scene = cube_scene(dir.path());
    let options = ViewsOptions {
        object: Some("cube".into()),
        oracle: true,
        ..Default::default()
    };
    let objects = list_views(&scene, &options).unwrap();
    assert_eq!(objects.len(), 1);
    let o = &objects[0];
    let t = o.truth.as_ref().unwrap();
    let truths: Vec<f64> = o.candidates.iter().filter_map(|c| c.truth).collect();
    // Every reachable candidate is measured, and only those.
    assert_eq!(
        truths.len(),
        o.candidates.iter().filter(|c| c.reachable).count()
    );
    assert!(!truths.is_empty());
    // A view adds to the laser's coverage, never takes from it.
    assert!(t.laser > 0.2 && t.laser < 0.9, "laser {}", t.laser);
    assert!(truths.iter().all(|&v| v >= t.laser && v <= 1.0));
    let best = truths.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    assert_eq!(t.best, best);
    assert_eq!(truths[t.best_rank - 1], best);
    assert_eq!(t.chosen, truths[0]);
    assert!((-1.0..=1.0).contains(&t.spearman));
    // The laser sees the cube from the robot's side: some candidate sees a face it missed.
    assert!(
        best > t.laser + 0.1,
        "best {best} over the laser's {}",
        t.laser
    );
}

#[test]
fn a_stored_oracle_is_the_computed_one_and_keyed_by_what_it_reads() {
    use nbv_sweep::oracle::{DensePoses, OracleCache, OracleOptions, oracle};
    let dir = tempfile::tempdir().unwrap();
    let scene = cube_scene(dir.path());
    let dense = DensePoses {
        radii: vec![0.45],
        delta_theta_deg: 30.0,
        theta_max_deg: 60.0,
        delta_phi_deg: 60.0,
        rolls: 1,
    };
    // One view an exploration took, with the arm's joints there.
    let world = TwinWorld::from_scene(&scene).unwrap();
    let camera = CameraModel::from_scene(&scene.sensors.short_range);
    let centre = Point3::new(AT[0], AT[1], AT[2] + HALF);
    let pose = view_pose(&centre, 0.45, 0.5, 0.0);
    let q = world.robot().ik(&camera.spec.frame, &pose).unwrap()[0].joints;
    let views = vec![("cube".to_string(), vec![(pose, q)])];
    let cache = OracleCache::new(dir.path().join("oracles"));
    let options = |cache: Option<OracleCache>| OracleOptions {
        dense: dense.clone(),
        views: views.clone(),
        cache,
        ..Default::default()
    };
    let computed = oracle(&scene, &options(None)).unwrap();
    let first = oracle(&scene, &options(Some(cache.clone()))).unwrap();
    assert_eq!(std::fs::read_dir(cache.dir()).unwrap().count(), 1);
    let second = oracle(&scene, &options(Some(cache.clone()))).unwrap();
    let objects = |r: &nbv_sweep::oracle::OracleReport| serde_json::to_value(&r.objects).unwrap();
    assert_eq!(objects(&first), objects(&computed));
    assert_eq!(objects(&second), objects(&computed));
    assert_eq!(computed.objects[0].views_noise_free.len(), 2);

    // What a sweep varies leaves the key; the world, the seed, phase 1 and the sphere change
    // it.
    let key = |s: &nbv_scenes::Scene| OracleCache::key(s, &dense).unwrap();
    let mut other = scene.clone();
    other.nbv.alpha_o = 0.25;
    other.nbv.gain_threshold = 9.0;
    other.registration = Default::default();
    assert_eq!(key(&other), key(&scene));
    let mut seed = scene.clone();
    seed.seed += 1;
    let mut radius = scene.clone();
    radius.nbv.radius = 0.3;
    let mut moved = scene.clone();
    moved.objects[0].pose.xyz[0] += 0.01;
    // Phase 1's segmentation makes the base the greedy cover starts from.
    let mut segmented = scene.clone();
    segmented.segmentation.cluster_tolerance += 0.01;
    for changed in [seed, radius, moved, segmented] {
        assert_ne!(key(&changed), key(&scene));
    }
}
