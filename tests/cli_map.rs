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
