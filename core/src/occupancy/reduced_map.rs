//! [`ReducedMap`]: the reduced occupancy map M̄ of the paper — the occupied voxels and the
//! unknown voxels on the crust of the unknown region — with its statistics.

use rayon::prelude::*;

use super::grid_geometry::GridGeometry;
use super::log_odds::VoxelState;
use super::occupancy_grid::{OccupancyGrid, StateCounts};

/// The reduced map M̄: a voxel belongs to it if it is occupied (`o > ε_o`), or unknown
/// (`|o| ≤ ε_o`) with at least one empty (`o < −ε_o`) face neighbour (6-neighbourhood).
///
/// Boundary rule: a neighbour outside the grid does **not** count as empty, so an unknown
/// voxel on the grid's border belongs to M̄ only through an empty in-grid neighbour.
/// (The paper's sentence "its 6-neighbors are empty" is read as "at least one": that is the
/// crust between seen free space and unseen space, the set its explanation describes.)
///
/// Stored as two sorted lists of linear indices (occupied, unknown crust) plus two
/// bitsets for O(1) membership tests along rays.
///
/// ```
/// use nbv_core::occupancy::{GridGeometry, OccupancyGrid, OccupancyParams, ReducedMap, VoxelState};
/// use nalgebra::Point3;
/// let g = GridGeometry::from_dims(Point3::origin(), 1.0, [5, 1, 1]).unwrap();
/// // empty, empty, unknown, unknown, occupied
/// let grid = OccupancyGrid::from_log_odds(
///     g, OccupancyParams::default(), vec![-1.0, -1.0, 0.0, 0.0, 1.0]).unwrap();
/// let m = ReducedMap::from_grid(&grid);
/// assert_eq!(m.occupied(), &[4]);
/// assert_eq!(m.unknown(), &[2]);
/// assert_eq!(m.state(3), None);
/// assert_eq!(m.stats().removed_unknown_share, 0.5);
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct ReducedMap {
    geometry: GridGeometry,
    occupied: Vec<usize>,
    unknown: Vec<usize>,
    occupied_bits: Vec<u64>,
    unknown_bits: Vec<u64>,
    stats: ReducedMapStats,
}

/// Sizes of the full and the reduced map.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ReducedMapStats {
    /// Voxels per state in the full grid.
    pub grid: StateCounts,
    /// Occupied voxels in M̄ (all occupied voxels of the grid).
    pub occupied: usize,
    /// Unknown voxels in M̄ (the crust).
    pub unknown_crust: usize,
    /// Share of the grid's unknown voxels that M̄ leaves out, in [0, 1] (0 if none is
    /// unknown).
    pub removed_unknown_share: f64,
}

const KIND_NONE: u8 = 0;
const KIND_OCCUPIED: u8 = 1;
const KIND_CRUST: u8 = 2;

impl ReducedMap {
    /// Computes M̄ from a grid (parallel over z-slices; the result is deterministic).
    pub fn from_grid(grid: &OccupancyGrid) -> Self {
        let geometry = *grid.geometry();
        let [nx, ny, nz] = geometry.dims();
        let nxy = nx * ny;
        let states: Vec<VoxelState> = grid
            .log_odds()
            .par_iter()
            .map(|&o| grid.params().state(o))
            .collect();
        let empty = |l: usize| states[l] == VoxelState::Empty;
        let kinds: Vec<u8> = (0..geometry.len())
            .into_par_iter()
            .with_min_len(nxy.max(1))
            .map(|l| match states[l] {
                VoxelState::Occupied => KIND_OCCUPIED,
                VoxelState::Empty => KIND_NONE,
                VoxelState::Unknown => {
                    let (x, y, z) = (l % nx, (l / nx) % ny, l / nxy);
                    let crust = (x > 0 && empty(l - 1))
                        || (x + 1 < nx && empty(l + 1))
                        || (y > 0 && empty(l - nx))
                        || (y + 1 < ny && empty(l + nx))
                        || (z > 0 && empty(l - nxy))
                        || (z + 1 < nz && empty(l + nxy));
                    if crust { KIND_CRUST } else { KIND_NONE }
                }
            })
            .collect();
        let words = geometry.len().div_ceil(64);
        let mut occupied_bits = vec![0u64; words];
        let mut unknown_bits = vec![0u64; words];
        let mut occupied = Vec::new();
        let mut unknown = Vec::new();
        let mut counts = StateCounts::default();
        for (l, (&k, &s)) in kinds.iter().zip(&states).enumerate() {
            match s {
                VoxelState::Occupied => counts.occupied += 1,
                VoxelState::Unknown => counts.unknown += 1,
                VoxelState::Empty => counts.empty += 1,
            }
            match k {
                KIND_OCCUPIED => {
                    occupied.push(l);
                    occupied_bits[l / 64] |= 1 << (l % 64);
                }
                KIND_CRUST => {
                    unknown.push(l);
                    unknown_bits[l / 64] |= 1 << (l % 64);
                }
                _ => {}
            }
        }
        let removed_unknown_share = if counts.unknown == 0 {
            0.0
        } else {
            (counts.unknown - unknown.len()) as f64 / counts.unknown as f64
        };
        let stats = ReducedMapStats {
            grid: counts,
            occupied: occupied.len(),
            unknown_crust: unknown.len(),
            removed_unknown_share,
        };
        Self {
            geometry,
            occupied,
            unknown,
            occupied_bits,
            unknown_bits,
            stats,
        }
    }

