//! [`GridGeometry`]: the bounded, axis-aligned voxel lattice over the workspace — world
//! point ↔ voxel index, voxel centres, linear indexing and 6-neighbours.

use nalgebra::{Point3, Vector3};

use super::OccupancyError;
use super::voxel_traversal::VoxelTraversal;

/// A voxel's integer coordinates `[ix, iy, iz]` inside the grid.
pub type VoxelIndex = [usize; 3];

/// Largest number of voxels a grid may have (2^28: 1 GiB of f32 log-odds).
pub const MAX_VOXELS: usize = 1 << 28;

/// The lattice: lower corner `min`, cubic voxels of edge `resolution`, `dims` voxels per
/// axis. Voxel `[i, j, k]` covers the half-open box
/// `[min + (i, j, k)·res, min + (i+1, j+1, k+1)·res)`; a point belongs to the voxel
/// `floor((p − min)/res)`, so a point exactly on a face belongs to the voxel on the
/// higher-index side, and points on the grid's upper faces are outside the grid.
///
/// Linear index: `ix + nx·(iy + ny·iz)` (x fastest).
///
/// ```
/// use nbv_core::occupancy::GridGeometry;
/// use nalgebra::Point3;
/// // The paper's workspace: 1.20 × 1.40 × 0.60 m at 2 cm.
/// let g = GridGeometry::new(
///     Point3::new(0.30, -0.70, 0.23), Point3::new(1.50, 0.70, 0.83), 0.02).unwrap();
/// assert_eq!(g.dims(), [60, 70, 30]);
/// assert_eq!(g.len(), 126_000);
/// let v = g.voxel_of(&Point3::new(0.311, -0.699, 0.255)).unwrap();
/// assert_eq!(v, [0, 0, 1]);
/// assert!((g.center(v) - Point3::new(0.31, -0.69, 0.26)).norm() < 1e-12);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GridGeometry {
    min: Point3<f64>,
    resolution: f64,
    dims: [usize; 3],
}

impl GridGeometry {
    /// The grid covering the box `[min, max]` with voxels of edge `resolution`. Each axis
    /// gets `ceil((max − min)/res)` voxels (with a 1e-6 voxel tolerance, so 1.2/0.02 gives
    /// 60, not 61): `max` is rounded up to a whole number of voxels.
    pub fn new(
        min: Point3<f64>,
        max: Point3<f64>,
        resolution: f64,
    ) -> Result<Self, OccupancyError> {
        check_resolution(resolution)?;
        let mut counts = [0f64; 3];
        for a in 0..3 {
            let extent = max[a] - min[a];
            if !(min[a].is_finite() && max[a].is_finite() && extent > 0.0) {
                return Err(OccupancyError::InvalidBounds {
                    min: [min.x, min.y, min.z],
                    max: [max.x, max.y, max.z],
                });
            }
            counts[a] = (extent / resolution - 1e-6).ceil().max(1.0);
        }
        let voxels = counts[0] * counts[1] * counts[2];
        if voxels.is_nan() || voxels > MAX_VOXELS as f64 {
            return Err(OccupancyError::TooManyVoxels {
                voxels,
                limit: MAX_VOXELS,
            });
        }
        Self::from_dims(min, resolution, counts.map(|n| n as usize))
    }

    /// The grid with `dims` voxels per axis from the lower corner `min`.
    pub fn from_dims(
        min: Point3<f64>,
        resolution: f64,
        dims: [usize; 3],
    ) -> Result<Self, OccupancyError> {
        check_resolution(resolution)?;
        if !(min.x.is_finite() && min.y.is_finite() && min.z.is_finite()) {
            return Err(OccupancyError::InvalidBounds {
                min: [min.x, min.y, min.z],
                max: [f64::NAN; 3],
            });
        }
        let total = dims
            .iter()
            .try_fold(1usize, |acc, &d| acc.checked_mul(d))
            .filter(|&t| t <= MAX_VOXELS);
        if dims.contains(&0) {
            return Err(OccupancyError::InvalidParameter {
                name: "dims",
                value: 0.0,
                reason: "every axis needs at least one voxel",
            });
        }
        if total.is_none() {
            return Err(OccupancyError::TooManyVoxels {
                voxels: dims.iter().map(|&d| d as f64).product(),
                limit: MAX_VOXELS,
            });
        }
        Ok(Self {
            min,
            resolution,
            dims,
        })
    }

