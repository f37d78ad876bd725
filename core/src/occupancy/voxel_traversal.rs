//! [`VoxelTraversal`]: 3-D DDA (Amanatides–Woo) over a [`GridGeometry`] — the voxels a ray
//! crosses, in order, with the distances at which it enters and leaves each one.
//!
//! Used by the grid update (free space along each measurement ray) and by the
//! next-best-view visibility (first reduced-map voxel along each sensor ray).

use nalgebra::{Point3, Vector3};

use super::OccupancyError;
use super::grid_geometry::{GridGeometry, VoxelIndex, lattice_floor};
use super::lattice_planes::LatticePlanes;

/// One voxel crossed by a ray: `t_enter ≤ t_exit` are distances (m) from the ray origin.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VoxelCrossing {
    /// The voxel.
    pub voxel: VoxelIndex,
    /// Its linear index in the grid.
    pub linear: usize,
    /// Distance along the ray where it enters the voxel (or where the ray starts).
    pub t_enter: f64,
    /// Distance along the ray where it leaves the voxel (or where the ray stops).
    pub t_exit: f64,
}

/// Iterator over the voxels crossed by the ray `origin + t·d`, `t ∈ [0, max_distance]`,
/// `d` the normalised direction, clipped to the grid.
///
/// Conventions (the reference traversal in the tests follows the same ones):
/// - **Clipping**: the ray is first clipped to the grid box by slab intersection; a ray that
///   starts outside enters at the clipped entry distance, a ray that leaves the grid (or
///   reaches `max_distance`) stops. A ray parallel to an axis is inside on that axis iff
///   `min ≤ o < max` (half-open like [`GridGeometry::voxel_of`]). Zero-length pieces
///   yield nothing: a ray that only touches the box (an edge or a corner) or has
///   `max_distance = 0` is empty.
/// - **Positive length**: the voxels yielded are those the ray crosses over a positive
///   length; consecutive crossings share their boundary distance
///   (`t_exit` of one = `t_enter` of the next).
/// - **Ties**: where the ray reaches several boundary planes at the same distance (it
///   passes exactly through a voxel edge or corner; exact floating-point equality of the
///   crossing distances), every tied axis steps at once, so the voxels touched only along
///   that edge or at that corner (zero length) are skipped. A ray lying exactly in a
///   boundary plane belongs to the voxel on the higher-index side (floor rule).
/// - Boundary distances are recomputed from the plane index at each step (no accumulated
///   `t_delta`), so long rays do not drift.
///
/// ```
/// use nbv_core::occupancy::GridGeometry;
/// use nalgebra::{Point3, Vector3};
/// let g = GridGeometry::from_dims(Point3::origin(), 1.0, [4, 4, 1]).unwrap();
/// // Starts outside, enters at x = 0, passes exactly through the corner (2, 2).
/// let v: Vec<_> = g
///     .traverse(&Point3::new(-1.0, -1.0, 0.5), &Vector3::new(1.0, 1.0, 0.0), 10.0)
///     .unwrap()
///     .map(|c| c.voxel)
///     .collect();
/// assert_eq!(v, vec![[0, 0, 0], [1, 1, 0], [2, 2, 0], [3, 3, 0]]);
/// ```
#[derive(Debug, Clone)]
pub struct VoxelTraversal {
    dims: [i64; 3],
    nx: usize,
    nxy: usize,
    min: [f64; 3],
    resolution: f64,
    origin: [f64; 3],
    inv_dir: [f64; 3],
    step: [i64; 3],
    idx: [i64; 3],
    t_next: [f64; 3],
    t: f64,
    t_end: f64,
    done: bool,
}

impl VoxelTraversal {
    /// See [`GridGeometry::traverse`]. Errors for a non-finite origin, a zero or non-finite
    /// direction, or a negative or NaN `max_distance` (`f64::INFINITY` means unbounded).
    #[inline]
    pub fn new(
        grid: &GridGeometry,
        origin: &Point3<f64>,
        direction: &Vector3<f64>,
        max_distance: f64,
    ) -> Result<Self, OccupancyError> {
        Self::with_norm(grid, origin, direction, direction.norm(), max_distance)
    }

