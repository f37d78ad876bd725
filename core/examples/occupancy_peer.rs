//! nbv's side of the OctoMap comparison (`benches/peers/octomap_insert.sh`): the
//! paper-scale synthetic sweep (275 lines × 200 rays, ~55K returns, 2 mm range noise,
//! origins off the voxel lattice) inserted into a
//! 60×70×30 grid of 2 cm voxels whose lower corner lies on OctoMap's lattice (every
//! coordinate a multiple of the resolution, so voxel boundaries coincide), timed, and
//! written for the peer script:
//!
//! - `cloud.ply`: the returns with their sensor origins (binary, doubles);
//! - `grid_per_line.nbvgrid`: one scan per scan line, as OctoMap's `insertPointCloud` is
//!   called once per line with that line's origin;
//! - `grid_one_scan.nbvgrid`: the whole sweep as one scan (what `nbv map` does);
//! - `nbv_timing.json`: median insertion times over the runs.
//!
//! Run: `cargo run --release -p nbv-core --example occupancy_peer -- OUTDIR [--runs N]`

use std::time::Instant;

use nalgebra::Point3;
use nbv_core::cloud::PointCloud;
use nbv_core::cloud::io::{FloatType, WriteOptions, write_cloud};
use nbv_core::occupancy::{GridGeometry, OccupancyGrid, OccupancyParams};

use nbv_fixtures::SyntheticSweep;

/// Lower corner of the grid: the paper's workspace with z moved down to 0.22 so that it
/// is a multiple of the 2 cm resolution, like x = 0.30 and y = −0.70.
const GRID_MIN: [f64; 3] = [0.30, -0.70, 0.22];
const RESOLUTION: f64 = 0.02;
const DIMS: [usize; 3] = [60, 70, 30];
const MAX_RANGE: f64 = 3.0;

/// Index ranges of consecutive rays that share an origin (one per scan line).
fn lines(origins: &[Point3<f64>]) -> Vec<std::ops::Range<usize>> {
    let mut out = Vec::new();
    let mut start = 0;
    for i in 1..=origins.len() {
        if i == origins.len() || origins[i] != origins[start] {
            out.push(start..i);
            start = i;
        }
    }
    out
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let out = std::path::PathBuf::from(
        args.next()
            .ok_or("usage: occupancy_peer OUTDIR [--runs N]")?,
    );
    let mut runs = 15usize;
    while let Some(a) = args.next() {
        match a.as_str() {
            "--runs" => runs = args.next().ok_or("--runs N")?.parse()?,
            other => return Err(format!("unknown argument {other}").into()),
        }
    }
    let runs = runs.max(1);
    std::fs::create_dir_all(&out)?;
    let (origins, points) = SyntheticSweep::paper_scale().noisy_scan(2014);
    let groups = lines(&origins);
    let geometry = GridGeometry::from_dims(Point3::from(GRID_MIN), RESOLUTION, DIMS)?;
    let params = OccupancyParams::default();

    let mut cloud = PointCloud::from_points(points.clone());
    cloud.origins = Some(origins.clone());
    let options = WriteOptions {
        float: FloatType::F64,
        ..WriteOptions::default()
    };
    write_cloud(out.join("cloud.ply"), &cloud, &options)?;

    let one_scan = || -> Result<OccupancyGrid, nbv_core::occupancy::OccupancyError> {
        let mut grid = OccupancyGrid::new(geometry, params)?;
        grid.insert_rays(&origins, &points, MAX_RANGE)?;
        Ok(grid)
    };
    let per_line = || -> Result<OccupancyGrid, nbv_core::occupancy::OccupancyError> {
        let mut grid = OccupancyGrid::new(geometry, params)?;
        for r in &groups {
            grid.insert_rays(&origins[r.clone()], &points[r.clone()], MAX_RANGE)?;
        }
        Ok(grid)
    };
    let one_thread = rayon::ThreadPoolBuilder::new().num_threads(1).build()?;
    let time =
        |f: &(dyn Fn() -> Result<OccupancyGrid, nbv_core::occupancy::OccupancyError> + Sync),
         pool: Option<&rayon::ThreadPool>|
         -> Result<(f64, OccupancyGrid), Box<dyn std::error::Error>> {
            let mut times = Vec::with_capacity(runs);
            let mut last = None;
            for _ in 0..runs {
                let t = Instant::now();
                let g = match pool {
                    Some(p) => p.install(f)?,
                    None => f()?,
                };
                times.push(t.elapsed().as_secs_f64());
                last = Some(g);
            }
            Ok((median(times), last.ok_or("no run")?))
        };
    let (t_one, grid_one) = time(&one_scan, None)?;
    let (t_one_1, _) = time(&one_scan, Some(&one_thread))?;
    let (t_line, grid_line) = time(&per_line, None)?;
    let (t_line_1, _) = time(&per_line, Some(&one_thread))?;
    grid_one.save(out.join("grid_one_scan.nbvgrid"))?;
    grid_line.save(out.join("grid_per_line.nbvgrid"))?;
    let threads = rayon::current_num_threads();
    let json = format!(
        "{{\n  \"rays\": {},\n  \"lines\": {},\n  \"runs\": {runs},\n  \"threads\": {threads},\n  \
         \"one_scan_s\": {t_one},\n  \"one_scan_1_thread_s\": {t_one_1},\n  \
         \"per_line_s\": {t_line},\n  \"per_line_1_thread_s\": {t_line_1}\n}}\n",
        points.len(),
        groups.len()
    );
    std::fs::write(out.join("nbv_timing.json"), &json)?;
    let c = grid_line.state_counts();
    println!(
        "nbv: {} rays in {} lines into {:?} voxels of {} m; median of {runs} runs:",
        points.len(),
        groups.len(),
        DIMS,
        RESOLUTION
    );
    println!(
        "  one scan:      {:.2} ms ({threads} threads), {:.2} ms (1 thread)",
        t_one * 1e3,
        t_one_1 * 1e3
    );
    println!(
        "  per scan line: {:.2} ms ({threads} threads), {:.2} ms (1 thread)",
        t_line * 1e3,
        t_line_1 * 1e3
    );
    println!(
        "  per-line grid: {} occupied, {} empty, {} unknown",
        c.occupied, c.empty, c.unknown
    );
    Ok(())
}