    /// The lattice of the grid it came from.
    pub fn geometry(&self) -> &GridGeometry {
        &self.geometry
    }

    /// Occupied voxels (linear indices, ascending).
    pub fn occupied(&self) -> &[usize] {
        &self.occupied
    }

    /// Unknown crust voxels (linear indices, ascending).
    pub fn unknown(&self) -> &[usize] {
        &self.unknown
    }

    /// Number of voxels in M̄.
    pub fn len(&self) -> usize {
        self.occupied.len() + self.unknown.len()
    }

    /// Whether M̄ has no voxel.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// `Some(Occupied)` or `Some(Unknown)` if the voxel is in M̄, `None` otherwise (or out of
    /// range).
    pub fn state(&self, linear: usize) -> Option<VoxelState> {
        let bit = |bits: &[u64]| {
            bits.get(linear / 64)
                .is_some_and(|w| w >> (linear % 64) & 1 == 1)
        };
        if bit(&self.occupied_bits) {
            Some(VoxelState::Occupied)
        } else if bit(&self.unknown_bits) {
            Some(VoxelState::Unknown)
        } else {
            None
        }
    }

    /// Whether the voxel is in M̄.
    pub fn contains(&self, linear: usize) -> bool {
        self.state(linear).is_some()
    }

    /// All voxels of M̄ with their state, ascending by linear index.
    pub fn iter(&self) -> impl Iterator<Item = (usize, VoxelState)> + '_ {
        let mut o = self.occupied.iter().peekable();
        let mut u = self.unknown.iter().peekable();
        std::iter::from_fn(move || match (o.peek(), u.peek()) {
            (Some(&&a), Some(&&b)) if a < b => o.next().map(|&l| (l, VoxelState::Occupied)),
            (Some(_), None) => o.next().map(|&l| (l, VoxelState::Occupied)),
            (_, Some(_)) => u.next().map(|&l| (l, VoxelState::Unknown)),
            (None, None) => None,
        })
    }

    /// Sizes of the full and reduced maps.
    pub fn stats(&self) -> &ReducedMapStats {
        &self.stats
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::occupancy::OccupancyParams;
    use nalgebra::Point3;
    use proptest::prelude::*;

    /// The definition, voxel by voxel, with the geometry's own neighbour iterator.
    fn by_definition(grid: &OccupancyGrid) -> Vec<(usize, VoxelState)> {
        let g = grid.geometry();
        (0..g.len())
            .filter_map(|l| {
                let v = g.unlinear(l)?;
                match grid.state(v)? {
                    VoxelState::Occupied => Some((l, VoxelState::Occupied)),
                    VoxelState::Unknown => g
                        .neighbors6(v)
                        .any(|n| grid.state(n) == Some(VoxelState::Empty))
                        .then_some((l, VoxelState::Unknown)),
                    VoxelState::Empty => None,
                }
            })
            .collect()
    }

    proptest! {
        #[test]
        fn matches_definition_on_random_grids(
            dims in (1usize..7, 1usize..7, 1usize..7),
            seed_values in prop::collection::vec(-3i8..=3, 343),
        ) {
            let g = GridGeometry::from_dims(Point3::origin(), 0.1, [dims.0, dims.1, dims.2]).unwrap();
            let values: Vec<f32> = seed_values[..g.len()].iter().map(|&v| v as f32 * 0.5).collect();
            let grid = OccupancyGrid::from_log_odds(g, OccupancyParams::default(), values).unwrap();
            let m = ReducedMap::from_grid(&grid);
            let expected = by_definition(&grid);
            prop_assert_eq!(m.iter().collect::<Vec<_>>(), expected.clone());
            for l in 0..g.len() {
                prop_assert_eq!(m.state(l), expected.iter().find(|e| e.0 == l).map(|e| e.1));
            }
            let s = m.stats();
            prop_assert_eq!(s.grid, grid.state_counts());
            prop_assert_eq!(s.occupied + s.unknown_crust, m.len());
            prop_assert!(s.removed_unknown_share >= 0.0 && s.removed_unknown_share <= 1.0);
        }
    }

    #[test]
    fn border_neighbours_are_not_empty() {
        // A single unknown voxel surrounded by the grid border only.
        let g = GridGeometry::from_dims(Point3::origin(), 1.0, [1, 1, 1]).unwrap();
        let grid = OccupancyGrid::new(g, OccupancyParams::default()).unwrap();
        let m = ReducedMap::from_grid(&grid);
        assert!(m.is_empty());
        assert_eq!(m.stats().removed_unknown_share, 1.0);
        // A 3×3×3 all-unknown block with the centre empty: the 6 face neighbours form M̄.
        let g = GridGeometry::from_dims(Point3::origin(), 1.0, [3, 3, 3]).unwrap();
        let mut v = vec![0.0f32; 27];
        v[13] = -1.0;
        let grid = OccupancyGrid::from_log_odds(g, OccupancyParams::default(), v).unwrap();
        let m = ReducedMap::from_grid(&grid);
        assert_eq!(m.unknown(), &[4, 10, 12, 14, 16, 22]);
        let s = m.stats();
        assert_eq!((s.grid.unknown, s.grid.empty, s.unknown_crust), (26, 1, 6));
        assert!((s.removed_unknown_share - 20.0 / 26.0).abs() < 1e-12);
        assert_eq!(m.state(99), None);
    }
}
