//! Phase 1 as a library: a synthetic sweep of a table with three objects becomes three
//! clusters and a grid whose states and reduced map agree with their definitions; known
//! obstacles are left out; the result does not depend on the thread count; bad input is
//! a typed error.

use nalgebra::{Point3, Vector3};
use nbv_core::cloud::PointCloud;
use nbv_core::occupancy::{GridGeometry, ReducedMap, VoxelState};
use nbv_core::perception::{
    OrientedBox, PerceptionError, PhaseOneConfig, SegmentationParams, phase_one,
};

const TABLE_TOP: f64 = 0.25;
/// Boxes on the table (min, max): two objects and a tall panel at the back.
const BOXES: [([f64; 3], [f64; 3]); 3] = [
    ([0.60, -0.30, 0.25], [0.72, -0.18, 0.37]),
    ([0.80, 0.05, 0.25], [0.90, 0.20, 0.45]),
    ([1.20, -0.40, 0.25], [1.24, 0.40, 0.60]),
];

fn cast(o: &Point3<f64>, d: &Vector3<f64>) -> Option<f64> {
    let mut best = (d.z < 0.0).then(|| (TABLE_TOP - o.z) / d.z).filter(|&t| {
        let p = o + d * t;
        (0.35..=1.35).contains(&p.x) && (-0.7..=0.7).contains(&p.y)
    });
    for (lo, hi) in BOXES {
        let (mut t0, mut t1) = (0.0f64, f64::INFINITY);
        for a in 0..3 {
            if d[a] == 0.0 {
                if o[a] < lo[a] || o[a] > hi[a] {
                    t0 = f64::INFINITY;
                }
                continue;
            }
            let (ta, tb) = ((lo[a] - o[a]) / d[a], (hi[a] - o[a]) / d[a]);
            t0 = t0.max(ta.min(tb));
            t1 = t1.min(ta.max(tb));
        }
        if t0 <= t1 && best.is_none_or(|b| t0 < b) {
            best = Some(t0);
        }
    }
    best
}

/// 100 lines × 140 rays, the scanner 1 m above the table moving along y.
fn sweep() -> PointCloud {
    let mut pts = Vec::new();
    let mut origins = Vec::new();
    for l in 0..100 {
        let o = Point3::new(0.05, -0.6 + 1.2 * l as f64 / 99.0, 1.25);
        for r in 0..140 {
            let a = (12.0 + 48.0 * r as f64 / 139.0f64).to_radians();
            let d = Vector3::new(a.sin(), 0.0, -a.cos());
            if let Some(t) = cast(&o, &d) {
                pts.push(o + d * t);
                origins.push(o);
            }
        }
    }
    let mut cloud = PointCloud::from_points(pts);
    cloud.origins = Some(origins);
    cloud
}

fn config() -> PhaseOneConfig {
    let g = GridGeometry::new(
        Point3::new(0.30, -0.70, 0.23),
        Point3::new(1.50, 0.70, 0.83),
        0.02,
    )
    .unwrap();
    let mut c = PhaseOneConfig::new(g);
    c.segmentation = SegmentationParams {
        outlier_neighbours: 16,
        min_cluster_points: 50,
        ..SegmentationParams::default()
    };
    c
}

fn box_of(p: &Point3<f64>) -> Option<usize> {
    BOXES
        .iter()
        .position(|(lo, hi)| (0..3).all(|a| p[a] >= lo[a] - 0.005 && p[a] <= hi[a] + 0.005))
}

