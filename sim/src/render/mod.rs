//! Headless pictures of the twin: a wgpu renderer that draws a [`RenderScene`] of plain
//! drawables (shaded triangle meshes, point sprites, instanced voxel cubes, thick line
//! segments) seen by a look-at [`Camera`] into an offscreen texture, and returns an
//! [`image::RgbaImage`] that [`save_png`] writes atomically.
//!
//! There is no window and no display: the [`Renderer`] asks wgpu for any adapter, hardware
//! or software (Mesa's lavapipe through Vulkan, llvmpipe through GL/EGL), honouring
//! `WGPU_BACKEND`. When none exists, [`Renderer::new`] returns [`RenderError::NoAdapter`],
//! whose message names the packages to install; [`Renderer::optional`] logs that as a
//! warning instead, for commands whose pictures are a by-product.
//!
//! Adapters turn the project's data into drawables: [`scene_items`] (robot at home, table,
//! obstacles, objects), [`robot_items`], [`map_items`] (the reduced map, Figures 7–8),
//! with [`front_and_back`] cameras.
//!
//! World coordinates are the robot base frame (x forward, y left, z up), in metres.
//!
//! ```no_run
//! use nbv_sim::render::{Camera, Color, MeshItem, RenderScene, Renderer, save_png};
//! use nbv_core::mesh::TriMesh;
//! use nalgebra::{Isometry3, Point3, Vector3};
//!
//! let mut scene = RenderScene::new();
//! scene.add_mesh(MeshItem::flat(
//!     TriMesh::cuboid([0.1, 0.1, 0.1]),
//!     Isometry3::translation(0.9, 0.0, 0.4),
//!     Color::rgb(0.8, 0.2, 0.2),
//! ));
//! let camera = Camera::front_of(Point3::new(0.3, -0.7, 0.23), Point3::new(1.5, 0.7, 0.83), 4.0 / 3.0);
//! let renderer = Renderer::new()?;
//! let image = renderer.render(&scene, &camera, 1280, 960)?;
//! save_png(&image, "scene.png")?;
//! # Ok::<(), nbv_sim::render::RenderError>(())
//! ```

mod camera;
mod color;
mod error;
mod gpu_data;
mod lighting;
mod line_set;
mod map_items;
mod mesh_item;
mod pipelines;
mod png_file;
mod point_set;
mod render_scene;
mod renderer;
mod scene_items;
pub mod tessellate;
mod voxel_set;

pub use camera::Camera;
pub use color::Color;
pub use error::RenderError;
pub use lighting::Lighting;
pub use line_set::LineSet;
pub use map_items::{UnknownVoxels, map_items, map_items_around};
pub use mesh_item::{MeshItem, Shading};
pub use png_file::save_png;
pub use point_set::{CloudColoring, PointSet};
pub use render_scene::RenderScene;
pub use renderer::{Renderer, RendererOptions};
pub use scene_items::{
    BACK_AZIMUTH, FRONT_AZIMUTH, OBSTACLE_COLOR, ROBOT_COLOR, SceneItemsError, TABLE_COLOR,
    UNKNOWN_OBSTACLE_COLOR, VIEW_ELEVATION, WORKSPACE_COLOR, fitted_front_and_back, front_and_back,
    object_color, robot_items, scene_items, workspace_bounds,
};
pub use voxel_set::VoxelSet;
/// wgpu's backend flags, for [`RendererOptions::backends`].
pub use wgpu::Backends;
