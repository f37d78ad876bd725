//! The pictures of `nbv explore`: the scene, the map after phase 1 from the front and the
//! back framed on the objects, with the unknown crust around them (Figures 7–8), each object's view sequence (Figure 9) and its model before and after
//! registration coloured by view (Figure 11), and its fused surface shaded (`model_mesh.png`, the
//! same framing). Pictures only add to the run: without a GPU
//! adapter, or if drawing fails, a warning is printed and the run goes on.

use crate::error::{Context, Result};
use crate::report::ExploreReport;
use nalgebra::{Point3, Vector3};
use nbv_core::cloud::PointCloud;
use nbv_core::occupancy::ReducedMap;
use nbv_core::pipeline::Exploration;
use nbv_scenes::Scene;
use nbv_sim::render::{
    BACK_AZIMUTH, Camera, CloudColoring, Color, FRONT_AZIMUTH, LineSet, MeshItem, PointSet,
    RenderScene, Renderer, UnknownVoxels, fitted_front_and_back, front_and_back, map_items,
    map_items_around, save_png, scene_items,
};
use std::path::Path;

/// How far (m) around an object's cluster the map pictures show unknown voxels.
const CRUST_MARGIN: f64 = 0.06;
/// How much (m) around those regions the map pictures frame.
const FRAME_MARGIN: f64 = 0.10;
/// Elevation (rad) of the map pictures' cameras: from high enough that the crust in
/// front of an object does not hide its top.
const MAP_ELEVATION: f64 = 0.95;

const WIDTH: u32 = 1280;
const HEIGHT: u32 = 960;

/// Writes every picture into `out`; warns instead of failing.
pub fn write(out: &Path, scene: &Scene, exploration: &Exploration, report: &ExploreReport) {
    let renderer = match Renderer::new() {
        Ok(r) => r,
        Err(e) => {
            eprintln!("warning: pictures skipped: {e}");
            return;
        }
    };
    if let Err(e) = draw_all(&renderer, out, scene, exploration, report) {
        eprintln!("warning: pictures incomplete: {e:#}");
    }
}

fn draw_all(
    renderer: &Renderer,
    out: &Path,
    scene: &Scene,
    exploration: &Exploration,
    report: &ExploreReport,
) -> Result<()> {
    let aspect = f64::from(WIDTH) / f64::from(HEIGHT);
    let items = scene_items(scene).context("drawing the scene")?;
    let (front, back) = fitted_front_and_back(&items, aspect);
    draw(renderer, &items, &front, &out.join("scene.png"))?;
    draw(renderer, &items, &back, &out.join("scene_back.png"))?;

    let grid = &exploration.phase_one.grid;
    let reduced = ReducedMap::from_grid(grid);
    let g = grid.geometry();
    // As Figures 7–8: the objects' voxels and the unknown crust around them, framed on
    // the objects (the crust of the space the sweep never looked at would wall them in).
    let regions: Vec<_> = exploration
        .objects
        .iter()
        .filter_map(|o| o.cluster.bounds())
        .map(|(lo, hi)| grown(lo, hi, CRUST_MARGIN))
        .collect();
    let (map, (front, back)) = if regions.is_empty() {
        (
            map_items(grid, &reduced, UnknownVoxels::Occluded),
            front_and_back(g.min(), g.max(), aspect),
        )
    } else {
        let framed: Vec<_> = regions
            .iter()
            .flat_map(|(lo, hi)| corners(grown(*lo, *hi, FRAME_MARGIN)))
            .collect();
        (
            map_items_around(grid, &reduced, &regions),
            (
                Camera::fit(&framed, FRONT_AZIMUTH, MAP_ELEVATION, aspect),
                Camera::fit(&framed, BACK_AZIMUTH, MAP_ELEVATION, aspect),
            ),
        )
    };
    draw(renderer, &map, &front, &out.join("map_front.png"))?;
    draw(renderer, &map, &back, &out.join("map_back.png"))?;

    for (object, entry) in exploration.objects.iter().zip(&report.objects) {
        let dir = out.join("objects").join(&entry.name);
        // The view sequence: the object's points per view and each viewpoint's frustum.
        let mut seq = RenderScene::new();
        seq.add_points(PointSet::uniform(
            object.cluster.points.clone(),
            Color::categorical(0),
            3.0,
        ));
        let mut lines = LineSet::new(2.0);
        for (k, v) in object.views.iter().enumerate() {
            let c = Color::categorical(k + 1);
            seq.add_points(PointSet::uniform(v.cloud.points.clone(), c, 3.0));
            lines.append(&LineSet::frustum(
                &v.sensor_pose,
                0.8,
                0.62,
                0.02,
                0.12,
                c,
                2.0,
            ));
        }
        seq.add_lines(lines);
        let pts = seq.outline_points();
        let camera = Camera::fit(&pts, std::f64::consts::PI, 0.5, aspect);
        draw(renderer, &seq, &camera, &dir.join("views.png"))?;
        // Models before and after registration, coloured by view, from the same camera.
        let before = object.unregistered_model();
        let after = object.model()?;
        let camera = Camera::fit(&before.points, std::f64::consts::PI, 0.4, aspect);
        draw_cloud(renderer, &before, &camera, &dir.join("model_before.png"))?;
        draw_cloud(renderer, &after, &camera, &dir.join("model_after.png"))?;
        // The fused surface, shaded, from the same camera.
        if let Some(surface) = &object.surface {
            let mut items = RenderScene::new();
            items.add_mesh(MeshItem::smooth(
                surface.mesh.clone(),
                nalgebra::Isometry3::identity(),
                Color::categorical(0),
            ));
            draw(renderer, &items, &camera, &dir.join("model_mesh.png"))?;
        }
    }
    Ok(())
}

/// A box grown by `m` on every side.
fn grown(lo: Point3<f64>, hi: Point3<f64>, m: f64) -> (Point3<f64>, Point3<f64>) {
    let d = Vector3::repeat(m);
    (lo - d, hi + d)
}

/// The eight corners of a box.
fn corners((lo, hi): (Point3<f64>, Point3<f64>)) -> [Point3<f64>; 8] {
    std::array::from_fn(|k| {
        Point3::new(
            if k & 1 == 0 { lo.x } else { hi.x },
            if k & 2 == 0 { lo.y } else { hi.y },
            if k & 4 == 0 { lo.z } else { hi.z },
        )
    })
}

fn draw_cloud(renderer: &Renderer, cloud: &PointCloud, camera: &Camera, path: &Path) -> Result<()> {
    let coloring = if cloud.views.is_some() {
        CloudColoring::ByView
    } else {
        CloudColoring::Uniform(Color::categorical(0))
    };
    let mut items = RenderScene::new();
    items.add_points(PointSet::from_cloud(cloud, coloring, 3.0)?);
    draw(renderer, &items, camera, path)
}

fn draw(renderer: &Renderer, items: &RenderScene, camera: &Camera, path: &Path) -> Result<()> {
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    let image = renderer
        .render(items, camera, WIDTH, HEIGHT)
        .with_context(|| format!("rendering {}", path.display()))?;
    save_png(&image, path).with_context(|| format!("writing {}", path.display()))
}
