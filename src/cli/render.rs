//! `nbv render …`: PNG pictures of a scene, of point clouds and of an occupancy map, drawn
//! headless with the twin's wgpu renderer; and [`map_pictures_or_warn`] for commands whose
//! pictures are only a by-product (they warn and go on without a GPU).

use anyhow::{Context, Result, bail};
use clap::{Args, Subcommand};
use nbv_core::cloud::io::read_cloud;
use nbv_core::occupancy::{OccupancyGrid, ReducedMap};
use nbv_sim::render::{
    Camera, Color, PointSet, RenderScene, Renderer, UnknownVoxels, fitted_front_and_back,
    front_and_back, map_items, save_png, scene_items,
};
use std::path::{Path, PathBuf};

/// Arguments of `nbv render`.
#[derive(Debug, Args)]
pub struct RenderArgs {
    #[command(subcommand)]
    command: RenderCommand,
}

/// Picture size shared by every picture command.
#[derive(Debug, Clone, Copy, Args)]
struct Size {
    /// Image width in pixels.
    #[arg(long, default_value_t = 1280, value_parser = clap::value_parser!(u32).range(16..=8192))]
    width: u32,
    /// Image height in pixels.
    #[arg(long, default_value_t = 960, value_parser = clap::value_parser!(u32).range(16..=8192))]
    height: u32,
}

impl Size {
    fn aspect(&self) -> f64 {
        f64::from(self.width) / f64::from(self.height)
    }
}

#[derive(Debug, Subcommand)]
enum RenderCommand {
    /// The scene: robot at its home configuration, table, obstacles, objects and the
    /// workspace box, seen from the front (the robot's side) and optionally from the back.
    Scene {
        /// Scene file or built-in scene name (see `nbv scene list`).
        #[arg(long)]
        scene: String,
        /// Front view PNG.
        #[arg(short, long)]
        output: PathBuf,
        /// Back view PNG.
        #[arg(long)]
        back: Option<PathBuf>,
        #[command(flatten)]
        size: Size,
    },
    /// Point clouds (PLY or PCD), one colour per file, framed to fit all of them.
    Cloud {
        /// The clouds.
        #[arg(required = true)]
        clouds: Vec<PathBuf>,
        /// Front view PNG.
        #[arg(short, long)]
        output: PathBuf,
        /// Back view PNG.
        #[arg(long)]
        back: Option<PathBuf>,
        /// Point size in pixels.
        #[arg(long, default_value_t = 3.0)]
        point_size: f32,
        #[command(flatten)]
        size: Size,
    },
    /// An occupancy map written by `nbv map` (MAPDIR/grid.nbvgrid): its reduced map,
    /// occupied voxels red and unknown crust voxels grey, as in the paper's Figures 7–8.
    Map {
        /// Directory written by `nbv map`.
        mapdir: PathBuf,
        /// Front view PNG.
        #[arg(short, long)]
        output: PathBuf,
        /// Back view PNG.
        #[arg(long)]
        back: Option<PathBuf>,
        /// Unknown voxels drawn: `occluded` (the crust under observed free space: the
        /// shadows of objects and obstacles), `crust` (all of M̄'s unknown voxels, which
        /// also wall in the space the sensor never looked at), or `none`.
        #[arg(long, value_enum, default_value_t = Unknown::Occluded)]
        unknown: Unknown,
        #[command(flatten)]
        size: Size,
    },
}

/// `--unknown` of `nbv render map`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum Unknown {
    Occluded,
    Crust,
    None,
}

impl From<Unknown> for UnknownVoxels {
    fn from(u: Unknown) -> Self {
        match u {
            Unknown::Occluded => UnknownVoxels::Occluded,
            Unknown::Crust => UnknownVoxels::Crust,
            Unknown::None => UnknownVoxels::None,
        }
    }
}