    /// [`VoxelTraversal::new`] with `norm = direction.norm()` already known (the grid
    /// update has it: it is the ray's length).
    #[inline]
    pub(crate) fn with_norm(
        grid: &GridGeometry,
        origin: &Point3<f64>,
        direction: &Vector3<f64>,
        norm: f64,
        max_distance: f64,
    ) -> Result<Self, OccupancyError> {
        debug_assert!(norm.to_bits() == direction.norm().to_bits() || norm.is_nan());
        let bad = |reason| Err(OccupancyError::InvalidRay { index: 0, reason });
        if !(origin.x.is_finite() && origin.y.is_finite() && origin.z.is_finite()) {
            return bad("origin is not finite");
        }
        if !(norm.is_finite() && norm > 0.0) {
            return bad("direction is zero or not finite");
        }
        if max_distance.is_nan() || max_distance < 0.0 {
            return bad("max distance is negative or NaN");
        }
        let d = direction / norm;
        let dims = grid.dims();
        let lo = grid.min();
        let hi = grid.max();
        let res = grid.resolution();
        let mut it = Self {
            dims: dims.map(|n| n as i64),
            nx: dims[0],
            nxy: dims[0] * dims[1],
            min: [lo.x, lo.y, lo.z],
            resolution: res,
            origin: [origin.x, origin.y, origin.z],
            inv_dir: [0.0; 3],
            step: [0; 3],
            idx: [0; 3],
            t_next: [f64::INFINITY; 3],
            t: 0.0,
            t_end: 0.0,
            done: true,
        };
        // Slab clipping.
        let (mut t0, mut t1) = (0.0f64, max_distance);
        for a in 0..3 {
            if d[a] == 0.0 {
                if !(origin[a] >= lo[a] && origin[a] < hi[a]) {
                    return Ok(it);
                }
            } else {
                let inv = 1.0 / d[a];
                let ta = (lo[a] - origin[a]) * inv;
                let tb = (hi[a] - origin[a]) * inv;
                t0 = t0.max(ta.min(tb));
                t1 = t1.min(ta.max(tb));
                it.inv_dir[a] = inv;
                it.step[a] = if d[a] > 0.0 { 1 } else { -1 };
            }
        }
        if t0.is_nan() || t1.is_nan() || t0 >= t1 {
            return Ok(it);
        }
        // Starting voxel: floor rule at the entry point, clamped against rounding.
        for a in 0..3 {
            let p = origin[a] + t0 * d[a];
            let f = lattice_floor((p - lo[a]) / res);
            it.idx[a] = f.clamp(0.0, (dims[a] - 1) as f64) as i64;
            if it.step[a] != 0 {
                it.t_next[a] = it.boundary(a);
                // A start exactly on a plane the ray leaves through at once (negative
                // direction) or rounding: move on until the next plane lies ahead.
                while it.t_next[a] <= t0 {
                    let n = it.idx[a] + it.step[a];
                    if n < 0 || n >= it.dims[a] {
                        return Ok(it);
                    }
                    it.idx[a] = n;
                    it.t_next[a] = it.boundary(a);
                }
            }
        }
        it.t = t0;
        it.t_end = t1;
        it.done = false;
        Ok(it)
    }

    /// Distance at which the ray crosses the next boundary plane on axis `a`.
    fn boundary(&self, a: usize) -> f64 {
        let plane = if self.step[a] > 0 {
            self.idx[a] + 1
        } else {
            self.idx[a]
        };
        (self.min[a] + plane as f64 * self.resolution - self.origin[a]) * self.inv_dir[a]
    }

