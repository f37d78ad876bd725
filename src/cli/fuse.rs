//! `nbv fuse DIR -o mesh.ply`: depth views in Open3D's reconstruction-system layout (an
//! episode's `objects/<name>/rgbd/` or another dataset) fused into a surface mesh by the
//! TSDF the episodes use; `--truth` scores it against a true mesh. This file parses the
//! arguments and prints.

use anyhow::{Context, Result};
use clap::Args;
use nbv_core::evaluation::{MeshQuality, mesh_quality};
use nbv_core::mesh::io::{read_mesh, write_ply_mesh};
use nbv_core::surface::{RgbdDataset, TsdfParams};
use std::path::PathBuf;
use std::time::Instant;

/// Arguments of `nbv fuse`.
#[derive(Debug, Args)]
pub struct FuseArgs {
    /// The dataset: depth/*.png (16-bit, mm), camera_intrinsic.json, trajectory.log
    /// (camera-to-world), and optionally noise.json (nbv's depth noise model).
    pub dir: Option<PathBuf>,
    /// The mesh to write (binary PLY with normals).
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// TSDF voxel edge (m); the scene default `[model] voxel`.
    #[arg(long, default_value_t = TsdfParams::default().voxel)]
    pub voxel: f64,
    /// TSDF truncation (m); the scene default `[model] truncation`.
    #[arg(long, default_value_t = TsdfParams::default().truncation)]
    pub truncation: f64,
    /// Observations a voxel needs for the mesh to pass through it.
    #[arg(long, default_value_t = TsdfParams::default().min_observations)]
    pub min_observations: u16,
    /// Instead of fusing, score this mesh (OBJ or STL, world frame) against `--truth`: its
    /// F-score, precision and completeness at 2, 5 and 10 mm and Chamfer, as JSON.
    #[arg(long)]
    pub score: Option<PathBuf>,
    /// The true mesh (STL or OBJ, world frame) to score the result against, at 2, 5 and
    /// 10 mm above its lowest point + 5 mm (the table top + 5 mm, as the report).
    #[arg(long)]
    pub truth: Option<PathBuf>,
}

/// Runs `nbv fuse`.
pub fn run(args: FuseArgs) -> Result<()> {
    let params = TsdfParams {
        voxel: args.voxel,
        truncation: args.truncation,
        min_observations: args.min_observations,
    };
    params.validate()?;
    if let Some(mesh) = &args.score {
        let truth = args.truth.as_ref().context("--score needs --truth")?;
        let m = read_mesh(mesh)?;
        print_quality(&score(&m, truth)?);
        return Ok(());
    }
    let dir = args
        .dir
        .context("the dataset directory is missing (nbv fuse DIR -o mesh.ply)")?;
    let output = args.output.context("-o mesh.ply is missing")?;
    let dataset = RgbdDataset::read(&dir)?;
    let start = Instant::now();
    let surface = dataset.fuse(params)?;
    let seconds = start.elapsed().as_secs_f64();
    write_ply_mesh(&surface.mesh, &surface.normals, &output)
        .with_context(|| format!("writing {}", output.display()))?;
    println!(
        "{}: {} view(s) fused in {:.1} ms ({:.2} ms per view): {} triangles, {} vertices -> {}",
        dir.display(),
        dataset.views.len(),
        seconds * 1e3,
        seconds * 1e3 / dataset.views.len().max(1) as f64,
        surface.mesh.triangles.len(),
        surface.mesh.vertices.len(),
        output.display()
    );
    if let Some(truth) = &args.truth {
        print_quality(&score(&surface.mesh, truth)?);
    }
    Ok(())
}

fn score(mesh: &nbv_core::mesh::TriMesh, truth: &std::path::Path) -> Result<MeshQuality> {
    let t = read_mesh(truth)?;
    let floor = t.bounds().map_or(f64::MIN, |(lo, _)| lo.z + 0.005);
    mesh_quality(&t, mesh, floor, 0)
        .context("an empty mesh, or a truth with nothing above its floor")
}

fn print_quality(q: &MeshQuality) {
    println!("{}", serde_json::to_string(q).unwrap_or_default());
}
