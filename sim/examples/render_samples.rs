//! Writes sample pictures of a table-top scene to `target/render-samples/` (or the
//! directory given as the first argument): the scene from the front and from the back,
//! an occupancy map (occupied red, unknown grey), point clouds coloured by view, and
//! viewpoints with their frusta. Run: `cargo run -p nbv-sim --example render_samples`.

use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};
use nbv_sim::render::{
    Camera, Color, LineSet, MeshItem, PointSet, RenderError, RenderScene, Renderer, VoxelSet,
    save_png, tessellate,
};
use std::path::PathBuf;

const W: u32 = 1280;
const H: u32 = 960;

fn pose(x: f64, y: f64, z: f64) -> Isometry3<f64> {
    Isometry3::translation(x, y, z)
}

/// A rough arm made of primitives: base, shoulder, upper arm, forearm, wrist.
fn robot(scene: &mut RenderScene) {
    let grey = Color::rgb(0.55, 0.56, 0.6);
    let orange = Color::rgb(0.93, 0.55, 0.15);
    scene.add_mesh(MeshItem::smooth(
        tessellate::cylinder(0.2, 0.3, 48),
        pose(0.0, 0.0, 0.15),
        grey,
    ));
    scene.add_mesh(MeshItem::smooth(
        tessellate::cylinder(0.14, 0.2, 48),
        pose(0.0, 0.0, 0.4),
        orange,
    ));
    // Upper arm from the shoulder (0.15, 0, 0.45) up and forward.
    let link = |scene: &mut RenderScene, a: Point3<f64>, b: Point3<f64>, r: f64, c: Color| {
        let d = b - a;
        let rot = UnitQuaternion::rotation_between(&Vector3::z(), &d).unwrap_or_default();
        let p = Isometry3::from_parts(Translation3::from(nalgebra::center(&a, &b).coords), rot);
        scene.add_mesh(MeshItem::smooth(
            tessellate::cylinder(r, d.norm(), 40),
            p,
            c,
        ));
        scene.add_mesh(MeshItem::smooth(
            tessellate::sphere(r * 1.15, 16, 32),
            Isometry3::translation(b.x, b.y, b.z),
            grey,
        ));
    };
    let shoulder = Point3::new(0.15, 0.0, 0.45);
    let elbow = Point3::new(0.25, 0.0, 1.03);
    let wrist = Point3::new(0.85, 0.0, 1.0);
    link(scene, shoulder, elbow, 0.09, orange);
    link(scene, elbow, wrist, 0.07, orange);
    link(scene, wrist, Point3::new(0.95, 0.0, 0.93), 0.04, grey);
}

fn table_and_objects(scene: &mut RenderScene) {
    scene.add_mesh(MeshItem::flat(
        tessellate::cuboid([1.4, 1.6, 0.04]),
        pose(0.9, 0.0, 0.21),
        Color::rgb(0.78, 0.66, 0.5),
    ));
    for (x, y) in [(0.25, -0.75), (0.25, 0.75), (1.55, -0.75), (1.55, 0.75)] {
        scene.add_mesh(MeshItem::flat(
            tessellate::cuboid([0.05, 0.05, 0.19]),
            pose(x, y, 0.095),
            Color::rgb(0.5, 0.42, 0.32),
        ));
    }
    let objects = [
        (
            tessellate::cylinder(0.06, 0.22, 48),
            pose(0.8, -0.3, 0.34),
            Color::rgb(0.2, 0.45, 0.85),
        ),
        (
            tessellate::cylinder(0.035, 0.25, 48),
            pose(0.95, 0.05, 0.355),
            Color::rgb(0.25, 0.7, 0.35),
        ),
        (
            tessellate::cylinder(0.035, 0.25, 48),
            pose(0.7, 0.25, 0.355),
            Color::rgb(0.9, 0.75, 0.2),
        ),
        (
            tessellate::cuboid([0.16, 0.1, 0.12]),
            pose(1.1, -0.1, 0.29),
            Color::rgb(0.8, 0.3, 0.25),
        ),
        (
            tessellate::sphere(0.06, 24, 48),
            pose(1.05, 0.35, 0.29),
            Color::rgb(0.65, 0.35, 0.75),
        ),
    ];
    for (mesh, p, c) in objects {
        scene.add_mesh(MeshItem::smooth(mesh, p, c));
    }
    // Obstacles at the back.
    for y in [-0.45, 0.0, 0.45] {
        scene.add_mesh(MeshItem::flat(
            tessellate::cuboid([0.05, 0.3, 0.45]),
            pose(1.4, y, 0.455),
            Color::rgb(0.45, 0.47, 0.5),
        ));
    }
}

/// Occupancy-style voxels (2 cm) of the objects' volumes: surface cells occupied, interior
/// cells unknown, plus an unknown shadow behind every object as the sensor would leave it.
fn occupancy() -> (Vec<Point3<f64>>, Vec<Point3<f64>>) {
    let res = 0.02;
    let mut occ = Vec::new();
    let mut unk = Vec::new();
    let shapes: [(Point3<f64>, f64, f64); 3] = [
        (Point3::new(0.8, -0.3, 0.34), 0.06, 0.22),
        (Point3::new(0.95, 0.05, 0.355), 0.035, 0.25),
        (Point3::new(0.7, 0.25, 0.355), 0.035, 0.25),
    ];
    for (c, r, h) in shapes {
        let n = (r / res).ceil() as i32 + 1;
        let m = (h / 2.0 / res).ceil() as i32;
        for i in -n..=n {
            for j in -n..=n {
                for k in -m..m {
                    let p = Point3::new(
                        c.x + f64::from(i) * res,
                        c.y + f64::from(j) * res,
                        c.z + (f64::from(k) + 0.5) * res,
                    );
                    let d = ((p.x - c.x).powi(2) + (p.y - c.y).powi(2)).sqrt();
                    if d <= r + res * 0.5 {
                        // Front half (facing the robot, -x) seen: occupied; back half unknown.
                        if p.x <= c.x { occ.push(p) } else { unk.push(p) }
                    }
                }
            }
        }
    }
    (occ, unk)
}

