//! Adapters from a scene to drawables: the robot's links from its URDF geometry at a
//! configuration, the table, the obstacles and the objects, the workspace box, and the
//! default front and back cameras.

use super::{Camera, Color, LineSet, MeshItem, RenderScene, tessellate};
use nalgebra::{Isometry3, Point3};
use nbv_core::kinematics::{Joints, LinkGeometry, Robot, Shape};
use nbv_core::math::Pose;
use nbv_core::mesh::TriMesh;
use nbv_scenes::Scene;
use nbv_scenes::placed::table_mesh;
use std::path::{Path, PathBuf};
use thiserror::Error;

/// Sides of tessellated cylinders and sphere sectors.
const SEGMENTS: usize = 48;
/// Colour of the table top.
pub const TABLE_COLOR: Color = Color::rgb(0.80, 0.70, 0.55);
/// Colour of obstacles the planner knows.
pub const OBSTACLE_COLOR: Color = Color::rgb(0.50, 0.53, 0.58);
/// Colour of obstacles the planner does not know.
pub const UNKNOWN_OBSTACLE_COLOR: Color = Color::rgb(0.36, 0.34, 0.42);
/// Colour of robot links whose URDF visual has no colour.
pub const ROBOT_COLOR: Color = Color::rgb(0.62, 0.64, 0.68);
/// Colour of the workspace box edges.
pub const WORKSPACE_COLOR: Color = Color::rgb(0.25, 0.25, 0.25);

/// Why a scene could not be turned into drawables.
#[derive(Debug, Error)]
pub enum SceneItemsError {
    /// The robot's URDF could not be read.
    #[error("{scene}: robot: {source}")]
    Robot {
        /// Scene name.
        scene: String,
        /// The URDF loader's error.
        #[source]
        source: nbv_core::kinematics::UrdfError,
    },
    /// An object or obstacle mesh could not be read.
    #[error(transparent)]
    Scene(#[from] Box<nbv_scenes::SceneError>),
    /// A link's mesh named in the URDF could not be read.
    #[error("link `{link}`: mesh {file}: {detail}")]
    LinkMesh {
        /// Link name.
        link: String,
        /// The mesh file as resolved.
        file: PathBuf,
        /// What went wrong.
        detail: String,
    },
}

/// The colour of object `i` in scene pictures: the categorical palette from its second
/// colour on (its first, a steel blue, is too close to the robot's Comau blue).
pub fn object_color(i: usize) -> Color {
    Color::categorical(i + 1)
}

/// The robot's links at configuration `q` with the robot mounted at `base`, from the
/// URDF's `<visual>` elements (or its `<collision>` elements when it has no visual at
/// all). Boxes, cylinders, capsules and spheres are tessellated; a `<mesh>` is read from
/// its file (STL or OBJ), resolved against `urdf_dir` after stripping `file://` or
/// `package://` (then, if absent, also without the package name).
///
/// ```
/// # let path = nbv_core::kinematics::COMAU_URDF;
/// use nbv_core::kinematics::{Joints, Robot};
/// let robot = Robot::from_urdf_file(path).unwrap();
/// let dir = std::path::Path::new(path).parent().unwrap();
/// let q = Joints::new(0.0, 0.0, -90f64.to_radians(), 0.0, 0.0, 0.0);
/// let links = nbv_sim::render::robot_items(&robot, &nalgebra::Isometry3::identity(), &q, dir).unwrap();
/// assert_eq!(links.len(), robot.visual_geometry().len());
/// ```
pub fn robot_items(
    robot: &Robot,
    base: &Pose,
    q: &Joints,
    urdf_dir: &Path,
) -> Result<Vec<MeshItem>, SceneItemsError> {
    let poses = robot.link_poses(q);
    let geometry = if robot.visual_geometry().is_empty() {
        robot.collision_geometry()
    } else {
        robot.visual_geometry()
    };
    let mut items = Vec::with_capacity(geometry.len());
    for g in geometry {
        let Some(link_pose) = poses.get(g.frame) else {
            continue;
        };
        let color = g.rgba.map_or(ROBOT_COLOR, |[r, gr, b, a]| {
            Color::rgba(r as f32, gr as f32, b as f32, a as f32)
        });
        let pose = base * link_pose * g.origin;
        let (mesh, smooth) = link_mesh(g, urdf_dir)?;
        items.push(if smooth {
            MeshItem::smooth(mesh, pose, color)
        } else {
            MeshItem::flat(mesh, pose, color)
        });
    }
    Ok(items)
}

/// The mesh of one URDF element in its own frame, and whether to shade it smooth.
fn link_mesh(g: &LinkGeometry, urdf_dir: &Path) -> Result<(TriMesh, bool), SceneItemsError> {
    Ok(match &g.shape {
        Shape::Box { size } => (tessellate::cuboid(*size), false),
        Shape::Cylinder { radius, length } => {
            (tessellate::cylinder(*radius, *length, SEGMENTS), true)
        }
        Shape::Sphere { radius } => (tessellate::sphere(*radius, SEGMENTS / 2, SEGMENTS), true),
        Shape::Capsule { radius, length } => {
            let mut m = tessellate::cylinder(*radius, *length, SEGMENTS);
            for z in [-length / 2.0, length / 2.0] {
                m.append(
                    &tessellate::sphere(*radius, SEGMENTS / 2, SEGMENTS)
                        .transformed(&Isometry3::translation(0.0, 0.0, z)),
                );
            }
            (m, true)
        }
        Shape::Mesh { filename, scale } => {
            let file = resolve_mesh(filename, urdf_dir);
            let mut m =
                nbv_core::mesh::io::read_mesh(&file).map_err(|e| SceneItemsError::LinkMesh {
                    link: g.link.clone(),
                    file: file.clone(),
                    detail: e.to_string(),
                })?;
            for v in &mut m.vertices {
                *v = Point3::new(v.x * scale[0], v.y * scale[1], v.z * scale[2]);
            }
            (m, true)
        }
    })
}

/// A URDF mesh reference as a path: `file://` and `package://` are stripped and the rest
/// is taken relative to the URDF's directory; for `package://pkg/rest`, `rest` is tried
/// when `pkg/rest` does not exist.
fn resolve_mesh(filename: &str, urdf_dir: &Path) -> PathBuf {
    if let Some(abs) = filename.strip_prefix("file://") {
        return PathBuf::from(abs);
    }
    match filename.strip_prefix("package://") {
        Some(rest) => {
            let full = urdf_dir.join(rest);
            if full.exists() {
                return full;
            }
            match rest.split_once('/') {
                Some((_, inner)) => urdf_dir.join(inner),
                None => full,
            }
        }
        None => urdf_dir.join(filename),
    }
}

/// Everything a scene shows: the robot at its home configuration, the table, the
/// obstacles (known ones grey-blue, unknown ones darker), the objects in
/// [`object_color`] and the workspace box as thin lines.
///
/// ```no_run
/// let scene = nbv_scenes::builtin::load("paper-env1")?;
/// let items = nbv_sim::render::scene_items(&scene)?;
/// assert_eq!(items.meshes.iter().filter(|m| m.color == nbv_sim::render::object_color(0)).count(), 1);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn scene_items(scene: &Scene) -> Result<RenderScene, SceneItemsError> {
    let mut items = RenderScene::new();
    let robot =
        Robot::from_urdf_file(&scene.robot.urdf).map_err(|source| SceneItemsError::Robot {
            scene: scene.name.clone(),
            source,
        })?;
    let urdf_dir = scene
        .robot
        .urdf
        .parent()
        .map_or_else(|| PathBuf::from("."), Path::to_path_buf);
    let home = crate::world::home_configuration(scene);
    for m in robot_items(&robot, &scene.robot.base.to_pose(), &home, &urdf_dir)? {
        items.add_mesh(m);
    }
    items.add_mesh(MeshItem::flat(
        table_mesh(&scene.table),
        Isometry3::identity(),
        TABLE_COLOR,
    ));
    let obstacles = scene.obstacle_meshes().map_err(Box::new)?;
    for (o, mesh) in scene.obstacles.iter().zip(obstacles) {
        let color = if o.known {
            OBSTACLE_COLOR
        } else {
            UNKNOWN_OBSTACLE_COLOR
        };
        items.add_mesh(MeshItem::flat(mesh, Isometry3::identity(), color));
    }
    let objects = scene.object_meshes().map_err(Box::new)?;
    for (i, mesh) in objects.into_iter().enumerate() {
        items.add_mesh(MeshItem::smooth(
            mesh,
            Isometry3::identity(),
            object_color(i),
        ));
    }
    let (lo, hi) = workspace_bounds(scene);
    items.add_lines(LineSet::aabb(lo, hi, WORKSPACE_COLOR, 1.5));
    Ok(items)
}

