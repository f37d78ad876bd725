//! `nbv map` end to end on a synthetic sweep (a table and two boxes): two clusters, the
//! three output files, their contents, determinism, and the error for a cloud without
//! sensor origins.

mod common;

use common::{boxes, nbv, synthetic_cloud, text};
use nbv_core::cloud::io::{WriteOptions, read_cloud, write_cloud};
use nbv_core::occupancy::OccupancyGrid;
use std::path::Path;

fn write(dir: &Path, name: &str, origins: bool) -> String {
    let path = dir.join(name);
    write_cloud(&path, &synthetic_cloud(origins), &WriteOptions::default()).unwrap();
    path.display().to_string()
}

fn stats(dir: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(dir.join("stats.json")).unwrap()).unwrap()
}

/// Every cluster's centroid lies over one box, and each box has exactly one cluster.
fn check_clusters(s: &serde_json::Value) {
    let clusters = s["clusters"].as_array().unwrap();
    assert_eq!(clusters.len(), 2, "{s:#}");
    let mut matched = [0; 2];
    for c in clusters {
        let x = c["centroid"][0].as_f64().unwrap();
        let y = c["centroid"][1].as_f64().unwrap();
        let zmax = c["max"][2].as_f64().unwrap();
        let b = boxes()
            .iter()
            .position(|(lo, hi)| x > lo[0] && x < hi[0] && y > lo[1] && y < hi[1])
            .unwrap_or_else(|| panic!("cluster {c} over no box"));
        matched[b] += 1;
        // The top of the cluster is the box top (voxel centroids: within 5 mm).
        assert!((zmax - boxes()[b].1[2]).abs() < 0.005, "{c}");
        assert!(c["points"].as_u64().unwrap() >= 100);
    }
    assert_eq!(matched, [1, 1]);
}

#[test]
fn two_boxes_give_two_clusters_and_the_files() {
    let tmp = tempfile::tempdir().unwrap();
    let cloud = write(tmp.path(), "cloud.ply", true);
    let out = tmp.path().join("map");
    let o = nbv(&["map", "--cloud", &cloud, "-o", out.to_str().unwrap()]);
    let stdout = text(&o.stdout);
    assert!(o.status.success(), "{stdout}\n{}", text(&o.stderr));
    assert!(stdout.contains("clusters: 2 "), "{stdout}");
    assert!(
        stdout.contains("grid: 60 x 70 x 30 = 126000 voxels"),
        "{stdout}"
    );
    assert!(stdout.contains("it removes"), "{stdout}");

    let s = stats(&out);
    check_clusters(&s);
    let g = &s["grid"];
    let n = g["voxels"].as_u64().unwrap();
    assert_eq!(n, 126_000);
    let (occ, emp, unk) = (
        g["occupied"].as_u64().unwrap(),
        g["empty"].as_u64().unwrap(),
        g["unknown"].as_u64().unwrap(),
    );
    assert_eq!(occ + emp + unk, n);
    assert!(occ > 1000 && emp > 10_000 && unk > 10_000, "{g}");
    let shares: f64 = ["occupied_share", "empty_share", "unknown_share"]
        .iter()
        .map(|k| g[*k].as_f64().unwrap())
        .sum();
    assert!((shares - 1.0).abs() < 1e-12);
    let table = &s["segmentation"]["table"];
    // Least squares over the inliers, which include the boxes' lowest centimetre.
    assert!(table["normal"][2].as_f64().unwrap() > 0.9999, "{table}");
    assert!(
        (table["offset"].as_f64().unwrap() + 0.25).abs() < 1e-3,
        "{table}"
    );

    // The grid file: same geometry and the same counts as stats.json.
    let grid = OccupancyGrid::load(out.join("grid.nbvgrid")).unwrap();
    assert_eq!(grid.geometry().dims(), [60, 70, 30]);
    let counts = grid.state_counts();
    assert_eq!(
        (counts.occupied, counts.empty, counts.unknown),
        (occ as usize, emp as usize, unk as usize)
    );
    let r = &s["reduced_map"];
    let reduced = nbv_core::occupancy::ReducedMap::from_grid(&grid);
    assert_eq!(
        r["unknown_crust"].as_u64().unwrap() as usize,
        reduced.unknown().len()
    );
    let removed = r["removed_unknown_share"].as_f64().unwrap();
    assert!(removed > 0.0 && removed < 1.0);

    // The clusters file: labels 0 and 1, as many points as the clusters.
    let clusters = read_cloud(out.join("clusters.ply")).unwrap();
    let labels = clusters.labels.as_ref().unwrap();
    let total: u64 = s["clusters"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["points"].as_u64().unwrap())
        .sum();
    assert_eq!(labels.len() as u64, total);
    assert!(labels.iter().all(|&l| l < 2) && labels.contains(&0) && labels.contains(&1));
    assert!(clusters.origins.is_some());

    // Same input, same bytes.
    let again = tmp.path().join("again");
    let o2 = nbv(&["map", "--cloud", &cloud, "-o", again.to_str().unwrap()]);
    assert!(o2.status.success());
    for f in ["grid.nbvgrid", "clusters.ply"] {
        assert_eq!(
            std::fs::read(out.join(f)).unwrap(),
            std::fs::read(again.join(f)).unwrap(),
            "{f}"
        );
    }
    // No temporary files left behind.
    let names: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names.len(), 3, "{names:?}");
}

