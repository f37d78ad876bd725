//! Hand-built rows of voxels and the rays cast through them, shared by the objectives'
//! tests: a ray stopped by an occupied voxel (unknown voxels behind it unseen), a ray
//! through an occluded unknown region onto a surface's rear side, a ray missing the grid.

use nalgebra::{Point3, Vector3};

use super::{RayVoxel, cast_ray};
use crate::occupancy::{GridGeometry, OcclusionDistances, OccupancyGrid, OccupancyParams};

/// h(0.1) = −0.1 ln 0.1 − 0.9 ln 0.9.
pub const H01: f64 = 0.325_082_973_391_448_2;
/// Log-odds of p = 0.1 (free) and p = 0.9 (occupied).
pub const FREE: f32 = -2.197_224_6;
/// Log-odds of p = 0.9.
pub const OCCUPIED: f32 = 2.197_224_6;

/// A row of voxels along x (0.1 m, from x = 0) with occlusion steps.
pub fn row(values: &[f32], steps: &[u16]) -> (OccupancyGrid, OcclusionDistances) {
    let g = GridGeometry::from_dims(Point3::origin(), 0.1, [values.len(), 1, 1]).unwrap();
    let grid =
        OccupancyGrid::from_log_odds(g, OccupancyParams::default(), values.to_vec()).unwrap();
    (grid, OcclusionDistances::from_steps(steps.to_vec()))
}

fn cast(grid: &OccupancyGrid, marks: &OcclusionDistances, dir: Vector3<f64>) -> Vec<RayVoxel> {
    let mut out = Vec::new();
    cast_ray(
        grid,
        Some(marks),
        &Point3::new(-0.05, 0.05, 0.05),
        &dir,
        1.0,
        &mut out,
    )
    .unwrap();
    out
}

/// free, free, occupied | unknown, unknown, free: the cast stops at the occupied voxel.
pub fn behind_occupied() -> Vec<RayVoxel> {
    let (grid, marks) = row(&[FREE, FREE, OCCUPIED, 0.0, 0.0, FREE], &[0, 0, 0, 1, 2, 0]);
    let ray = cast(&grid, &marks, Vector3::x());
    assert_eq!(ray.len(), 3);
    ray
}

/// free, unknown (2 steps behind), unknown (1 step behind), occupied, free: the ray crosses
/// the unmeasured region occluded by the surface and meets the surface from behind.
pub fn occluded_unknown() -> Vec<RayVoxel> {
    let (grid, marks) = row(&[FREE, 0.0, 0.0, OCCUPIED, FREE], &[0, 2, 1, 0, 0]);
    let ray = cast(&grid, &marks, Vector3::x());
    assert_eq!(ray.len(), 4);
    ray
}

/// A ray pointing away from the grid: no voxel.
pub fn empty() -> Vec<RayVoxel> {
    let (grid, marks) = row(&[FREE, 0.0, OCCUPIED], &[0, 0, 0]);
    let ray = cast(&grid, &marks, -Vector3::x());
    assert!(ray.is_empty());
    ray
}