    /// Calls `f` with the linear index of every voxel the traversal has still to yield, in
    /// order: exactly the voxels of iterating it (same boundary distances, same ties, same
    /// end), without the crossing distances. This is the grid update's inner loop: the
    /// linear index moves by a stride per axis and each axis counts the planes it has left,
    /// so a step is one minimum, one comparison per axis and one boundary distance.
    ///
    /// ```
    /// use nbv_core::occupancy::GridGeometry;
    /// use nalgebra::{Point3, Vector3};
    /// let g = GridGeometry::from_dims(Point3::origin(), 1.0, [4, 4, 1]).unwrap();
    /// let (o, d) = (Point3::new(-1.0, -0.5, 0.5), Vector3::new(1.0, 0.7, 0.0));
    /// let mut fast = Vec::new();
    /// g.traverse(&o, &d, 10.0).unwrap().for_each_linear(|l| fast.push(l));
    /// let slow: Vec<usize> = g.traverse(&o, &d, 10.0).unwrap().map(|c| c.linear).collect();
    /// assert_eq!(fast, slow);
    /// ```
    #[inline]
    pub fn for_each_linear(self, mut f: impl FnMut(usize)) {
        self.find_map_linear(|l, _| -> Option<()> {
            f(l);
            None
        });
    }

    /// Calls `f` with the linear index and the entry distance (`t_enter`) of every voxel
    /// the traversal has still to yield, in order, until `f` returns `Some`; returns that.
    /// The same voxels and distances as iterating, in the tight loop of
    /// [`VoxelTraversal::for_each_linear`] (used by the next-best-view ray casting, which
    /// stops at the first voxel of the reduced map).
    ///
    /// ```
    /// use nbv_core::occupancy::GridGeometry;
    /// use nalgebra::{Point3, Vector3};
    /// let g = GridGeometry::from_dims(Point3::origin(), 1.0, [4, 4, 1]).unwrap();
    /// let (o, d) = (Point3::new(-1.0, -0.5, 0.5), Vector3::new(1.0, 0.7, 0.0));
    /// let third = g.traverse(&o, &d, 10.0).unwrap().nth(2).unwrap();
    /// let mut k = 0;
    /// let found = g.traverse(&o, &d, 10.0).unwrap().find_map_linear(|l, t| {
    ///     k += 1;
    ///     (k == 3).then_some((l, t))
    /// });
    /// assert_eq!(found, Some((third.linear, third.t_enter)));
    /// ```
    #[inline]
    pub fn find_map_linear<B>(self, f: impl FnMut(usize, f64) -> Option<B>) -> Option<B> {
        let (min, res) = (self.min, self.resolution);
        self.walk(|a, k| min[a] + k as f64 * res, f)
    }

    /// [`VoxelTraversal::find_map_linear`] with the boundary planes read from `planes`,
    /// which must be this traversal's lattice's: the same voxels and distances, bit for
    /// bit, one load in place of a plane's arithmetic per step (the grid update's loop).
    #[inline]
    pub(crate) fn find_map_linear_on<B>(
        self,
        planes: &LatticePlanes,
        f: impl FnMut(usize, f64) -> Option<B>,
    ) -> Option<B> {
        debug_assert!(
            planes.geometry().dims().map(|n| n as i64) == self.dims
                && planes.geometry().resolution() == self.resolution
        );
        let [px, py, pz] = [planes.axis(0), planes.axis(1), planes.axis(2)];
        self.walk(
            |a, k| match a {
                0 => px[k],
                1 => py[k],
                _ => pz[k],
            },
            f,
        )
    }