/// The scene's workspace box.
pub fn workspace_bounds(scene: &Scene) -> (Point3<f64>, Point3<f64>) {
    (
        Point3::from(scene.workspace.min),
        Point3::from(scene.workspace.max),
    )
}

/// Azimuth of [`fitted_front_and_back`]'s front camera: from the robot's side and to the
/// left, so that the arm does not hide the table.
pub const FRONT_AZIMUTH: f64 = std::f64::consts::PI - 0.8;
/// Azimuth of [`fitted_front_and_back`]'s back camera: from behind and to the right.
pub const BACK_AZIMUTH: f64 = -0.8;
/// Elevation of [`fitted_front_and_back`]'s cameras.
pub const VIEW_ELEVATION: f64 = 0.55;

/// Cameras that frame everything `items` draws as tightly as fits an image of aspect
/// `width / height`, from the front-left ([`FRONT_AZIMUTH`]) and from the back-right
/// ([`BACK_AZIMUTH`]): for scenes with the robot, and for point clouds.
///
/// ```
/// use nbv_sim::render::{Color, LineSet, RenderScene, fitted_front_and_back};
/// use nalgebra::Point3;
/// let mut items = RenderScene::new();
/// items.add_lines(LineSet::aabb(Point3::origin(), Point3::new(1.0, 1.0, 0.5), Color::BLACK, 1.0));
/// let (front, back) = fitted_front_and_back(&items, 4.0 / 3.0);
/// assert!(front.eye.x < 0.0 && back.eye.x > 1.0);
/// ```
pub fn fitted_front_and_back(items: &RenderScene, aspect: f64) -> (Camera, Camera) {
    let points = items.outline_points();
    (
        Camera::fit(&points, FRONT_AZIMUTH, VIEW_ELEVATION, aspect),
        Camera::fit(&points, BACK_AZIMUTH, VIEW_ELEVATION, aspect),
    )
}

/// The default cameras of a box (a workspace) for images of aspect `width / height`: from
/// the front (the robot's side) and from the back, as in the paper's Figures 7–8.
///
/// ```
/// use nalgebra::Point3;
/// let (lo, hi) = (Point3::new(0.30, -0.70, 0.23), Point3::new(1.50, 0.70, 0.83));
/// let (front, back) = nbv_sim::render::front_and_back(lo, hi, 4.0 / 3.0);
/// assert!(front.eye.x < lo.x && back.eye.x > hi.x);
/// ```
pub fn front_and_back(min: Point3<f64>, max: Point3<f64>, aspect: f64) -> (Camera, Camera) {
    (
        Camera::front_of(min, max, aspect),
        Camera::back_of(min, max, aspect),
    )
}