/// Runs `nbv render …`.
pub fn run(args: RenderArgs) -> Result<()> {
    match args.command {
        RenderCommand::Scene {
            scene,
            output,
            back,
            size,
        } => {
            let s = nbv_scenes::overrides::load(&scene)?;
            let items = scene_items(&s).with_context(|| format!("drawing {scene}"))?;
            let renderer = renderer()?;
            let cameras = fitted_front_and_back(&items, size.aspect());
            draw_pair(&renderer, &items, cameras, size, &output, back.as_deref())
        }
        RenderCommand::Cloud {
            clouds,
            output,
            back,
            point_size,
            size,
        } => {
            let mut items = RenderScene::new();
            for (i, path) in clouds.iter().enumerate() {
                let cloud =
                    read_cloud(path).with_context(|| format!("reading {}", path.display()))?;
                if cloud.is_empty() {
                    eprintln!("note: {} has no points", path.display());
                }
                let color = Color::categorical(i);
                println!(
                    "{}: {} points, colour #{:02x}{:02x}{:02x}",
                    path.display(),
                    cloud.len(),
                    color.to_srgb8()[0],
                    color.to_srgb8()[1],
                    color.to_srgb8()[2]
                );
                items.add_points(PointSet::uniform(cloud.points, color, point_size));
            }
            if items.bounds().is_none() {
                bail!("the clouds have no points to draw");
            }
            let renderer = renderer()?;
            let cameras = fitted_front_and_back(&items, size.aspect());
            draw_pair(&renderer, &items, cameras, size, &output, back.as_deref())
        }
        RenderCommand::Map {
            mapdir,
            output,
            back,
            unknown,
            size,
        } => {
            let path = mapdir.join("grid.nbvgrid");
            let grid = OccupancyGrid::load(&path)
                .with_context(|| format!("reading {}", path.display()))?;
            let reduced = ReducedMap::from_grid(&grid);
            let s = reduced.stats();
            println!(
                "{}: reduced map of {} occupied and {} unknown crust voxels",
                path.display(),
                s.occupied,
                s.unknown_crust
            );
            let g = grid.geometry();
            let renderer = renderer()?;
            let cameras = front_and_back(g.min(), g.max(), size.aspect());
            draw_pair(
                &renderer,
                &map_items(&grid, &reduced, unknown.into()),
                cameras,
                size,
                &output,
                back.as_deref(),
            )
        }
    }
}

/// The renderer, or an error that names the missing drivers.
fn renderer() -> Result<Renderer> {
    Renderer::new().context("`nbv render` needs a GPU or Mesa's software drivers")
}

/// Draws `items` seen by the front camera (and, if asked, by the back one).
fn draw_pair(
    renderer: &Renderer,
    items: &RenderScene,
    (front, back): (Camera, Camera),
    size: Size,
    front_path: &Path,
    back_path: Option<&Path>,
) -> Result<()> {
    draw(renderer, items, &front, size, front_path)?;
    if let Some(p) = back_path {
        draw(renderer, items, &back, size, p)?;
    }
    Ok(())
}

fn draw(
    renderer: &Renderer,
    items: &RenderScene,
    camera: &Camera,
    size: Size,
    path: &Path,
) -> Result<()> {
    let image = renderer
        .render(items, camera, size.width, size.height)
        .with_context(|| format!("rendering {}", path.display()))?;
    save_png(&image, path).with_context(|| format!("writing {}", path.display()))?;
    println!("wrote {} ({}x{})", path.display(), size.width, size.height);
    Ok(())
}

/// Pictures of a reduced map from the front and the back, for commands whose pictures
/// only add to other work: without a renderer (the message names the missing drivers), or
/// if drawing fails, it prints a warning and returns normally.
pub fn map_pictures_or_warn(grid: &OccupancyGrid, reduced: &ReducedMap, front: &Path, back: &Path) {
    let renderer = match Renderer::new() {
        Ok(r) => r,
        Err(e) => {
            eprintln!("warning: pictures skipped: {e}");
            return;
        }
    };
    let g = grid.geometry();
    let size = Size {
        width: 1280,
        height: 960,
    };
    if let Err(e) = draw_pair(
        &renderer,
        &map_items(grid, reduced, UnknownVoxels::Occluded),
        front_and_back(g.min(), g.max(), size.aspect()),
        size,
        front,
        Some(back),
    ) {
        eprintln!("warning: no pictures: {e:#}");
    }
}
