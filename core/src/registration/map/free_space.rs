//! [`FreeSpace`]: the space a range sensor saw to be empty — where its rays passed before
//! they hit something — around one view, for the MAP registration's visibility test.
//!
//! A point of another view that lies where the reference sensor's rays passed contradicts
//! what that sensor saw; a point where no ray passed (behind a surface, in a shadow, off
//! the sweep) is merely unseen by it. Without that distinction a data term cannot tell a
//! view that slid past the edge of the reference's surface (its points now float where
//! the laser saw through to the table) from a view that correctly sees a face the
//! reference never saw (Turk & Levoy's boundary rejection treats both alike). Free-space
//! reasoning of this kind is what volumetric fusion carves with (Curless & Levoy,
//! SIGGRAPH 1996) and what consistency checks between range views test (Huber & Hebert,
//! "Fully automatic registration of multiple 3D data sets", IVC 2003).
//!
//! Each ray that crosses the region of interest is sampled every half `radius` from where
//! it enters the region to `margin` short of its hit (the sensor's noise along the ray),
//! and every cell of a grid of half `radius` whose centre lies within `radius` of a sample
//! is marked free: a point is in free space when its cell is marked (within `radius` of a
//! ray, to the cell's half diagonal). With `radius` a little over half the rays' spacing,
//! the marks cover the space between neighbouring rays and reach past the outermost ray by
//! less than half a spacing. The test is one bit lookup, however many rays there are; the
//! grid's memory is one bit a cell (a 20 cm region at the laser's ~3 mm spacing: ~1 MB).

use kiddo::{ImmutableKdTree, SquaredEuclidean};
use nalgebra::{Point3, Vector3};

use crate::cloud::PointCloud;
use crate::registration::RegistrationError;

/// The test radius of [`FreeSpace::of_scan`] per gap between neighbouring hits: a
/// little over half, so that the samples of neighbouring rays cover the space between
/// them.
pub const RADIUS_PER_SPACING: f64 = 0.6;

/// Two, for the nearest other point.
const TWO: std::num::NonZeroUsize = std::num::NonZeroUsize::new(2).unwrap();

/// Samples per ray at most (a ray grazing a long region is cut short there).
const MAX_SAMPLES_PER_RAY: usize = 4096;

/// Cells of the grid at most (2²⁸ bits: 32 MiB); a larger region gets coarser cells.
const MAX_CELLS: f64 = 268_435_456.0;

/// Where a sensor's rays passed, within an axis-aligned region: one bit per cell.
pub struct FreeSpace {
    bits: Vec<u64>,
    dims: [usize; 3],
    cell: f64,
    samples: usize,
    radius: f64,
    lo: Point3<f64>,
}

impl std::fmt::Debug for FreeSpace {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("FreeSpace")
            .field("samples", &self.samples)
            .field("radius", &self.radius)
            .field("cell", &self.cell)
            .field("dims", &self.dims)
            .field("lo", &self.lo)
            .finish_non_exhaustive()
    }
}

