//! Adapters from an occupancy map to drawables: the reduced map M̄ as voxel cubes,
//! occupied red and unknown grey, as in the paper's Figures 7–8.

use super::{Color, LineSet, RenderScene, VoxelSet};
use nalgebra::Point3;
use nbv_core::occupancy::{OccupancyGrid, ReducedMap, VoxelState};

/// Colour of the edges of the grid's box in map pictures.
const GRID_BOX_COLOR: Color = Color::rgb(0.25, 0.25, 0.25);

/// Which unknown voxels of M̄ a map picture shows (occupied voxels are always shown).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum UnknownVoxels {
    /// The unknown crust voxels that lie under observed free space: some voxel above
    /// them in their column is empty. These are the shadows the sensor could not see
    /// into (behind objects and obstacles); the crust of the space the sensor never
    /// looked at (above and around its field of view), which would wall the picture in,
    /// is left out.
    #[default]
    Occluded,
    /// Every unknown voxel of M̄ (the whole crust).
    Crust,
    /// None: occupied voxels only.
    None,
}

/// The voxels of M̄ as cubes: occupied voxels in [`Color::OCCUPIED`], the unknown voxels
/// chosen by `unknown` in [`Color::UNKNOWN`], each cube slightly smaller than a voxel so
/// that neighbours stay distinct, and the grid's box as thin lines. `reduced` must come
/// from `grid`.
///
/// ```
/// use nbv_core::occupancy::{GridGeometry, OccupancyGrid, OccupancyParams, ReducedMap};
/// use nbv_sim::render::{UnknownVoxels, map_items};
/// use nalgebra::Point3;
/// // One column, bottom to top: occupied, unknown, empty, unknown, unknown.
/// let g = GridGeometry::from_dims(Point3::origin(), 1.0, [1, 1, 5]).unwrap();
/// let grid = OccupancyGrid::from_log_odds(
///     g, OccupancyParams::default(), vec![1.0, 0.0, -1.0, 0.0, 0.0]).unwrap();
/// let m = ReducedMap::from_grid(&grid);
/// let items = map_items(&grid, &m, UnknownVoxels::Occluded);
/// assert_eq!(items.voxels[0].centers, vec![Point3::new(0.5, 0.5, 0.5)]); // occupied
/// assert_eq!(items.voxels[1].centers, vec![Point3::new(0.5, 0.5, 1.5)]); // under free space
/// assert_eq!(map_items(&grid, &m, UnknownVoxels::Crust).voxels[1].centers.len(), 2);
/// ```
pub fn map_items(
    grid: &OccupancyGrid,
    reduced: &ReducedMap,
    unknown: UnknownVoxels,
) -> RenderScene {
    let g = grid.geometry();
    let [nx, ny, nz] = g.dims();
    let centers = |list: &mut dyn Iterator<Item = usize>| -> Vec<Point3<f64>> {
        list.filter_map(|l| g.unlinear(l))
            .map(|v| g.center(v))
            .collect()
    };
    // Per column, one above the highest empty voxel (0 when the column has none).
    let mut top_empty = vec![0usize; nx * ny];
    for z in 0..nz {
        for (c, top) in top_empty.iter_mut().enumerate() {
            if grid.state_linear(c + nx * ny * z) == Some(VoxelState::Empty) {
                *top = z + 1;
            }
        }
    }
    let shown: Vec<usize> = match unknown {
        UnknownVoxels::Crust => reduced.unknown().to_vec(),
        UnknownVoxels::None => Vec::new(),
        UnknownVoxels::Occluded => reduced
            .unknown()
            .iter()
            .copied()
            .filter(|&l| l / (nx * ny) + 1 < top_empty[l % (nx * ny)])
            .collect(),
    };
    voxel_items(
        grid,
        centers(&mut reduced.occupied().iter().copied()),
        centers(&mut shown.into_iter()),
    )
}

/// The voxels of M̄ as [`map_items`] draws them, with only the unknown voxels inside
/// `regions` (boxes, `(min, max)`, e.g. around the objects): the crust the next views
/// are chosen to see, without the crust of the space the sensor never looked at that
/// would wall the objects in. `reduced` must come from `grid`.
///
/// ```
/// use nbv_core::occupancy::{GridGeometry, OccupancyGrid, OccupancyParams, ReducedMap};
/// use nbv_sim::render::map_items_around;
/// use nalgebra::Point3;
/// // One column, bottom to top: occupied, unknown, empty, unknown, unknown.
/// let g = GridGeometry::from_dims(Point3::origin(), 1.0, [1, 1, 5]).unwrap();
/// let grid = OccupancyGrid::from_log_odds(
///     g, OccupancyParams::default(), vec![1.0, 0.0, -1.0, 0.0, 0.0]).unwrap();
/// let m = ReducedMap::from_grid(&grid);
/// let low = [(Point3::new(0.0, 0.0, 0.0), Point3::new(1.0, 1.0, 2.0))];
/// let items = map_items_around(&grid, &m, &low);
/// assert_eq!(items.voxels[0].centers.len(), 1); // occupied, always
/// assert_eq!(items.voxels[1].centers, vec![Point3::new(0.5, 0.5, 1.5)]); // in the box
/// ```
pub fn map_items_around(
    grid: &OccupancyGrid,
    reduced: &ReducedMap,
    regions: &[(Point3<f64>, Point3<f64>)],
) -> RenderScene {
    let g = grid.geometry();
    let centers = |list: &[usize]| -> Vec<Point3<f64>> {
        list.iter()
            .filter_map(|l| g.unlinear(*l))
            .map(|v| g.center(v))
            .collect()
    };
    let inside = |p: &Point3<f64>| {
        regions
            .iter()
            .any(|(lo, hi)| (0..3).all(|a| p[a] >= lo[a] && p[a] <= hi[a]))
    };
    let mut unknown = centers(reduced.unknown());
    unknown.retain(|p| inside(p));
    voxel_items(grid, centers(reduced.occupied()), unknown)
}

/// Occupied and unknown voxel cubes, each slightly smaller than a voxel so that
/// neighbours stay distinct, and the grid's box as thin lines.
fn voxel_items(
    grid: &OccupancyGrid,
    occupied: Vec<Point3<f64>>,
    unknown: Vec<Point3<f64>>,
) -> RenderScene {
    let g = grid.geometry();
    let size = g.resolution() * 0.96;
    let mut items = RenderScene::new();
    items.add_voxels(VoxelSet::uniform(occupied, size, Color::OCCUPIED));
    items.add_voxels(VoxelSet::uniform(unknown, size, Color::UNKNOWN));
    items.add_lines(LineSet::aabb(g.min(), g.max(), GRID_BOX_COLOR, 1.5));
    items
}