    /// The walk of [`VoxelTraversal::find_map_linear`], with `plane(a, k)` the coordinate
    /// of axis `a`'s boundary plane `k` (`min[a] + k·resolution`, however it is found).
    #[inline]
    fn walk<B>(
        self,
        plane: impl Fn(usize, usize) -> f64,
        mut f: impl FnMut(usize, f64) -> Option<B>,
    ) -> Option<B> {
        if self.done {
            return None;
        }
        /// One axis of the walk: the linear stride of a step, the steps left inside the
        /// grid, the index of the next boundary plane and its increment.
        #[derive(Clone, Copy)]
        struct Axis {
            stride: isize,
            left: i64,
            plane: usize,
            step: isize,
        }
        let strides = [1isize, self.nx as isize, self.nxy as isize];
        let axis = |a: usize| match self.step[a] {
            1 => Axis {
                stride: strides[a],
                left: self.dims[a] - 1 - self.idx[a],
                plane: (self.idx[a] + 1) as usize,
                step: 1,
            },
            -1 => Axis {
                stride: -strides[a],
                left: self.idx[a],
                plane: self.idx[a] as usize,
                step: -1,
            },
            _ => Axis {
                stride: 0,
                left: 0,
                plane: 0,
                step: 0,
            },
        };
        let (mut x, mut y, mut z) = (axis(0), axis(1), axis(2));
        let [mut tx, mut ty, mut tz] = self.t_next;
        let (origin, inv) = (self.origin, self.inv_dir);
        let t_end = self.t_end;
        let mut lin =
            self.idx[0] as usize + self.nx * self.idx[1] as usize + self.nxy * self.idx[2] as usize;
        // The same expression as `boundary`: no accumulated increments. A plane is only
        // read after a step that stayed inside the grid, so `k ≤ dims[a]`.
        let boundary = |a: usize, k: usize| (plane(a, k) - origin[a]) * inv[a];
        // No distance is NaN, so `<` picks the minimum as `f64::min` does.
        let less = |a: f64, b: f64| if a < b { a } else { b };
        let mut t_enter = self.t;
        loop {
            if let Some(b) = f(lin, t_enter) {
                return Some(b);
            }
            let tn = less(less(tx, ty), tz);
            if tn >= t_end {
                return None;
            }
            t_enter = tn;
            // Every axis whose next plane is at `tn` steps (ties step together).
            if tx == tn {
                if x.left == 0 {
                    return None;
                }
                x.left -= 1;
                lin = lin.wrapping_add_signed(x.stride);
                x.plane = x.plane.wrapping_add_signed(x.step);
                tx = boundary(0, x.plane);
            }
            if ty == tn {
                if y.left == 0 {
                    return None;
                }
                y.left -= 1;
                lin = lin.wrapping_add_signed(y.stride);
                y.plane = y.plane.wrapping_add_signed(y.step);
                ty = boundary(1, y.plane);
            }
            if tz == tn {
                if z.left == 0 {
                    return None;
                }
                z.left -= 1;
                lin = lin.wrapping_add_signed(z.stride);
                z.plane = z.plane.wrapping_add_signed(z.step);
                tz = boundary(2, z.plane);
            }
        }
    }

    /// Distance where the ray enters the grid (or starts), and where it stops, if the
    /// traversal has not started yet; after that, the remaining interval.
    pub fn remaining(&self) -> Option<(f64, f64)> {
        (!self.done).then_some((self.t, self.t_end))
    }
}

impl Iterator for VoxelTraversal {
    type Item = VoxelCrossing;