impl FreeSpace {
    /// The free space of the rays `origins[i] → hits[i]` within the box `[lo, hi]`, each
    /// ray ending `margin` (m) short of its hit, tested within `radius` (m) of a ray.
    ///
    /// ```
    /// use nbv_core::registration::FreeSpace;
    /// use nalgebra::Point3;
    /// // Rays straight down every 2 mm onto a table at z = 0, from 1 m up; a 4 cm step on
    /// // the table at x < 0 stops them at z = 0.04.
    /// let hits: Vec<Point3<f64>> = (-50..50)
    ///     .flat_map(|i| (-10..10).map(move |j| (i, j)))
    ///     .map(|(i, j)| {
    ///         let (x, y) = (f64::from(i) * 0.002, f64::from(j) * 0.002);
    ///         Point3::new(x, y, if x < 0.0 { 0.04 } else { 0.0 })
    ///     })
    ///     .collect();
    /// let origins: Vec<Point3<f64>> = hits.iter().map(|h| Point3::new(h.x, h.y, 1.0)).collect();
    /// let lo = Point3::new(-0.1, -0.02, -0.01);
    /// let hi = Point3::new(0.1, 0.02, 0.1);
    /// let free = FreeSpace::from_rays(&origins, &hits, lo, hi, 0.0012, 0.003).unwrap();
    /// assert!(free.contains(&Point3::new(0.02, 0.0, 0.02))); // above the table
    /// assert!(!free.contains(&Point3::new(-0.02, 0.0, 0.02))); // inside the step
    /// assert!(!free.contains(&Point3::new(0.02, 0.0, 0.001))); // at the table, within the noise
    /// assert!(!free.contains(&Point3::new(0.02, 0.0, 0.5))); // outside the region
    /// ```
    pub fn from_rays(
        origins: &[Point3<f64>],
        hits: &[Point3<f64>],
        lo: Point3<f64>,
        hi: Point3<f64>,
        radius: f64,
        margin: f64,
    ) -> Result<Self, RegistrationError> {
        if !(radius.is_finite() && radius > 0.0) {
            return Err(RegistrationError::InvalidParameter {
                name: "free_space.radius",
                value: radius,
                reason: "must be finite and > 0",
            });
        }
        if !(margin.is_finite() && margin >= 0.0) {
            return Err(RegistrationError::InvalidParameter {
                name: "free_space.margin",
                value: margin,
                reason: "must be finite and >= 0",
            });
        }
        if origins.len() != hits.len() {
            return Err(RegistrationError::CorrespondenceMismatch {
                sources: origins.len(),
                targets: hits.len(),
            });
        }
        let step = 0.5 * radius;
        let size = (hi - lo).sup(&Vector3::zeros());
        let cell = step.max((size.x * size.y * size.z / MAX_CELLS).cbrt());
        let dims = [0, 1, 2].map(|a| ((size[a] / cell).ceil() as usize).max(1));
        let mut space = Self {
            bits: vec![0; (dims[0] * dims[1] * dims[2]).div_ceil(64)],
            dims,
            cell,
            samples: 0,
            radius,
            lo,
        };
        for (o, h) in origins.iter().zip(hits) {
            let Some((enter, leave)) = clip(o, h, &lo, &hi) else {
                continue;
            };
            let length = (h - o).norm();
            let end = leave.min(length - margin);
            if end <= enter || !end.is_finite() {
                continue;
            }
            let u: Vector3<f64> = (h - o) / length;
            let n = (((end - enter) / step).floor() as usize + 1).min(MAX_SAMPLES_PER_RAY);
            for k in 0..n {
                space.mark(&(o + u * (end - k as f64 * step)));
            }
            space.samples += n;
        }
        Ok(space)
    }

    /// Marks every cell whose centre lies within `radius` of `sample`: per column of
    /// cells along z, the run of centres within the ball's chord there.
    fn mark(&mut self, sample: &Point3<f64>) {
        let (r, cell) = (self.radius, self.cell);
        // Cell centres along axis `a` within [from, to] (metres): their index range.
        let cells = |a: usize, from: f64, to: f64| {
            let first = ((from - self.lo[a]) / cell - 0.5).ceil().max(0.0);
            let last = ((to - self.lo[a]) / cell - 0.5)
                .floor()
                .min(self.dims[a] as f64 - 1.0);
            (first as usize, last as isize)
        };
        let centre = |a: usize, i: usize| self.lo[a] + (i as f64 + 0.5) * cell;
        let (x0, x1) = cells(0, sample.x - r, sample.x + r);
        let (y0, y1) = cells(1, sample.y - r, sample.y + r);
        for i in (x0..).take_while(|&i| i as isize <= x1) {
            let dx = centre(0, i) - sample.x;
            for j in (y0..).take_while(|&j| j as isize <= y1) {
                let dy = centre(1, j) - sample.y;
                let chord = r * r - dx * dx - dy * dy;
                if chord < 0.0 {
                    continue;
                }
                let h = chord.sqrt();
                let (z0, z1) = cells(2, sample.z - h, sample.z + h);
                for k in (z0..).take_while(|&k| k as isize <= z1) {
                    let bit = self.bit([i, j, k]);
                    self.bits[bit / 64] |= 1 << (bit % 64);
                }
            }
        }
    }