    /// Lower corner.
    pub fn min(&self) -> Point3<f64> {
        self.min
    }

    /// Upper corner, `min + dims·resolution`.
    pub fn max(&self) -> Point3<f64> {
        self.min + self.extent()
    }

    /// Size of the grid along each axis (m).
    pub fn extent(&self) -> Vector3<f64> {
        Vector3::new(
            self.dims[0] as f64,
            self.dims[1] as f64,
            self.dims[2] as f64,
        ) * self.resolution
    }

    /// Voxel edge length (m).
    pub fn resolution(&self) -> f64 {
        self.resolution
    }

    /// Voxels per axis.
    pub fn dims(&self) -> [usize; 3] {
        self.dims
    }

    /// Total number of voxels.
    pub fn len(&self) -> usize {
        self.dims[0] * self.dims[1] * self.dims[2]
    }

    /// Always false: a grid has at least one voxel.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Whether `p` is inside the grid (half-open on the upper faces).
    pub fn contains(&self, p: &Point3<f64>) -> bool {
        self.voxel_of(p).is_some()
    }

    /// The voxel containing `p`, or `None` outside the grid (or for a non-finite point).
    pub fn voxel_of(&self, p: &Point3<f64>) -> Option<VoxelIndex> {
        let mut idx = [0usize; 3];
        for a in 0..3 {
            let f = lattice_floor((p[a] - self.min[a]) / self.resolution);
            if !(f >= 0.0 && f < self.dims[a] as f64) {
                return None;
            }
            idx[a] = f as usize;
        }
        Some(idx)
    }

    /// Linear index of a voxel, `None` if it is outside the grid.
    pub fn linear(&self, idx: VoxelIndex) -> Option<usize> {
        (idx[0] < self.dims[0] && idx[1] < self.dims[1] && idx[2] < self.dims[2])
            .then(|| idx[0] + self.dims[0] * (idx[1] + self.dims[1] * idx[2]))
    }

    /// Voxel of a linear index, `None` if it is out of range.
    pub fn unlinear(&self, linear: usize) -> Option<VoxelIndex> {
        (linear < self.len()).then(|| {
            let [nx, ny, _] = self.dims;
            [linear % nx, (linear / nx) % ny, linear / (nx * ny)]
        })
    }

    /// Centre of a voxel (any index: outside the grid it extrapolates the lattice).
    pub fn center(&self, idx: VoxelIndex) -> Point3<f64> {
        Point3::new(
            self.min.x + (idx[0] as f64 + 0.5) * self.resolution,
            self.min.y + (idx[1] as f64 + 0.5) * self.resolution,
            self.min.z + (idx[2] as f64 + 0.5) * self.resolution,
        )
    }

    /// The face neighbours of a voxel that lie inside the grid, in the order
    /// −x, +x, −y, +y, −z, +z.
    pub fn neighbors6(&self, idx: VoxelIndex) -> impl Iterator<Item = VoxelIndex> + '_ {
        const STEPS: [(usize, bool); 6] = [
            (0, false),
            (0, true),
            (1, false),
            (1, true),
            (2, false),
            (2, true),
        ];
        STEPS.into_iter().filter_map(move |(axis, up)| {
            let mut n = idx;
            if up {
                n[axis] = n[axis].checked_add(1).filter(|&v| v < self.dims[axis])?;
            } else {
                n[axis] = n[axis].checked_sub(1)?;
            }
            Some(n)
        })
    }

    /// The voxels crossed by the ray from `origin` along `direction` (any non-zero length;
    /// it is normalised) up to `max_distance` metres, clipped to the grid: see
    /// [`VoxelTraversal`].
    pub fn traverse(
        &self,
        origin: &Point3<f64>,
        direction: &Vector3<f64>,
        max_distance: f64,
    ) -> Result<VoxelTraversal, OccupancyError> {
        VoxelTraversal::new(self, origin, direction, max_distance)
    }

    /// The voxels crossed by the segment `from → to`, clipped to the grid.
    pub fn traverse_segment(
        &self,
        from: &Point3<f64>,
        to: &Point3<f64>,
    ) -> Result<VoxelTraversal, OccupancyError> {
        let d = to - from;
        VoxelTraversal::new(self, from, &d, d.norm())
    }
}