#[test]
fn one_cluster_per_box_and_a_consistent_map() {
    let cloud = sweep();
    let c = config();
    let out = phase_one(&cloud, &c).unwrap();
    let seg = &out.segmentation;
    assert_eq!(seg.clusters.len(), 3, "{:?}", seg.counts);
    let mut seen = [false; 3];
    for k in &seg.clusters {
        let b = box_of(&k.centroid).expect("centroid inside a box");
        assert!(!seen[b], "two clusters on box {b}");
        seen[b] = true;
        // Every point of the cluster lies on its box.
        assert!(
            k.indices
                .iter()
                .all(|&i| box_of(&seg.filtered.points[i]) == Some(b))
        );
        assert!(k.min.z > TABLE_TOP + c.segmentation.plane_distance);
    }
    // The least-squares refinement also takes in the lowest centimetre of the boxes and
    // the panel, so the plane is not exact; every table point is within the threshold.
    let t = seg.table.as_ref().unwrap();
    assert!(t.normal.z > 0.999, "normal {:?}", t.normal);
    let table_points = seg
        .filtered
        .points
        .iter()
        .filter(|p| (p.z - TABLE_TOP).abs() < 1e-6);
    assert!(table_points.clone().count() > 5000);
    for p in table_points {
        assert!(
            t.signed_distance(p).abs() <= c.segmentation.plane_distance,
            "{p}"
        );
    }
    let counts = seg.counts;
    assert_eq!(counts.input, cloud.len());
    assert!(counts.after_outliers <= counts.after_voxel && counts.after_voxel <= counts.in_region);
    assert_eq!(
        counts.clustered,
        seg.clusters.iter().map(|k| k.len()).sum::<usize>()
    );
    let labelled = seg.labelled_clusters();
    assert_eq!(labelled.len(), counts.clustered);
    assert_eq!(labelled.labels.as_ref().unwrap().iter().max(), Some(&2));

    // The grid: one scan of every ray; every end point's voxel is occupied.
    let m = &out.map;
    assert_eq!(m.scan.rays, cloud.len());
    assert_eq!(m.scan.truncated, 0);
    let g = m.grid.geometry();
    for p in &cloud.points {
        if let Some(v) = g.voxel_of(p) {
            assert_eq!(m.grid.state(v), Some(VoxelState::Occupied));
        }
    }
    // Space the rays cross above the table is empty; the shadow behind a box is unknown.
    assert_eq!(
        m.grid
            .state(g.voxel_of(&Point3::new(0.5, 0.0, 0.6)).unwrap()),
        Some(VoxelState::Empty)
    );
    assert_eq!(
        m.grid
            .state(g.voxel_of(&Point3::new(0.95, 0.12, 0.28)).unwrap()),
        Some(VoxelState::Unknown)
    );
    // Behind the panel (seen from the front only) is unknown.
    assert_eq!(
        m.grid
            .state(g.voxel_of(&Point3::new(1.40, 0.0, 0.35)).unwrap()),
        Some(VoxelState::Unknown)
    );
    assert_eq!(m.reduced, ReducedMap::from_grid(&m.grid));
    let s = m.reduced.stats();
    assert_eq!(s.grid, m.grid.state_counts());
    assert!(
        s.removed_unknown_share > 0.3 && s.removed_unknown_share < 1.0,
        "{s:?}"
    );
}

#[test]
fn known_obstacles_are_left_out() {
    let cloud = sweep();
    let mut c = config();
    // Without exclusion the panel is the third cluster; exclude it as a known obstacle.
    let (lo, hi) = BOXES[2];
    c.exclude = vec![OrientedBox::from_bounds(Point3::from(lo), Point3::from(hi)).inflated(0.02)];
    let out = phase_one(&cloud, &c).unwrap();
    assert_eq!(out.segmentation.clusters.len(), 2);
    assert!(
        out.segmentation
            .clusters
            .iter()
            .all(|k| box_of(&k.centroid) != Some(2))
    );
    // The grid still sees the panel: every return on it marks an occupied voxel.
    let g = out.map.grid.geometry();
    let on_panel: Vec<_> = cloud
        .points
        .iter()
        .filter(|p| box_of(p) == Some(2))
        .collect();
    assert!(on_panel.len() > 1000);
    for p in on_panel {
        let v = g.voxel_of(p).unwrap();
        assert_eq!(out.map.grid.state(v), Some(VoxelState::Occupied));
    }
}

#[test]
fn same_result_for_any_thread_count() {
    let cloud = sweep();
    let c = config();
    let run = |threads| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| phase_one(&cloud, &c).unwrap())
    };
    assert_eq!(run(1), run(3));
}