    fn next(&mut self) -> Option<VoxelCrossing> {
        if self.done {
            return None;
        }
        let tn = self.t_next[0].min(self.t_next[1]).min(self.t_next[2]);
        let voxel = self.idx.map(|i| i as usize);
        let crossing = VoxelCrossing {
            voxel,
            linear: voxel[0] + self.nx * voxel[1] + self.nxy * voxel[2],
            t_enter: self.t,
            t_exit: tn.min(self.t_end),
        };
        if tn >= self.t_end {
            self.done = true;
        } else {
            for a in 0..3 {
                if self.t_next[a] == tn {
                    let n = self.idx[a] + self.step[a];
                    if n < 0 || n >= self.dims[a] {
                        self.done = true;
                    }
                    self.idx[a] = n;
                    self.t_next[a] = self.boundary(a);
                }
            }
            self.t = tn;
        }
        Some(crossing)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// A dyadic grid: every boundary plane and the test points below are exact in f64.
    fn grid() -> GridGeometry {
        GridGeometry::from_dims(Point3::new(-1.0, -0.5, 0.0), 0.25, [8, 6, 4]).unwrap()
    }

    fn voxels(g: &GridGeometry, o: [f64; 3], d: [f64; 3], t: f64) -> Vec<VoxelIndex> {
        g.traverse(&Point3::from(o), &Vector3::from(d), t)
            .unwrap()
            .map(|c| c.voxel)
            .collect()
    }

    /// The reference traversal: sample the clipped-free ray at the midpoints of steps of
    /// `res/1000`, map each sample with the floor rule, keep the in-grid ones, and
    /// deduplicate consecutive repeats. Independent of the DDA (no slabs, no t_max).
    fn reference(g: &GridGeometry, o: [f64; 3], d: [f64; 3], t_max: f64) -> Vec<(VoxelIndex, f64)> {
        let o = Point3::from(o);
        let d = Vector3::from(d).normalize();
        let step = g.resolution() / 1000.0;
        let n = (t_max / step).ceil() as usize;
        let mut out: Vec<(VoxelIndex, f64)> = Vec::new();
        for i in 0..n {
            let t = (i as f64 + 0.5) * step;
            if t > t_max {
                break;
            }
            if let Some(v) = g.voxel_of(&(o + d * t))
                && out.last().map(|l| l.0) != Some(v)
            {
                out.push((v, t));
            }
        }
        out
    }

    /// Checks the DDA against the reference: every sampled voxel is crossed by the DDA in
    /// the same order, every DDA voxel crossed over more than two sample steps is sampled,
    /// and the crossings tile the clipped interval.
    fn agree(g: &GridGeometry, o: [f64; 3], d: [f64; 3], t_max: f64) -> Result<(), TestCaseError> {
        let dda: Vec<VoxelCrossing> = g
            .traverse(&Point3::from(o), &Vector3::from(d), t_max)
            .unwrap()
            .collect();
        let reference = reference(g, o, d, t_max);
        let step = g.resolution() / 1000.0;
        // Order: the reference sequence is a subsequence of the DDA sequence.
        let mut k = 0;
        for (v, t) in &reference {
            while k < dda.len() && dda[k].voxel != *v {
                k += 1;
            }
            prop_assert!(
                k < dda.len(),
                "sampled voxel {:?} at t={} missing from DDA {:?}",
                v,
                t,
                dda
            );
            prop_assert!(dda[k].t_enter <= t + 1e-9 && *t <= dda[k].t_exit + 1e-9);
        }
        for c in &dda {
            if c.t_exit - c.t_enter > 2.0 * step {
                prop_assert!(
                    reference.iter().any(|r| r.0 == c.voxel),
                    "DDA voxel {:?} ({}..{}) not sampled",
                    c.voxel,
                    c.t_enter,
                    c.t_exit
                );
            }
            prop_assert!(c.t_exit >= c.t_enter);
            prop_assert_eq!(g.linear(c.voxel), Some(c.linear));
        }
        for w in dda.windows(2) {
            prop_assert_eq!(w[0].t_exit, w[1].t_enter);
            let diff: Vec<i64> = (0..3)
                .map(|a| w[1].voxel[a] as i64 - w[0].voxel[a] as i64)
                .collect();
            prop_assert!(diff.iter().all(|x| x.abs() <= 1) && diff.iter().any(|&x| x != 0));
        }
        if let (Some(f), Some(l)) = (dda.first(), dda.last()) {
            prop_assert!(l.t_exit <= t_max);
            prop_assert!(f.t_enter >= 0.0);
        }
        Ok(())
    }

    #[test]
    fn axis_rays_on_boundary_planes_follow_the_floor_rule() {
        let g = grid();
        // Along +x in the plane y = 0 (a boundary), z = 0.5 (a boundary): rows iy = 2, iz = 2.
        let v = voxels(&g, [-2.0, 0.0, 0.5], [1.0, 0.0, 0.0], 10.0);
        assert_eq!(v, (0..8).map(|i| [i, 2, 2]).collect::<Vec<_>>());
        // Along −x from x = 0 exactly (a boundary): starts in ix = 3, not 4.
        let v = voxels(&g, [0.0, 0.1, 0.1], [-1.0, 0.0, 0.0], 0.6);
        assert_eq!(v, vec![[3, 2, 0], [2, 2, 0], [1, 2, 0]]);
        // In the upper face plane y = 1.0: outside (half-open grid).
        assert!(voxels(&g, [-2.0, 1.0, 0.1], [1.0, 0.0, 0.0], 10.0).is_empty());
        // Along the lower face plane y = −0.5: inside (row 0).
        assert_eq!(
            voxels(&g, [-2.0, -0.5, 0.1], [1.0, 0.0, 0.0], 10.0).len(),
            8
        );
        for (o, d) in [
            ([-2.0, 0.0, 0.5], [1.0, 0.0, 0.0]),
            ([0.0, 0.1, 0.1], [-1.0, 0.0, 0.0]),
            ([0.1, -2.0, 0.25], [0.0, 1.0, 0.0]),
            ([0.0, 0.0, 3.0], [0.0, 0.0, -1.0]),
        ] {
            agree(&g, o, d, 4.0).unwrap();
        }
    }

    #[test]
    fn corners_and_edges_step_all_tied_axes() {
        let g = grid();
        // Diagonal through the corners x = y (dyadic, exact ties).
        let v = voxels(&g, [-1.0, -0.5, 0.1], [1.0, 1.0, 0.0], 10.0);
        assert_eq!(v, (0..6).map(|i| [i, i, 0]).collect::<Vec<_>>());
        // Space diagonal through voxel corners.
        let v = voxels(&g, [-1.0, -0.5, 0.0], [1.0, 1.0, 1.0], 10.0);
        assert_eq!(v, (0..4).map(|i| [i, i, i]).collect::<Vec<_>>());
        // Negative diagonal starting exactly on a corner.
        let v = voxels(&g, [0.0, 0.0, 0.1], [-1.0, -1.0, 0.0], 10.0);
        assert_eq!(v, vec![[3, 1, 0], [2, 0, 0]]);
        // Grazing along an edge (in the planes x = 0 and y = 0): floor rule on both.
        let v = voxels(&g, [0.0, 0.0, -1.0], [0.0, 0.0, 1.0], 10.0);
        assert_eq!(v, (0..4).map(|i| [4, 2, i]).collect::<Vec<_>>());
        agree(&g, [-1.0, -0.5, 0.1], [1.0, 1.0, 0.0], 3.0).unwrap();
        agree(&g, [0.0, 0.0, 0.1], [-1.0, -1.0, 0.0], 3.0).unwrap();
    }

    #[test]
    fn clipping_and_truncation() {
        let g = grid();
        // Starts outside, enters through the −x face, distances from the true origin.
        let c: Vec<_> = g
            .traverse(
                &Point3::new(-2.0, 0.1, 0.1),
                &Vector3::new(2.0, 0.0, 0.0),
                1.6,
            )
            .unwrap()
            .collect();
        assert_eq!(c.len(), 3);
        assert_eq!(c[0].voxel, [0, 2, 0]);
        assert_eq!(c[0].t_enter, 1.0);
        assert_eq!(c[2].t_exit, 1.6);
        // Misses the grid entirely, or only touches a corner.
        assert!(voxels(&g, [-2.0, 5.0, 0.1], [1.0, 0.0, 0.0], 10.0).is_empty());
        assert!(voxels(&g, [-2.0, 0.5, 0.1], [1.0, -1.0, 0.0], 10.0).is_empty());
        // Pointing away.
        assert!(voxels(&g, [-2.0, 0.1, 0.1], [-1.0, 0.0, 0.0], 10.0).is_empty());
        // Zero length.
        assert!(voxels(&g, [0.1, 0.1, 0.1], [1.0, 0.0, 0.0], 0.0).is_empty());
        // Leaves through +x: stops at the face.
        let c: Vec<_> = g
            .traverse(
                &Point3::new(0.6, 0.1, 0.1),
                &Vector3::new(1.0, 0.0, 0.0),
                10.0,
            )
            .unwrap()
            .collect();
        assert_eq!(c.len(), 2);
        assert!((c[1].t_exit - 0.4).abs() < 1e-15);
        // Bad rays.
        for (o, d, t) in [
            ([f64::NAN, 0.0, 0.0], [1.0, 0.0, 0.0], 1.0),
            ([0.0, 0.0, 0.0], [0.0, 0.0, 0.0], 1.0),
            ([0.0, 0.0, 0.0], [1.0, f64::INFINITY, 0.0], 1.0),
            ([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], -1.0),
            ([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], f64::NAN),
        ] {
            assert!(g.traverse(&Point3::from(o), &Vector3::from(d), t).is_err());
        }
        // Unbounded ray.
        assert_eq!(
            voxels(&g, [0.1, 0.1, 0.1], [0.0, 0.0, 1.0], f64::INFINITY).len(),
            4
        );
    }

    fn lattice_coord() -> impl Strategy<Value = f64> {
        // Multiples of res/4 = 1/16 around and inside the grid: many exact boundary hits.
        (-40i32..40).prop_map(|k| k as f64 / 16.0)
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(300))]