/// `x.floor()`, bit for bit, without a call into libm for the lattice coordinates of
/// ordinary magnitude (the default x86-64 target has no rounding instruction, and the grid
/// update floors three coordinates per ray): below 2^52 in magnitude the truncation by an
/// integer conversion is exact; larger, infinite or NaN values go to `f64::floor`.
#[inline]
pub(crate) fn lattice_floor(x: f64) -> f64 {
    if x.abs() < 4_503_599_627_370_496.0 {
        let t = x as i64 as f64;
        if t > x { t - 1.0 } else { t.copysign(x) }
    } else {
        x.floor()
    }
}

fn check_resolution(resolution: f64) -> Result<(), OccupancyError> {
    if resolution.is_finite() && resolution > 0.0 {
        Ok(())
    } else {
        Err(OccupancyError::InvalidParameter {
            name: "resolution",
            value: resolution,
            reason: "must be finite and > 0",
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit() -> GridGeometry {
        GridGeometry::from_dims(Point3::new(-1.0, -1.0, 0.0), 0.25, [8, 4, 2]).unwrap()
    }

    proptest::proptest! {
        #[test]
        fn lattice_floor_is_floor(x in proptest::num::f64::ANY, k in -1000i64..1000, e in -60i32..60) {
            for v in [x, k as f64, k as f64 / 64.0, x * 2f64.powi(e), -0.0, 4_503_599_627_370_495.5] {
                proptest::prop_assert_eq!(lattice_floor(v).to_bits(), v.floor().to_bits());
            }
        }
    }

    #[test]
    fn index_round_trips_and_boundaries() {
        let g = unit();
        assert_eq!(g.len(), 64);
        assert_eq!(g.max(), Point3::new(1.0, 0.0, 0.5));
        for l in 0..g.len() {
            let v = g.unlinear(l).unwrap();
            assert_eq!(g.linear(v), Some(l));
            assert_eq!(g.voxel_of(&g.center(v)), Some(v));
        }
        assert_eq!(g.unlinear(64), None);
        assert_eq!(g.linear([8, 0, 0]), None);
        // On a face: the higher-index voxel; upper faces are outside.
        assert_eq!(g.voxel_of(&Point3::new(-0.75, -1.0, 0.0)), Some([1, 0, 0]));
        assert_eq!(g.voxel_of(&Point3::new(1.0, -0.5, 0.1)), None);
        assert_eq!(g.voxel_of(&Point3::new(-1.0, -1.0, 0.0)), Some([0, 0, 0]));
        assert_eq!(g.voxel_of(&Point3::new(f64::NAN, 0.0, 0.0)), None);
    }

    #[test]
    fn neighbours_stay_inside() {
        let g = unit();
        assert_eq!(
            g.neighbors6([0, 0, 0]).collect::<Vec<_>>(),
            vec![[1, 0, 0], [0, 1, 0], [0, 0, 1]]
        );
        assert_eq!(g.neighbors6([3, 2, 1]).count(), 5);
        assert_eq!(g.neighbors6([3, 2, 0]).count(), 5);
        assert_eq!(g.neighbors6([7, 3, 1]).count(), 3);
        let cube = GridGeometry::from_dims(Point3::origin(), 1.0, [3, 3, 3]).unwrap();
        assert_eq!(
            cube.neighbors6([1, 1, 1]).collect::<Vec<_>>(),
            vec![
                [0, 1, 1],
                [2, 1, 1],
                [1, 0, 1],
                [1, 2, 1],
                [1, 1, 0],
                [1, 1, 2]
            ]
        );
    }

    #[test]
    fn bad_geometry() {
        let o = Point3::origin();
        assert!(GridGeometry::new(o, Point3::new(1.0, 1.0, 1.0), 0.0).is_err());
        assert!(GridGeometry::new(o, Point3::new(1.0, -1.0, 1.0), 0.1).is_err());
        assert!(GridGeometry::new(o, Point3::new(1e9, 1e9, 1e9), 1e-3).is_err());
        assert!(GridGeometry::from_dims(o, 0.1, [0, 1, 1]).is_err());
        assert!(GridGeometry::from_dims(o, 0.1, [usize::MAX, 2, 1]).is_err());
        assert!(GridGeometry::from_dims(Point3::new(f64::NAN, 0.0, 0.0), 0.1, [1, 1, 1]).is_err());
        let g = GridGeometry::new(o, Point3::new(1.0, 0.5, 0.21), 0.1).unwrap();
        assert_eq!(g.dims(), [10, 5, 3]);
    }
}
