//! `nbv map`: phase 1 on a mid-range cloud file (or a ROS 2 bag's clouds with their sensor
//! poses from `/tf`) — object clusters, the occupancy grid and
//! its reduced map — printed as statistics and written as `grid.nbvgrid`, `clusters.ply`
//! and `stats.json`. The pipeline itself is `nbv_core::perception::phase_one`, the
//! configuration without a scene `nbv_scenes::pipeline_params::default_phase_one_config`,
//! the files `nbv_sweep::map_stats`; this file parses the arguments and prints.

use anyhow::{Context, Result, bail};
use clap::Args;
use nalgebra::Point3;
use nbv_core::cloud::PointCloud;
use nbv_core::cloud::io::{ReadOptions, read_cloud_with};
use nbv_core::perception::{PhaseOne, PhaseOneConfig, phase_one};
use nbv_scenes::pipeline_params::default_phase_one_config;
use nbv_sweep::map_stats::{share, stats_json, write_map_files};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Arguments of `nbv map`.
#[derive(Debug, Args)]
pub struct MapArgs {
    /// The accumulated mid-range cloud (PLY or PCD), in the world frame, with per-point
    /// sensor origins (PLY `ox oy oz`, PCD `vp_x vp_y vp_z` or a non-identity VIEWPOINT).
    #[arg(long, required_unless_present = "bag", conflicts_with = "bag")]
    cloud: Option<PathBuf>,
    /// The cloud from a bag instead: its clouds moved into the fixed frame (the scene's
    /// world), each point's ray cast from its sensor's position at the stamp.
    #[command(flatten)]
    bag: super::bag_views::BagInput,
    /// Output directory (created if missing): grid.nbvgrid, clusters.ply, stats.json.
    #[arg(short, long)]
    output: PathBuf,
    /// Scene file or built-in scene name: its workspace, [mapping], [segmentation],
    /// mid-range maximum range and known obstacles (left out of the clusters). Without
    /// it: the paper's workspace [0.30,-0.70,0.23]..[1.50,0.70,0.83] at 0.02 m and the
    /// schema's defaults.
    #[arg(long)]
    scene: Option<String>,
    /// Sensor origin `x,y,z` (m) of every point, for a cloud taken from one position; it
    /// replaces the cloud's own origins if it has some.
    #[arg(long, value_parser = parse_xyz, allow_hyphen_values = true)]
    origin: Option<Point3<f64>>,
    /// Also draw the reduced map from the front and the back (map_front.png,
    /// map_back.png); without a GPU or Mesa this only warns.
    #[arg(long)]
    pictures: bool,
}

/// Parses `x,y,z`.
pub fn parse_xyz(s: &str) -> Result<Point3<f64>, String> {
    let v: Vec<f64> = s
        .split(',')
        .map(|t| t.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|e| format!("`{s}`: {e} (expected x,y,z in metres)"))?;
    match v[..] {
        [x, y, z] if v.iter().all(|c| c.is_finite()) => Ok(Point3::new(x, y, z)),
        _ => Err(format!("`{s}`: expected three finite numbers x,y,z")),
    }
}

/// Runs `nbv map`.
pub fn run(args: MapArgs) -> Result<()> {
    let (config, scene_name) = match &args.scene {
        Some(s) => {
            let scene = nbv_scenes::overrides::load(s)?;
            let config = scene
                .phase_one_config()
                .with_context(|| format!("phase-1 parameters of {s}"))?;
            (config, Some(scene.name))
        }
        None => (
            default_phase_one_config().context("the default workspace")?,
            None,
        ),
    };
    let (source, mut cloud) = read_input(&args)?;
    let origin_source = if args.bag.bag.is_some() && args.origin.is_none() {
        "/tf"
    } else {
        sensor_origins(&args, &source, &mut cloud)?
    };
    if cloud.is_empty() {
        bail!("{}: the cloud has no points", source.display());
    }

    let start = Instant::now();
    let result =
        phase_one(&cloud, &config).with_context(|| format!("phase 1 on {}", source.display()))?;
    let elapsed = start.elapsed().as_secs_f64();

    print_summary(&source, &cloud, origin_source, &config, &result, elapsed);
    let stats = stats_json(
        &source,
        &cloud,
        origin_source,
        scene_name.as_deref(),
        &config,
        &result,
    );
    let files = write_map_files(&args.output, &result, &stats)?;
    println!(
        "wrote {}, {}, {}",
        files.grid.display(),
        files.clusters.display(),
        files.stats.display()
    );
    if args.pictures {
        super::render::map_pictures_or_warn(
            &result.map.grid,
            &result.map.reduced,
            &args.output.join("map_front.png"),
            &args.output.join("map_back.png"),
        );
    }
    Ok(())
}

