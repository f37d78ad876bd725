//! `stats.json` of `nbv map`: what phase 1 made of a mid-range cloud — the segmentation's
//! parameters and counts, the table plane, the clusters, the occupancy grid and its
//! reduced map — as JSON; and the files `nbv map` writes ([`write_map_files`]).

use crate::error::{Context, Result};
use nalgebra::Point3;
use nbv_core::cloud::PointCloud;
use nbv_core::cloud::io::{CloudIoError, WriteOptions, write_atomically, write_cloud};
use nbv_core::perception::{PhaseOne, PhaseOneConfig};
use serde_json::{Value, json};
use std::path::{Path, PathBuf};

/// The share `n / total` (0 for an empty total).
///
/// ```
/// assert_eq!(nbv_sweep::map_stats::share(1, 4), 0.25);
/// assert_eq!(nbv_sweep::map_stats::share(1, 0), 0.0);
/// ```
pub fn share(n: usize, total: usize) -> f64 {
    if total == 0 {
        0.0
    } else {
        n as f64 / total as f64
    }
}

fn xyz(p: &Point3<f64>) -> Value {
    json!([p.x, p.y, p.z])
}

/// The statistics of phase 1 on the cloud read from `path` (`origin_source` says where
/// the sensor origins came from; `scene` names the scene whose parameters were used).
pub fn stats_json(
    path: &Path,
    cloud: &PointCloud,
    origin_source: &str,
    scene: Option<&str>,
    config: &PhaseOneConfig,
    r: &PhaseOne,
) -> Value {
    let seg = &r.segmentation;
    let c = &seg.counts;
    let p = &config.segmentation;
    let g = r.map.grid.geometry();
    let s = r.map.reduced.stats();
    let n = g.len();
    let o = &config.occupancy;
    json!({
        "cloud": {
            "path": path.display().to_string(),
            "points": cloud.len(),
            "origins": origin_source,
        },
        "scene": scene,
        "segmentation": {
            "params": {
                "voxel": p.voxel,
                "outlier_neighbours": p.outlier_neighbours,
                "outlier_std": p.outlier_std,
                "plane_distance": p.plane_distance,
                "plane_iterations": p.plane_iterations,
                "plane_max_tilt": p.plane_max_tilt,
                "cluster_tolerance": p.cluster_tolerance,
                "min_cluster_points": p.min_cluster_points,
                "max_cluster_points": p.max_cluster_points,
                "seed": p.seed,
                "excluded_boxes": config.exclude.len(),
            },
            "counts": {
                "input": c.input,
                "in_region": c.in_region,
                "after_voxel": c.after_voxel,
                "after_outliers": c.after_outliers,
                "table_inliers": c.table_inliers,
                "above_table": c.above_table,
                "clustered": c.clustered,
                "small_components": c.small_components,
                "large_components": c.large_components,
            },
            "table": seg.table.as_ref().map(|t| json!({
                "normal": [t.normal.x, t.normal.y, t.normal.z],
                "offset": t.offset,
                "inliers": t.inliers.len(),
                "rms": t.rms,
            })),
        },
        "clusters": seg.clusters.iter().enumerate().map(|(j, k)| json!({
            "id": j,
            "points": k.len(),
            "centroid": xyz(&k.centroid),
            "min": xyz(&k.min),
            "max": xyz(&k.max),
        })).collect::<Vec<_>>(),
        "grid": {
            "dims": g.dims(),
            "resolution": g.resolution(),
            "min": xyz(&g.min()),
            "max": xyz(&g.max()),
            "voxels": n,
            "hit_probability": o.hit_probability,
            "clamp": [o.clamp_min, o.clamp_max],
            "epsilon_o": o.occupied_epsilon,
            "max_range": config.max_range,
            "occupied": s.grid.occupied,
            "empty": s.grid.empty,
            "unknown": s.grid.unknown,
            "occupied_share": share(s.grid.occupied, n),
            "empty_share": share(s.grid.empty, n),
            "unknown_share": share(s.grid.unknown, n),
        },
        "scan": {
            "rays": r.map.scan.rays,
            "occupied_updates": r.map.scan.occupied,
            "free_updates": r.map.scan.free,
            "truncated": r.map.scan.truncated,
            "hits_outside": r.map.scan.hits_outside,
        },
        "reduced_map": {
            "voxels": s.occupied + s.unknown_crust,
            "occupied": s.occupied,
            "unknown_crust": s.unknown_crust,
            "removed_unknown_share": s.removed_unknown_share,
        },
    })
}

/// The files [`write_map_files`] wrote.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct MapFiles {
    /// The occupancy grid after phase 1 (`grid.nbvgrid`).
    pub grid: PathBuf,
    /// The object clusters, each point labelled with its cluster (`clusters.ply`).
    pub clusters: PathBuf,
    /// The statistics (`stats.json`, [`stats_json`]).
    pub stats: PathBuf,
}

/// Writes phase 1's result `r` into `dir` (created if missing): the grid, the labelled
/// clusters and the statistics `stats`, each atomically, in that order.
///
/// ```
/// use nbv_core::perception::phase_one;
/// let config = nbv_scenes::pipeline_params::default_phase_one_config().unwrap();
/// // A table top seen from 1.5 m above it.
/// let table = (0..40).flat_map(|i| (0..40).map(move |j| {
///     nalgebra::Point3::new(0.6 + 0.01 * i as f64, -0.2 + 0.01 * j as f64, 0.25)
/// }));
/// let mut cloud = nbv_core::cloud::PointCloud::from_points(table.collect());
/// cloud.origins = Some(vec![nalgebra::Point3::new(0.8, 0.0, 1.5); cloud.len()]);
/// let result = phase_one(&cloud, &config).unwrap();
/// let dir = std::env::temp_dir().join(format!("nbv-map-files-doc-{}", std::process::id()));
/// let files = nbv_sweep::map_stats::write_map_files(&dir, &result, &serde_json::json!({})).unwrap();
/// assert_eq!(std::fs::read_to_string(&files.stats).unwrap(), "{}\n");
/// assert!(files.grid.exists() && files.clusters.exists());
/// std::fs::remove_dir_all(&dir).unwrap();
/// ```
pub fn write_map_files(dir: &Path, r: &PhaseOne, stats: &Value) -> Result<MapFiles> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let grid = dir.join("grid.nbvgrid");
    r.map
        .grid
        .save(&grid)
        .with_context(|| format!("writing {}", grid.display()))?;
    let clusters = dir.join("clusters.ply");
    write_cloud(
        &clusters,
        &r.segmentation.labelled_clusters(),
        &WriteOptions::default(),
    )
    .with_context(|| format!("writing {}", clusters.display()))?;
    let stats_path = dir.join("stats.json");
    let text = serde_json::to_string_pretty(stats).context("serialising the statistics")? + "\n";
    write_atomically(&stats_path, |w| {
        w.write_all(text.as_bytes()).map_err(CloudIoError::from)
    })
    .with_context(|| format!("writing {}", stats_path.display()))?;
    Ok(MapFiles {
        grid,
        clusters,
        stats: stats_path,
    })
}
