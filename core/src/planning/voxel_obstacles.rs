//! [`VoxelObstacles`]: the reduced map's occupied and unknown voxels as obstacles, kept as
//! a bitset over the dense lattice, with a broad phase that walks only the lattice rows a
//! shape's bounding box overlaps, each clipped to its obstacles' x range and to the chord
//! of the shape's bounding sphere; the exact test is settled by the distance to the
//! shape's core where it can be ([`ShapeCore`]) and by parry's GJK only where it cannot.

use super::parry_bridge::{Bounds, ParryPose, ParryShape, cube, intersects, translation};
use super::shape_core::ShapeCore;
use crate::occupancy::{GridGeometry, ReducedMap};

/// Obstacle voxels on a lattice.
#[derive(Debug, Clone)]
pub(crate) struct VoxelObstacles {
    geometry: GridGeometry,
    bits: Vec<u64>,
    /// Per row of the lattice (`y + ny·z`), the first and last x of its obstacle voxels
    /// (`first > last`: none). Removals leave it as it was: it only ever bounds the set.
    rows: Vec<(usize, usize)>,
    count: usize,
    cube: ParryShape,
}

impl VoxelObstacles {
    /// Every voxel of M̄ (occupied and unknown crust).
    pub fn from_reduced_map(map: &ReducedMap) -> Self {
        let geometry = *map.geometry();
        let mut bits = vec![0u64; geometry.len().div_ceil(64)];
        let [nx, ny, nz] = geometry.dims();
        let mut rows = vec![(usize::MAX, 0); ny * nz];
        for &l in map.occupied().iter().chain(map.unknown()) {
            bits[l / 64] |= 1 << (l % 64);
            let (row, x) = (l / nx, l % nx);
            rows[row] = (rows[row].0.min(x), rows[row].1.max(x));
        }
        Self {
            geometry,
            bits,
            rows,
            count: map.len(),
            cube: cube(0.5 * geometry.resolution()),
        }
    }

    /// The lattice.
    pub fn geometry(&self) -> &GridGeometry {
        &self.geometry
    }

    /// Number of obstacle voxels.
    pub fn len(&self) -> usize {
        self.count
    }

    /// Whether voxel `l` is an obstacle.
    pub fn contains(&self, l: usize) -> bool {
        self.bits
            .get(l / 64)
            .is_some_and(|w| w >> (l % 64) & 1 == 1)
    }

    /// Removes voxels from the obstacle set (out-of-range indices are ignored); returns how
    /// many were removed.
    pub fn remove(&mut self, voxels: &[usize]) -> usize {
        let mut removed = 0;
        for &l in voxels {
            if self.contains(l) {
                self.bits[l / 64] &= !(1 << (l % 64));
                self.count -= 1;
                removed += 1;
            }
        }
        removed
    }

    /// Voxel index range `[lo, hi]` (inclusive) per axis overlapped by `bounds`, or `None` if
    /// the box misses the grid.
    fn index_range(&self, bounds: &Bounds) -> Option<([usize; 3], [usize; 3])> {
        let min = self.geometry.min();
        let res = self.geometry.resolution();
        let dims = self.geometry.dims();
        let mut lo = [0usize; 3];
        let mut hi = [0usize; 3];
        for a in 0..3 {
            let f0 = ((bounds.0[a] - min[a]) / res).floor();
            let f1 = ((bounds.1[a] - min[a]) / res).floor();
            if !(f1 >= 0.0 && f0 < dims[a] as f64) {
                return None;
            }
            lo[a] = f0.max(0.0) as usize;
            hi[a] = (f1 as usize).min(dims[a] - 1);
        }
        Some((lo, hi))
    }

    /// Visits, in increasing linear index order, the obstacle voxels the posed shape
    /// intersects (`bounds` is the shape's world bounding box); `visit` returns `false` to
    /// stop. Returns `false` iff stopped.
    ///
    /// `sphere` (centre, radius) encloses the shape: voxels whose centre is farther than
    /// `radius` plus half the voxel diagonal are skipped before the exact test. The exact
    /// test is GJK only where the distance from the voxel's centre to the shape's `core`
    /// (the shape's, at `pose`) leaves it open ([`ShapeCore::touches_cube`]); without a
    /// core, GJK everywhere.
    pub fn for_each_hit(
        &self,
        pose: &ParryPose,
        shape: &ParryShape,
        core: Option<&ShapeCore>,
        bounds: &Bounds,
        sphere: ([f64; 3], f64),
        mut visit: impl FnMut(usize) -> bool,
    ) -> bool {
        let Some((lo, hi)) = self.index_range(bounds) else {
            return true;
        };
        let [nx, ny, _] = self.geometry.dims();
        let reach = sphere.1 + 0.5 * 3f64.sqrt() * self.geometry.resolution();
        let reach2 = reach * reach;
        let res = self.geometry.resolution();
        let half = 0.5 * res;
        let min_x = self.geometry.min()[0];
        for z in lo[2]..=hi[2] {
            for y in lo[1]..=hi[1] {
                let (set_from, set_to) = self.rows[y + ny * z];
                let (x0, x1) = (lo[0].max(set_from), hi[0].min(set_to));
                if x0 > x1 {
                    continue;
                }
                // The row's centres within the sphere's chord (one voxel to spare each
                // side; the test below is exact).
                let c = self.geometry.center([lo[0], y, z]);
                let across = reach2 - (c.y - sphere.0[1]).powi(2) - (c.z - sphere.0[2]).powi(2);
                if across < 0.0 {
                    continue;
                }
                let chord = across.sqrt();
                let from = ((sphere.0[0] - chord - min_x) / res - 1.5).floor().max(0.0) as usize;
                let to = ((sphere.0[0] + chord - min_x) / res + 0.5).ceil();
                let (x0, x1) = (from.max(x0), (to.max(0.0) as usize).min(x1));
                if x0 > x1 {
                    continue;
                }
                let row = nx * (y + ny * z);
                let (first, last) = (row + x0, row + x1);
                // Walk the set bits of [first, last] word by word.
                for w in first / 64..=last / 64 {
                    let mut word = self.bits[w];
                    if w == first / 64 {
                        word &= u64::MAX << (first % 64);
                    }
                    if w == last / 64 && last % 64 < 63 {
                        word &= (1u64 << (last % 64 + 1)) - 1;
                    }
                    while word != 0 {
                        let l = w * 64 + word.trailing_zeros() as usize;
                        word &= word - 1;
                        let c = self.geometry.center([l - row, y, z]);
                        let d2 = (c.x - sphere.0[0]).powi(2)
                            + (c.y - sphere.0[1]).powi(2)
                            + (c.z - sphere.0[2]).powi(2);
                        if d2 > reach2 {
                            continue;
                        }
                        let touches =
                            core.and_then(|k| k.touches_cube(&c, half))
                                .unwrap_or_else(|| {
                                    intersects(
                                        pose,
                                        shape,
                                        &translation([c.x, c.y, c.z]),
                                        &self.cube,
                                    )
                                });
                        if touches && !visit(l) {
                            return false;
                        }
                    }
                }
            }
        }
        true
    }
}