/// Where the cloud's sensor origins come from: `--origin` (which replaces the cloud's
/// own, with a note) or the cloud; an error without either.
/// The input's path and its cloud: the file, or the bag's clouds in the fixed frame with
/// each point's sensor origin.
fn read_input(args: &MapArgs) -> Result<(PathBuf, PointCloud)> {
    if let (Some(views), Some(bag)) = (args.bag.read(None)?, &args.bag.bag) {
        let mut cloud = PointCloud::default();
        for (view, pose) in views.clouds.iter().zip(&views.poses) {
            let origin = Point3::from(pose.translation.vector);
            let mut moved = PointCloud::from_points(view.points.iter().map(|p| pose * p).collect());
            moved.origins = Some(vec![origin; moved.len()]);
            cloud.extend(&moved);
        }
        return Ok((bag.clone(), cloud));
    }
    let Some(path) = &args.cloud else {
        bail!("give --cloud FILE or --bag BAG --topic TOPIC");
    };
    let file = read_cloud_with(path, &ReadOptions::default())
        .with_context(|| format!("reading {}", path.display()))?;
    if file.dropped_non_finite > 0 {
        eprintln!(
            "note: {} points with non-finite coordinates were dropped",
            file.dropped_non_finite
        );
    }
    Ok((path.clone(), file.cloud))
}

fn sensor_origins(args: &MapArgs, source: &Path, cloud: &mut PointCloud) -> Result<&'static str> {
    match (args.origin, cloud.origins.is_some()) {
        (Some(o), had) => {
            if had {
                eprintln!("note: --origin replaces the cloud's own sensor origins");
            }
            cloud.origins = Some(vec![o; cloud.len()]);
            Ok("--origin")
        }
        (None, true) => Ok("cloud"),
        (None, false) => bail!(
            "{}: the cloud has no per-point sensor origins (PLY `ox oy oz`, PCD `vp_x vp_y \
             vp_z` or VIEWPOINT), so its rays cannot be cast into the occupancy grid; give \
             the sensor position with --origin x,y,z",
            source.display()
        ),
    }
}

fn fmt_point(p: &Point3<f64>) -> String {
    format!("({:.3}, {:.3}, {:.3})", p.x, p.y, p.z)
}

fn print_summary(
    path: &Path,
    cloud: &PointCloud,
    origin_source: &str,
    config: &PhaseOneConfig,
    r: &PhaseOne,
    elapsed: f64,
) {
    let seg = &r.segmentation;
    let c = &seg.counts;
    let p = &config.segmentation;
    println!(
        "cloud {}: {} points, origins from {origin_source}",
        path.display(),
        cloud.len()
    );
    println!(
        "segmentation: {} in region ({} excluded boxes) -> voxel {} m: {} -> outlier \
         removal (k {}, {} sigma): {}",
        c.in_region,
        config.exclude.len(),
        p.voxel,
        c.after_voxel,
        p.outlier_neighbours,
        p.outlier_std,
        c.after_outliers
    );
    match &seg.table {
        Some(t) => println!(
            "table plane: {} inliers, normal ({:.3}, {:.3}, {:.3}), height {:.3} m, rms {:.1} mm",
            c.table_inliers,
            t.normal.x,
            t.normal.y,
            t.normal.z,
            -t.offset / t.normal.z.max(1e-12),
            t.rms * 1e3
        ),
        None => println!("table plane: none found (every point is clustered)"),
    }
    println!(
        "above the table: {} points; components dropped: {} below {} points, {} above {}",
        c.above_table,
        c.small_components,
        p.min_cluster_points,
        c.large_components,
        p.max_cluster_points
    );
    println!("clusters: {} ({} points)", seg.clusters.len(), c.clustered);
    for (j, k) in seg.clusters.iter().enumerate() {
        let size = k.max - k.min;
        println!(
            "  #{j}: {} points, centroid {}, bbox {} .. {} ({:.3} x {:.3} x {:.3} m)",
            k.len(),
            fmt_point(&k.centroid),
            fmt_point(&k.min),
            fmt_point(&k.max),
            size.x,
            size.y,
            size.z
        );
    }
    let g = r.map.grid.geometry();
    let s = r.map.reduced.stats();
    let n = g.len();
    let [nx, ny, nz] = g.dims();
    println!(
        "grid: {nx} x {ny} x {nz} = {n} voxels of {} m from {} to {}",
        g.resolution(),
        fmt_point(&g.min()),
        fmt_point(&g.max())
    );
    println!(
        "  occupied {:.1}% ({}), empty {:.1}% ({}), unknown {:.1}% ({})",
        100.0 * share(s.grid.occupied, n),
        s.grid.occupied,
        100.0 * share(s.grid.empty, n),
        s.grid.empty,
        100.0 * share(s.grid.unknown, n),
        s.grid.unknown
    );
    println!(
        "  scan: {} rays, {} longer than {} m, {} hits outside the grid",
        r.map.scan.rays, r.map.scan.truncated, config.max_range, r.map.scan.hits_outside
    );
    println!(
        "reduced map: {} voxels ({} occupied + {} unknown crust); it removes {:.1}% of the \
         unknown voxels",
        s.occupied + s.unknown_crust,
        s.occupied,
        s.unknown_crust,
        100.0 * s.removed_unknown_share
    );
    println!("phase 1 took {elapsed:.2} s");
}