fn clouds_by_view() -> PointSet {
    // Points sampled on the three cylinders' sides, split into four views by azimuth.
    let mut points = Vec::new();
    let mut colors = Vec::new();
    let shapes = [
        (Point3::new(0.8, -0.3, 0.34), 0.06, 0.22),
        (Point3::new(0.95, 0.05, 0.355), 0.035, 0.25),
        (Point3::new(0.7, 0.25, 0.355), 0.035, 0.25),
    ];
    for (c, r, h) in shapes {
        for a in 0..180 {
            let t = std::f64::consts::TAU * f64::from(a) / 180.0;
            for k in 0..40 {
                let z = c.z - h / 2.0 + h * f64::from(k) / 39.0;
                points.push(Point3::new(c.x + r * t.cos(), c.y + r * t.sin(), z));
                colors.push(Color::categorical(a as usize * 4 / 180));
            }
        }
    }
    PointSet {
        points,
        colors,
        size: 3.0,
    }
}

fn viewpoints(scene: &mut RenderScene) {
    for (i, (x, y, z)) in [
        (0.45, -0.4, 0.75),
        (0.5, 0.35, 0.8),
        (0.95, -0.6, 0.7),
        (1.1, 0.6, 0.72),
    ]
    .into_iter()
    .enumerate()
    {
        let eye = Point3::new(x, y, z);
        let target = Point3::new(0.85, 0.0, 0.35);
        // Optical frame: +z towards the target, x right, y down.
        let zc = (target - eye).normalize();
        let xc = zc.cross(&Vector3::z()).normalize();
        let yc = zc.cross(&xc);
        let rot = UnitQuaternion::from_matrix(&nalgebra::Matrix3::from_columns(&[xc, yc, zc]));
        let p = Isometry3::from_parts(Translation3::from(eye.coords), rot);
        let color = Color::categorical(i);
        scene.add_lines(LineSet::frustum(&p, 0.9, 0.7, 0.02, 0.25, color, 2.5));
        scene.add_lines(LineSet::axes(&p, 0.06, 3.0));
    }
}

fn main() -> Result<(), RenderError> {
    let dir = std::env::args()
        .nth(1)
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from("target/render-samples"));
    std::fs::create_dir_all(&dir).map_err(|e| RenderError::Write {
        path: dir.clone(),
        detail: e.to_string(),
    })?;
    let renderer = Renderer::new()?;
    println!(
        "adapter: {}, {}x MSAA",
        renderer.adapter_summary(),
        renderer.sample_count()
    );
    let (lo, hi) = (
        Point3::new(0.30, -0.70, 0.23),
        Point3::new(1.50, 0.70, 0.83),
    );
    let front = Camera::front_of(lo, hi, 4.0 / 3.0);
    let back = Camera::back_of(lo, hi, 4.0 / 3.0);

    let mut scene = RenderScene::new();
    robot(&mut scene);
    table_and_objects(&mut scene);
    scene.add_lines(LineSet::aabb(lo, hi, Color::rgb(0.2, 0.2, 0.2), 1.5));
    let wide = Camera::framing(
        Point3::new(-0.3, -0.9, 0.0),
        Point3::new(1.6, 0.9, 1.2),
        2.4,
        0.45,
        4.0 / 3.0,
    );
    save_png(
        &renderer.render(&scene, &wide, W, H)?,
        dir.join("scene.png"),
    )?;
    save_png(
        &renderer.render(&scene, &front, W, H)?,
        dir.join("scene_front.png"),
    )?;
    save_png(
        &renderer.render(&scene, &back, W, H)?,
        dir.join("scene_back.png"),
    )?;

    let (occ, unk) = occupancy();
    let mut map = RenderScene::new();
    map.add_voxels(VoxelSet::uniform(occ, 0.02, Color::OCCUPIED));
    map.add_voxels(VoxelSet::uniform(unk, 0.02, Color::UNKNOWN));
    map.add_lines(LineSet::aabb(lo, hi, Color::rgb(0.2, 0.2, 0.2), 1.5));
    save_png(
        &renderer.render(&map, &front, W, H)?,
        dir.join("occupancy_front.png"),
    )?;
    save_png(
        &renderer.render(&map, &back, W, H)?,
        dir.join("occupancy_back.png"),
    )?;

    let mut clouds = RenderScene::new();
    clouds.add_points(clouds_by_view());
    viewpoints(&mut clouds);
    let (clo, chi) = clouds.bounds().unwrap_or((lo, hi));
    let close = Camera::framing(clo, chi, 2.6, 0.5, 4.0 / 3.0);
    save_png(
        &renderer.render(&clouds, &close, W, H)?,
        dir.join("clouds_views.png"),
    )?;
    println!("wrote {}", dir.display());
    Ok(())
}