#[test]
fn bad_input_is_a_typed_error() {
    let c = config();
    let mut cloud = sweep();
    cloud.origins = None;
    assert_eq!(phase_one(&cloud, &c), Err(PerceptionError::MissingOrigins));

    let mut far = PointCloud::from_points(vec![Point3::new(5.0, 5.0, 5.0); 10]);
    far.origins = Some(vec![Point3::origin(); 10]);
    assert_eq!(
        phase_one(&far, &c),
        Err(PerceptionError::NothingInRegion { points: 10 })
    );

    let mut nan = sweep();
    nan.points[3].x = f64::NAN;
    assert!(matches!(
        phase_one(&nan, &c),
        Err(PerceptionError::Processing { .. })
    ));

    let mut bad = config();
    bad.segmentation.max_cluster_points = 1;
    assert!(matches!(
        phase_one(&sweep(), &bad),
        Err(PerceptionError::InvalidParameter {
            name: "max_cluster_points",
            ..
        })
    ));
    // Fewer points than the outlier filter's neighbourhood.
    let mut few = PointCloud::from_points(vec![Point3::new(0.5, 0.0, 0.3); 5]);
    few.origins = Some(vec![Point3::new(0.5, 0.0, 1.0); 5]);
    let err = phase_one(&few, &c).unwrap_err();
    assert!(err.to_string().starts_with("outlier removal:"), "{err}");
}

#[test]
fn an_object_seen_in_two_parts_is_one_cluster() {
    // The sweep misses a 4 cm band around the second box's middle (as under a bottle's
    // shoulder): two components over the same footprint, one object.
    let full = sweep();
    let keep: Vec<usize> = (0..full.len())
        .filter(|&i| {
            let p = full.points[i];
            !(box_of(&p) == Some(1) && p.z > 0.33 && p.z < 0.37)
        })
        .collect();
    let cloud = full.select(&keep);
    let out = phase_one(&cloud, &config()).unwrap();
    assert_eq!(out.segmentation.counts.merged_parts, 1);
    let boxes: Vec<_> = out
        .segmentation
        .clusters
        .iter()
        .map(|k| box_of(&k.centroid))
        .collect();
    assert_eq!(boxes, [Some(0), Some(1), Some(2)]);
    // Both parts are in the second box's cluster.
    let second = &out.segmentation.clusters[1];
    let z: Vec<f64> = second
        .indices
        .iter()
        .map(|&i| out.segmentation.filtered.points[i].z)
        .collect();
    assert!(z.iter().any(|&z| z < 0.33) && z.iter().any(|&z| z > 0.37));
}

#[test]
fn a_known_face_moved_by_pose_error_is_no_object() {
    // The robot reported the sweep 25 mm off along x: the panel's front face (x = 1.20)
    // appears at 1.175, outside its box grown by the 2 cm clustering tolerance.
    let mut cloud = sweep();
    cloud.transform(&nalgebra::Isometry3::translation(-0.025, 0.0, 0.0));
    let mut c = config();
    let (lo, hi) = BOXES[2];
    c.exclude = vec![OrientedBox::from_bounds(Point3::from(lo), Point3::from(hi)).inflated(0.02)];
    // The layer left in front of the box is a sliver of its face: dropped, not an object.
    let out = phase_one(&cloud, &c).unwrap();
    let boxes: Vec<_> = out
        .segmentation
        .clusters
        .iter()
        .map(|k| box_of(&(k.centroid + Vector3::new(0.025, 0.0, 0.0))))
        .collect();
    assert_eq!(boxes, [Some(0), Some(1)]);
    assert_eq!(out.segmentation.slivers.len(), 1);
    let (_, sliver) = &out.segmentation.slivers[0];
    assert_eq!(sliver.obstacle, 0);
    assert!(sliver.thickness < 0.002 && (sliver.distance - 0.005).abs() < 0.002);
    // Grown by 3σ of the pose error the rig declares (1 cm, 0.1°), the box holds the face:
    // nothing is left to drop.
    let prior = nbv_core::registration::PosePrior {
        rotation_sigma: 0.1f64.to_radians(),
        translation_sigma: 0.01,
    };
    let sensor = Point3::new(0.05, 0.0, 1.25);
    let out = phase_one(&cloud, &c.with_pose_error(&prior, &sensor)).unwrap();
    assert_eq!(out.segmentation.clusters.len(), 2);
    assert!(out.segmentation.slivers.is_empty());
}
