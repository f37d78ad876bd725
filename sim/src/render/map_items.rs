//! Adapters from an occupancy map to drawables: the reduced map M̄ as voxel cubes,
//! occupied red and unknown grey, as in the paper's Figures 7–8.

use super::{Color, LineSet, RenderScene, VoxelSet};
use nalgebra::Point3;
use nbv_core::occupancy::ReducedMap;

/// Colour of the edges of the grid's box in map pictures.
const GRID_BOX_COLOR: Color = Color::rgb(0.25, 0.25, 0.25);

/// The voxels of M̄: its occupied voxels in [`Color::OCCUPIED`] and its unknown crust in
/// [`Color::UNKNOWN`], each cube slightly smaller than a voxel so that neighbours stay
/// distinct, and the grid's box as thin lines. (The unknown voxels M̄ leaves out are
/// hidden behind the crust anyway: drawing the crust keeps the picture legible.)
///
/// ```
/// use nbv_core::occupancy::{GridGeometry, OccupancyGrid, OccupancyParams, ReducedMap};
/// use nalgebra::Point3;
/// let g = GridGeometry::from_dims(Point3::origin(), 1.0, [5, 1, 1]).unwrap();
/// let grid = OccupancyGrid::from_log_odds(
///     g, OccupancyParams::default(), vec![-1.0, -1.0, 0.0, 0.0, 1.0]).unwrap();
/// let items = nbv_sim::render::map_items(&ReducedMap::from_grid(&grid));
/// assert_eq!(items.voxels[0].centers, vec![Point3::new(4.5, 0.5, 0.5)]); // occupied
/// assert_eq!(items.voxels[1].centers, vec![Point3::new(2.5, 0.5, 0.5)]); // unknown crust
/// ```
pub fn map_items(reduced: &ReducedMap) -> RenderScene {
    let g = reduced.geometry();
    let centers = |list: &[usize]| -> Vec<Point3<f64>> {
        list.iter()
            .filter_map(|&l| g.unlinear(l))
            .map(|v| g.center(v))
            .collect()
    };
    let size = g.resolution() * 0.96;
    let mut items = RenderScene::new();
    items.add_voxels(VoxelSet::uniform(
        centers(reduced.occupied()),
        size,
        Color::OCCUPIED,
    ));
    items.add_voxels(VoxelSet::uniform(
        centers(reduced.unknown()),
        size,
        Color::UNKNOWN,
    ));
    items.add_lines(LineSet::aabb(g.min(), g.max(), GRID_BOX_COLOR, 1.5));
    items
}