#[test]
fn scene_parameters_and_known_obstacles() {
    let tmp = tempfile::tempdir().unwrap();
    let cloud = write(tmp.path(), "cloud.ply", true);
    let out = tmp.path().join("map");
    let o = nbv(&[
        "map",
        "--cloud",
        &cloud,
        "-o",
        out.to_str().unwrap(),
        "--scene",
        "paper-env1",
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let s = stats(&out);
    check_clusters(&s);
    assert_eq!(s["scene"], "paper-env1");
    assert_eq!(s["segmentation"]["params"]["excluded_boxes"], 2);
    assert_eq!(s["grid"]["epsilon_o"].as_f64().unwrap(), 0.4f32 as f64);
}

#[test]
fn a_cloud_without_origins_is_a_clear_error_unless_origin_is_given() {
    let tmp = tempfile::tempdir().unwrap();
    let cloud = write(tmp.path(), "bare.ply", false);
    let out = tmp.path().join("map");
    let o = nbv(&["map", "--cloud", &cloud, "-o", out.to_str().unwrap()]);
    assert!(!o.status.success());
    let err = text(&o.stderr);
    assert!(err.contains("no per-point sensor origins"), "{err}");
    assert!(err.contains("--origin x,y,z"), "{err}");
    assert!(!out.exists(), "nothing is written on error");

    // One sensor position for every point (the middle of the sweep).
    let o = nbv(&[
        "map",
        "--cloud",
        &cloud,
        "-o",
        out.to_str().unwrap(),
        "--origin=0.05,0,1.25",
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let s = stats(&out);
    assert_eq!(s["cloud"]["origins"], "--origin");
    check_clusters(&s);

    let o = nbv(&["map", "--cloud", &cloud, "-o", "x", "--origin", "1,2"]);
    assert!(!o.status.success());
    assert!(text(&o.stderr).contains("three finite numbers"));
}

/// `nbv map --bag`: the synthetic sweep as a ROS 2 bag — each scan line a PointCloud2 in
/// the laser's frame, the laser's pose on `/tf` at the line's stamp under a static
/// `world → base_link` — maps exactly as the cloud file does: the same two clusters, the same
/// grid as a cloud file of the same points narrowed to 32-bit floats in the laser's frame,
/// as they cross the wire (the synthetic sweep's points and origins lie on voxel faces, so
/// any rounding moves rays across them: against the f64 sweep, 1.6 % of the occupied
/// voxels change).
#[test]
fn a_bag_of_scan_lines_maps_as_its_cloud_does() {
    use nbv_bag::messages::{Header, TFMessage, Time, Transform, TransformStamped};
    let tmp = tempfile::tempdir().unwrap();
    let sweep = synthetic_cloud(true);
    let origins = sweep.origins.as_ref().unwrap();
    let narrowed: Vec<_> = sweep
        .points
        .iter()
        .zip(origins)
        .map(|(p, o)| o + (p - o).map(|c| f64::from(c as f32)))
        .collect();
    let mut as_sent = nbv_core::cloud::PointCloud::from_points(narrowed);
    as_sent.origins = Some(origins.clone());
    let cloud_path = tmp.path().join("cloud.ply");
    let lossless = WriteOptions {
        float: nbv_core::cloud::io::FloatType::F64,
        ..WriteOptions::default()
    };
    write_cloud(&cloud_path, &as_sent, &lossless).unwrap();
    let cloud = cloud_path.display().to_string();
    let bag = tmp.path().join("sweep");
    let mut w = nbv_bag::BagWriter::create(&bag).unwrap();
    let tf = |parent: &str, child: &str, t: i64, x: [f64; 3]| TFMessage {
        transforms: vec![TransformStamped {
            header: Header {
                stamp: Time::from_nanos(t),
                frame_id: parent.into(),
            },
            child_frame_id: child.into(),
            transform: Transform::from_isometry(&nalgebra::Isometry3::translation(
                x[0], x[1], x[2],
            )),
        }],
    };
    w.write("/tf_static", 1, &tf("world", "base_link", 0, [0.0; 3]))
        .unwrap();
    let mut start = 0;
    let mut lines = 0;
    while start < sweep.len() {
        let o = origins[start];
        let end = (start..sweep.len())
            .find(|&k| origins[k] != o)
            .unwrap_or(sweep.len());
        let t = 1_000_000_000 + 10_000_000 * lines;
        let laser = [o.x, o.y, o.z];
        w.write(
            "/tf",
            u64::try_from(t).unwrap(),
            &tf("base_link", "laser", t, laser),
        )
        .unwrap();
        let local: Vec<_> = sweep.points[start..end]
            .iter()
            .map(|p| p - o.coords)
            .collect();
        let header = Header {
            stamp: Time::from_nanos(t),
            frame_id: "laser".into(),
        };
        let msg = nbv_bag::point_cloud::cloud_from_points_f64(header, &local);
        w.write("/scan", u64::try_from(t).unwrap(), &msg).unwrap();
        start = end;
        lines += 1;
    }
    w.finish().unwrap();
    assert!(lines > 10, "{lines} lines");

    let (a, b) = (tmp.path().join("from-cloud"), tmp.path().join("from-bag"));
    let o = nbv(&["map", "--cloud", &cloud, "-o", a.to_str().unwrap()]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let bag_arg = bag.to_str().unwrap();
    let o = nbv(&[
        "map",
        "--bag",
        bag_arg,
        "--topic",
        "/scan",
        "-o",
        b.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(
        text(&o.stderr).contains("posed in frame \"world\""),
        "{}",
        text(&o.stderr)
    );
    let (sa, sb) = (stats(&a), stats(&b));
    check_clusters(&sb);
    for key in ["occupied", "empty", "unknown"] {
        let (x, y) = (
            sa["grid"][key].as_f64().unwrap(),
            sb["grid"][key].as_f64().unwrap(),
        );
        assert!(x == y, "{key}: {x} from the cloud, {y} from the bag");
    }
    // A cloud topic that is not one, and a bag without /tf for the clouds' frame.
    let o = nbv(&["map", "--bag", bag_arg, "--topic", "/tf", "-o", "x"]);
    assert!(
        text(&o.stderr).contains("not sensor_msgs/msg/PointCloud2"),
        "{}",
        text(&o.stderr)
    );
    assert!(!Path::new("x").exists());
}
