//! [`LatticePlanes`]: the coordinates of a grid's boundary planes, `min + k·resolution`
//! per axis, worked out once per scan instead of once per voxel step.

use super::grid_geometry::GridGeometry;

/// The boundary planes of a [`GridGeometry`]'s lattice: on axis `a`, plane `k`
/// (`0 ≤ k ≤ dims[a]`) lies at `min[a] + k·resolution`, the same expression, rounded the
/// same way, as the DDA's boundary distances use. A traversal that reads its planes here
/// ([`super::VoxelTraversal::find_map_linear_on`]) yields exactly the voxels and
/// distances of one that computes them, with one load in place of a multiplication, an
/// addition and an int-to-float conversion per step.
#[derive(Debug, Clone)]
pub(crate) struct LatticePlanes {
    geometry: GridGeometry,
    planes: [Vec<f64>; 3],
}

impl LatticePlanes {
    /// The planes of `geometry`'s lattice.
    pub(crate) fn new(geometry: &GridGeometry) -> Self {
        let (min, res, dims) = (geometry.min(), geometry.resolution(), geometry.dims());
        Self {
            geometry: *geometry,
            planes: std::array::from_fn(|a| {
                (0..=dims[a]).map(|k| min[a] + k as f64 * res).collect()
            }),
        }
    }

    /// The lattice these planes belong to.
    pub(crate) fn geometry(&self) -> &GridGeometry {
        &self.geometry
    }

    /// The coordinates of axis `a`'s planes, `dims[a] + 1` of them.
    #[inline]
    pub(crate) fn axis(&self, a: usize) -> &[f64] {
        &self.planes[a]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Point3;

    #[test]
    fn planes_are_the_lattice_boundaries() {
        let g = GridGeometry::from_dims(Point3::new(0.3, -0.7, 0.22), 0.02, [60, 70, 30]).unwrap();
        let p = LatticePlanes::new(&g);
        for a in 0..3 {
            assert_eq!(p.axis(a).len(), g.dims()[a] + 1);
            assert_eq!(p.axis(a)[0], g.min()[a]);
            // The upper face, as `GridGeometry::max` places it, to the last bit.
            assert_eq!(p.axis(a)[g.dims()[a]], g.max()[a]);
            assert!(p.axis(a).windows(2).all(|w| w[0] < w[1]));
        }
        assert_eq!(p.geometry(), &g);
    }
}