        #[test]
        fn dda_matches_fine_sampling_random(
            o in (-2.0f64..2.0, -1.5f64..1.5, -1.0f64..2.0),
            d in (-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0),
            t_max in 0.0f64..3.0,
        ) {
            let d = [d.0, d.1, d.2];
            prop_assume!(d.iter().map(|x| x * x).sum::<f64>() > 1e-4);
            agree(&grid(), [o.0, o.1, o.2], d, t_max)?;
        }

        #[test]
        fn for_each_linear_equals_the_iterator(
            o in (lattice_coord(), lattice_coord(), lattice_coord()),
            d in (-2i32..=2, -2i32..=2, -2i32..=2),
            r in (-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0),
            t_max in 0.0f64..4.0,
            skip in 0usize..3,
        ) {
            // Lattice rays (ties on edges and corners) and the same rays bent off the lattice.
            prop_assume!(d != (0, 0, 0));
            let g = grid();
            let o = Point3::new(o.0, o.1, o.2);
            for dir in [
                Vector3::new(d.0 as f64, d.1 as f64, d.2 as f64),
                Vector3::new(d.0 as f64 + r.0 * 0.3, d.1 as f64 + r.1 * 0.3, d.2 as f64 + r.2 * 0.3),
            ] {
                prop_assume!(dir.norm() > 1e-3);
                let slow: Vec<usize> = g.traverse(&o, &dir, t_max).unwrap().map(|c| c.linear).collect();
                let mut fast = Vec::new();
                g.traverse(&o, &dir, t_max).unwrap().for_each_linear(|l| fast.push(l));
                prop_assert_eq!(&fast, &slow);
                let slow_t: Vec<(usize, u64)> = g.traverse(&o, &dir, t_max).unwrap()
                    .map(|c| (c.linear, c.t_enter.to_bits())).collect();
                let mut fast_t = Vec::new();
                let none = g.traverse(&o, &dir, t_max).unwrap().find_map_linear(|l, t| {
                    fast_t.push((l, t.to_bits()));
                    None::<()>
                });
                prop_assert_eq!(none, None);
                prop_assert_eq!(&fast_t, &slow_t);
                // The planes read from a table, with the norm given: the same, bit for bit.
                let mut table_t = Vec::new();
                VoxelTraversal::with_norm(&g, &o, &dir, dir.norm(), t_max).unwrap()
                    .find_map_linear_on(&LatticePlanes::new(&g), |l, t| {
                        table_t.push((l, t.to_bits()));
                        None::<()>
                    });
                prop_assert_eq!(&table_t, &slow_t);
                if let Some(&(l, t)) = slow_t.get(skip) {
                    let found = g.traverse(&o, &dir, t_max).unwrap()
                        .find_map_linear(|l2, t2| (l2 == l && t2.to_bits() == t).then_some(t2));
                    prop_assert_eq!(found.map(f64::to_bits), Some(t));
                }
                // After part of the traversal has been iterated, the rest.
                let mut it = g.traverse(&o, &dir, t_max).unwrap();
                let head: Vec<usize> = it.by_ref().take(skip).map(|c| c.linear).collect();
                let mut rest = Vec::new();
                it.for_each_linear(|l| rest.push(l));
                prop_assert_eq!([head, rest].concat(), slow);
            }
        }

        #[test]
        fn dda_matches_fine_sampling_on_lattice_rays(
            o in (lattice_coord(), lattice_coord(), lattice_coord()),
            d in (-2i32..=2, -2i32..=2, -2i32..=2),
            t_max in 0.0f64..3.0,
        ) {
            // Starts on voxel faces/edges/corners, with axis-aligned, 45° and 2:1 directions.
            prop_assume!(d != (0, 0, 0));
            agree(&grid(), [o.0, o.1, o.2], [d.0 as f64, d.1 as f64, d.2 as f64], t_max)?;
        }
    }
}