    /// The bit of cell `index` (z fastest: a column's run is contiguous).
    fn bit(&self, index: [usize; 3]) -> usize {
        (index[0] * self.dims[1] + index[1]) * self.dims[2] + index[2]
    }

    /// The free space of a scan cloud (points and their sensor origins) within `[lo,
    /// hi]`, tested within 0.6 times the median gap between neighbouring
    /// hits in the region, each ray ending `margin` short of its hit. `Ok(None)` for a
    /// cloud without origins or with fewer than two hits in the region.
    pub fn of_scan(
        cloud: &PointCloud,
        lo: Point3<f64>,
        hi: Point3<f64>,
        margin: f64,
    ) -> Result<Option<Self>, RegistrationError> {
        let Some(origins) = &cloud.origins else {
            return Ok(None);
        };
        let inside = |p: &Point3<f64>| (0..3).all(|a| p[a] >= lo[a] && p[a] <= hi[a]);
        let local: Vec<[f64; 3]> = cloud
            .points
            .iter()
            .filter(|p| inside(p))
            .map(|p| [p.x, p.y, p.z])
            .collect();
        if local.len() < 2 {
            return Ok(None);
        }
        let tree = ImmutableKdTree::<f64, 3>::builder()
            .build_from_slice(&local)
            .map_err(|e| RegistrationError::KdTree {
                view: 0,
                message: e.to_string(),
            })?;
        let mut gaps: Vec<f64> = local
            .iter()
            .map(|q| {
                let two = tree
                    .query(q)
                    .nearest_n::<SquaredEuclidean<f64>>(TWO)
                    .execute();
                two.iter().map(|n| n.distance).fold(0.0, f64::max).sqrt()
            })
            .collect();
        gaps.sort_by(f64::total_cmp);
        let spacing = gaps[gaps.len() / 2];
        if spacing.is_nan() || spacing <= 0.0 {
            return Ok(None);
        }
        Self::from_rays(
            origins,
            &cloud.points,
            lo,
            hi,
            RADIUS_PER_SPACING * spacing,
            margin,
        )
        .map(Some)
    }

    /// Whether `p` lies where a ray passed: its cell (inside the region) is marked.
    pub fn contains(&self, p: &Point3<f64>) -> bool {
        let mut index = [0usize; 3];
        for a in 0..3 {
            let i = ((p[a] - self.lo[a]) / self.cell).floor();
            if i.is_nan() || i < 0.0 || i >= self.dims[a] as f64 {
                return false;
            }
            index[a] = i as usize;
        }
        let bit = self.bit(index);
        self.bits[bit / 64] & (1 << (bit % 64)) != 0
    }

    /// The number of samples along the rays.
    pub fn samples(&self) -> usize {
        self.samples
    }
}

/// The stretch `[enter, leave]` (distances from `o` towards `h`, not beyond `h`) of the
/// segment `o → h` inside the box `[lo, hi]` (slab test), if it crosses it.
fn clip(
    o: &Point3<f64>,
    h: &Point3<f64>,
    lo: &Point3<f64>,
    hi: &Point3<f64>,
) -> Option<(f64, f64)> {
    let d = h - o;
    let length = d.norm();
    if length.is_nan() || length <= 1e-9 {
        return None;
    }
    let u = d / length;
    let (mut enter, mut leave) = (0.0f64, length);
    for a in 0..3 {
        if u[a].abs() < 1e-12 {
            if o[a] < lo[a] || o[a] > hi[a] {
                return None;
            }
            continue;
        }
        let (t0, t1) = ((lo[a] - o[a]) / u[a], (hi[a] - o[a]) / u[a]);
        enter = enter.max(t0.min(t1));
        leave = leave.min(t0.max(t1));
    }
    (enter <= leave).then_some((enter, leave))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_ray_clipped_to_a_box() {
        let lo = Point3::new(-1.0, -1.0, 0.0);
        let hi = Point3::new(1.0, 1.0, 1.0);
        let (o, h) = (Point3::new(0.0, 0.0, 3.0), Point3::new(0.0, 0.0, -1.0));
        let (a, b) = clip(&o, &h, &lo, &hi).unwrap();
        assert!((a - 2.0).abs() < 1e-12 && (b - 3.0).abs() < 1e-12);
        // Missing the box, and ending before it.
        assert!(
            clip(
                &Point3::new(2.0, 0.0, 3.0),
                &Point3::new(2.0, 0.0, -1.0),
                &lo,
                &hi
            )
            .is_none()
        );
        assert!(clip(&o, &Point3::new(0.0, 0.0, 1.5), &lo, &hi).is_none());
    }

    #[test]
    fn the_space_past_an_edge_is_free_the_shadow_behind_it_is_not() {
        // Rays from (−1, 0, 1) onto a 4 cm-high block on x ∈ [0, 0.04] and the table z = 0
        // beyond it: the block's top is hit, the table beyond it only past its shadow.
        let eye = Point3::new(-1.0, 0.0, 1.0);
        let mut hits = Vec::new();
        for i in 0..200 {
            for j in -5..5 {
                let (x, y) = (-0.1 + f64::from(i) * 0.0015, f64::from(j) * 0.0015);
                // Where the ray towards (x, y, 0) first meets the block's top or side.
                let target = Point3::new(x, y, 0.0);
                let u = (target - eye).normalize();
                let at_top = (0.04 - eye.z) / u.z;
                let p = eye + u * at_top;
                let hit = if (0.0..=0.04).contains(&p.x) {
                    p
                } else {
                    let at_side = (0.0 - eye.x) / u.x;
                    let s = eye + u * at_side;
                    if s.z <= 0.04 && s.z >= 0.0 { s } else { target }
                };
                hits.push(hit);
            }
        }
        let origins = vec![eye; hits.len()];
        let lo = Point3::new(-0.1, -0.01, -0.01);
        let hi = Point3::new(0.2, 0.01, 0.1);
        let free = FreeSpace::from_rays(&origins, &hits, lo, hi, 0.0012, 0.002).unwrap();
        assert!(free.samples() > 1000);
        // Above the block and past its far edge at the top's height: seen through.
        assert!(free.contains(&Point3::new(0.02, 0.0, 0.05)));
        assert!(free.contains(&Point3::new(0.05, 0.0, 0.042)));
        // In the block, and in its shadow just past the far edge, below the grazing ray.
        assert!(!free.contains(&Point3::new(0.02, 0.0, 0.02)));
        assert!(!free.contains(&Point3::new(0.045, 0.0, 0.01)));
    }

    #[test]
    fn bad_parameters_are_errors() {
        let p = [Point3::origin()];
        let (lo, hi) = (Point3::new(-1.0, -1.0, -1.0), Point3::new(1.0, 1.0, 1.0));
        assert!(FreeSpace::from_rays(&p, &p, lo, hi, 0.0, 0.0).is_err());
        assert!(FreeSpace::from_rays(&p, &p, lo, hi, 0.01, f64::NAN).is_err());
        assert!(FreeSpace::from_rays(&p, &[], lo, hi, 0.01, 0.0).is_err());
        // A degenerate ray is skipped: nothing is free.
        let free = FreeSpace::from_rays(&p, &p, lo, hi, 0.01, 0.0).unwrap();
        assert!(!free.contains(&Point3::origin()));
    }
}
