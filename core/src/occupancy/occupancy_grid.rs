//! [`OccupancyGrid`]: the dense log-odds map over the workspace and its per-scan update by
//! ray casting (paper eq. (1)–(2)).

use nalgebra::Point3;
use rayon::prelude::*;

use super::OccupancyError;
use super::grid_geometry::{GridGeometry, VoxelIndex};
use super::lattice_planes::LatticePlanes;
use super::log_odds::{OccupancyParams, VoxelState, probability};
use super::scan_marks::{MARK_FREE, MARK_HIT, ScanMarks};
use super::voxel_traversal::VoxelTraversal;
use crate::cloud::PointCloud;

/// Rays handed to one rayon task during a scan update.
const RAYS_PER_TASK: usize = 1024;

/// The voxels one scan changes: disjoint, ascending linear indices.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct ScanVoxels {
    /// Voxels hit by at least one ray's end point (each gets `+u` once).
    pub occupied: Vec<usize>,
    /// Voxels crossed by at least one ray and hit by none (each gets `−u` once).
    pub free: Vec<usize>,
}

/// What a scan update did.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ScanUpdate {
    /// Rays in the scan.
    pub rays: usize,
    /// Voxels updated as occupied.
    pub occupied: usize,
    /// Voxels updated as free.
    pub free: usize,
    /// Rays longer than the maximum range (free space cleared up to it, no hit).
    pub truncated: usize,
    /// Rays within range whose end point lies outside the grid (no hit in the grid).
    pub hits_outside: usize,
}

/// A ray that returned nothing within its length (a depth pixel without a return in any
/// frame of a burst): it clears free space from `origin` to `end` and hits nothing.
/// [`OccupancyGrid::insert_scan`] stops it before the first voxel the grid already holds
/// occupied: a missing return says nothing about what is already known to be there (a
/// grazing or dark surface returns nothing either).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FreeRay {
    /// Where the ray starts (the sensor's origin).
    pub origin: Point3<f64>,
    /// Where it stops clearing.
    pub end: Point3<f64>,
}

/// A dense occupancy grid: one f32 log-odds per voxel of a [`GridGeometry`], all 0
/// (unknown) at the start.
///
/// A scan (a set of rays origin → point) is applied as OctoMap's `insertPointCloud` does:
/// the set of hit voxels and the set of crossed voxels are collected over the whole scan,
/// the hit set is removed from the crossed set, then every hit voxel gets `+u` once and
/// every remaining crossed voxel `−u` once, each clamped. So a voxel changes at most once
/// per scan, and a hit wins over a pass. Per ray:
/// - the voxels crossed from the origin to the point (a [`VoxelTraversal`], clipped to the
///   grid: origins outside the grid are fine) are passed, except the hit voxel itself;
/// - the voxel containing the point is hit, if the point is in the grid;
/// - a ray longer than `max_range` clears free space up to `max_range` only and hits
///   nothing; a ray of zero length hits its voxel and passes none.
///
/// Rays are traced in parallel (rayon, chunks of rays) into one shared array of marks, in
/// two passes — every crossed voxel is marked free, then every hit voxel is marked hit —
/// each storing a single constant value, so the result is the same for any thread count
/// or order. The marks are kept with the grid, all untouched between scans, and each task
/// lists the voxels it marked first: applying a scan and clearing its marks costs the
/// voxels the scan touched, not the grid, so many small scans (one per scan line, as
/// OctoMap is fed) cost what their rays cost.
///
/// ```
/// use nbv_core::occupancy::{GridGeometry, OccupancyGrid, OccupancyParams, VoxelState};
/// use nalgebra::Point3;
/// let g = GridGeometry::from_dims(Point3::origin(), 0.1, [10, 1, 1]).unwrap();
/// let mut grid = OccupancyGrid::new(g, OccupancyParams::default()).unwrap();
/// let up = grid
///     .insert_rays(&[Point3::new(-1.0, 0.05, 0.05)], &[Point3::new(0.55, 0.05, 0.05)], 5.0)
///     .unwrap();
/// assert_eq!((up.occupied, up.free), (1, 5));
/// assert_eq!(grid.state([5, 0, 0]), Some(VoxelState::Occupied));
/// assert_eq!(grid.state([4, 0, 0]), Some(VoxelState::Empty));
/// assert_eq!(grid.state([6, 0, 0]), Some(VoxelState::Unknown));
/// ```
#[derive(Debug, Clone)]
pub struct OccupancyGrid {
    geometry: GridGeometry,
    params: OccupancyParams,
    log_odds: Vec<f32>,
    /// Scratch of the scan updates (all untouched between calls; not part of the map).
    marks: ScanMarks,
}

/// Two grids are equal when their lattices, parameters and log-odds are.
impl PartialEq for OccupancyGrid {
    fn eq(&self, other: &Self) -> bool {
        self.geometry == other.geometry
            && self.params == other.params
            && self.log_odds == other.log_odds
    }
}

/// What tracing a scan left: the lists of touched voxels (one per task, maybe with a few
/// repeats from racing threads) and the ray counters.
struct Traced {
    touched: Vec<Vec<u32>>,
    truncated: usize,
    hits_outside: usize,
}

/// Numbers of voxels per state.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct StateCounts {
    /// Occupied voxels.
    pub occupied: usize,
    /// Unknown voxels.
    pub unknown: usize,
    /// Empty voxels.
    pub empty: usize,
}

impl OccupancyGrid {
    /// An all-unknown grid.
    pub fn new(geometry: GridGeometry, params: OccupancyParams) -> Result<Self, OccupancyError> {
        params.validate()?;
        Ok(Self {
            log_odds: vec![0.0; geometry.len()],
            geometry,
            params,
            marks: ScanMarks::default(),
        })
    }

    /// A grid with given log-odds (linear index order, x fastest); values must be finite.
    pub fn from_log_odds(
        geometry: GridGeometry,
        params: OccupancyParams,
        log_odds: Vec<f32>,
    ) -> Result<Self, OccupancyError> {
        params.validate()?;
        if log_odds.len() != geometry.len() {
            return Err(OccupancyError::ValueCount {
                expected: geometry.len(),
                got: log_odds.len(),
            });
        }
        if let Some(index) = log_odds.iter().position(|v| !v.is_finite()) {
            return Err(OccupancyError::NonFiniteValue { index });
        }
        Ok(Self {
            geometry,
            params,
            log_odds,
            marks: ScanMarks::default(),
        })
    }

    /// The lattice.
    pub fn geometry(&self) -> &GridGeometry {
        &self.geometry
    }

    /// The log-odds parameters.
    pub fn params(&self) -> &OccupancyParams {
        &self.params
    }

    /// All log-odds, by linear index.
    pub fn log_odds(&self) -> &[f32] {
        &self.log_odds
    }

    /// Log-odds of a voxel (`None` outside the grid).
    pub fn value(&self, voxel: VoxelIndex) -> Option<f32> {
        self.geometry.linear(voxel).map(|l| self.log_odds[l])
    }

    /// Occupancy probability `p(m) = 1/(1 + exp(−o))` of a voxel.
    pub fn probability(&self, voxel: VoxelIndex) -> Option<f64> {
        self.value(voxel).map(|o| probability(o.into()))
    }

    /// State of a voxel.
    pub fn state(&self, voxel: VoxelIndex) -> Option<VoxelState> {
        self.value(voxel).map(|o| self.params.state(o))
    }

    /// State of a voxel by linear index.
    pub fn state_linear(&self, linear: usize) -> Option<VoxelState> {
        self.log_odds.get(linear).map(|&o| self.params.state(o))
    }

    /// Linear indices (ascending) of the voxels in `state` — e.g. the occupied voxels to
    /// compare with another mapper or to draw.
    pub fn indices_in_state(&self, state: VoxelState) -> Vec<usize> {
        (0..self.log_odds.len())
            .filter(|&l| self.params.state(self.log_odds[l]) == state)
            .collect()
    }

    /// Voxels per state.
    pub fn state_counts(&self) -> StateCounts {
        let mut c = StateCounts::default();
        for &o in &self.log_odds {
            match self.params.state(o) {
                VoxelState::Occupied => c.occupied += 1,
                VoxelState::Unknown => c.unknown += 1,
                VoxelState::Empty => c.empty += 1,
            }
        }
        c
    }

    /// The voxels a scan would mark, without changing the grid. `max_range` > 0
    /// (`f64::INFINITY` for none).
    pub fn scan_voxels(
        &self,
        origins: &[Point3<f64>],
        points: &[Point3<f64>],
        max_range: f64,
    ) -> Result<(ScanVoxels, ScanUpdate), OccupancyError> {
        check_scan(origins, points, max_range)?;
        let mut marks = ScanMarks::new(self.geometry.len());
        let planes = LatticePlanes::new(&self.geometry);
        let traced = trace_scan(&planes, &marks, origins, points, max_range, &[]);
        let mut voxels = ScanVoxels::default();
        for &l in traced.touched.iter().flatten() {
            let l = l as usize;
            match marks.take(l) {
                MARK_HIT => voxels.occupied.push(l),
                MARK_FREE => voxels.free.push(l),
                _ => {}
            }
        }
        voxels.occupied.sort_unstable();
        voxels.free.sort_unstable();
        let update = ScanUpdate {
            rays: points.len(),
            occupied: voxels.occupied.len(),
            free: voxels.free.len(),
            truncated: traced.truncated,
            hits_outside: traced.hits_outside,
        };
        Ok((voxels, update))
    }

    /// Applies one scan of rays `origins[i] → points[i]`. Costs the scan's voxel steps;
    /// only the voxels the scan touches are read or written.
    pub fn insert_rays(
        &mut self,
        origins: &[Point3<f64>],
        points: &[Point3<f64>],
        max_range: f64,
    ) -> Result<ScanUpdate, OccupancyError> {
        self.insert_scan(origins, points, max_range, &[])
    }

    /// Applies one scan of rays `origins[i] → points[i]` and of rays that returned nothing
    /// (`free`), as one update: each free ray passes the voxels from its origin to its end,
    /// or to the first voxel this grid holds occupied, whichever comes first; a hit of
    /// the scan still wins over its passes.
    ///
    /// ```
    /// use nbv_core::occupancy::{FreeRay, GridGeometry, OccupancyGrid, OccupancyParams, VoxelState};
    /// use nalgebra::Point3;
    /// let g = GridGeometry::from_dims(Point3::origin(), 0.1, [10, 1, 1]).unwrap();
    /// let mut grid = OccupancyGrid::new(g, OccupancyParams::default()).unwrap();
    /// let o = Point3::new(-1.0, 0.05, 0.05);
    /// grid.insert_rays(&[o], &[Point3::new(0.75, 0.05, 0.05)], 5.0).unwrap(); // voxel 7 hit
    /// let free = FreeRay { origin: o, end: Point3::new(0.95, 0.05, 0.05) };
    /// grid.insert_scan(&[], &[], 5.0, &[free]).unwrap();
    /// assert_eq!(grid.state([6, 0, 0]), Some(VoxelState::Empty));
    /// assert_eq!(grid.state([7, 0, 0]), Some(VoxelState::Occupied)); // the ray stopped
    /// assert_eq!(grid.state([8, 0, 0]), Some(VoxelState::Unknown));
    /// ```
    pub fn insert_scan(
        &mut self,
        origins: &[Point3<f64>],
        points: &[Point3<f64>],
        max_range: f64,
        free: &[FreeRay],
    ) -> Result<ScanUpdate, OccupancyError> {
        check_scan(origins, points, max_range)?;
        check_free(free)?;
        let planes = LatticePlanes::new(&self.geometry);
        let free = self.stopped_at_occupied(&planes, free);
        self.marks.ensure_len(self.geometry.len());
        let traced = trace_scan(&planes, &self.marks, origins, points, max_range, &free);
        let params = self.params;
        let mut update = ScanUpdate {
            rays: points.len(),
            truncated: traced.truncated,
            hits_outside: traced.hits_outside,
            ..ScanUpdate::default()
        };
        // Each touched voxel is updated once: its first take returns its mark, a repeat
        // finds it untouched. The order of the updates does not matter. (`u` once: the
        // same values as `after_hit` and `after_pass`, without a logarithm per voxel.)
        let (u, lo, hi) = (params.hit_log_odds(), params.clamp_min, params.clamp_max);
        for &l in traced.touched.iter().flatten() {
            let l = l as usize;
            match self.marks.take(l) {
                MARK_HIT => {
                    self.log_odds[l] = (self.log_odds[l] + u).clamp(lo, hi);
                    update.occupied += 1;
                }
                MARK_FREE => {
                    self.log_odds[l] = (self.log_odds[l] - u).clamp(lo, hi);
                    update.free += 1;
                }
                _ => {}
            }
        }
        Ok(update)
    }

    /// `free` with each ray cut where it enters the first voxel this grid holds occupied
    /// (rays starting in one are dropped).
    fn stopped_at_occupied(&self, planes: &LatticePlanes, free: &[FreeRay]) -> Vec<FreeRay> {
        let eps = self.params.occupied_epsilon;
        free.par_iter()
            .filter_map(|r| {
                let d = r.end - r.origin;
                let len = d.norm();
                let walk = VoxelTraversal::new(&self.geometry, &r.origin, &d, len).ok()?;
                let stop = walk
                    .find_map_linear_on(planes, |l, t| (self.log_odds[l] > eps).then_some(t))
                    .unwrap_or(len);
                // Just short of the occupied voxel's entry face.
                let stop = stop - 1e-9 * self.geometry.resolution();
                (stop > 0.0).then(|| FreeRay {
                    origin: r.origin,
                    end: r.origin + d * (stop / len),
                })
            })
            .collect()
    }

    /// Applies one scan given as a cloud with its `origins` column, with the rays that
    /// returned nothing (`free`, see [`Self::insert_scan`]; empty for none).
    pub fn insert_cloud(
        &mut self,
        cloud: &PointCloud,
        max_range: f64,
        free: &[FreeRay],
    ) -> Result<ScanUpdate, OccupancyError> {
        cloud.validate()?;
        let origins = cloud
            .origins
            .as_deref()
            .ok_or(OccupancyError::MissingOrigins)?;
        self.insert_scan(origins, &cloud.points, max_range, free)
    }

    /// Applies one scan where every ray starts at the same `origin`.
    pub fn insert_from_origin(
        &mut self,
        origin: &Point3<f64>,
        points: &[Point3<f64>],
        max_range: f64,
    ) -> Result<ScanUpdate, OccupancyError> {
        let origins = vec![*origin; points.len()];
        self.insert_rays(&origins, points, max_range)
    }
}

/// Checks that every free ray's origin and end are finite.
fn check_free(free: &[FreeRay]) -> Result<(), OccupancyError> {
    let finite = |p: &Point3<f64>| p.iter().all(|c| c.is_finite());
    match free
        .iter()
        .position(|r| !finite(&r.origin) || !finite(&r.end))
    {
        Some(index) => Err(OccupancyError::InvalidRay {
            index,
            reason: "free ray: origin or end point is not finite",
        }),
        None => Ok(()),
    }
}

/// Checks a scan's arguments: as many origins as points, every coordinate finite,
/// `max_range` > 0.
fn check_scan(
    origins: &[Point3<f64>],
    points: &[Point3<f64>],
    max_range: f64,
) -> Result<(), OccupancyError> {
    if origins.len() != points.len() {
        return Err(OccupancyError::LengthMismatch {
            origins: origins.len(),
            points: points.len(),
        });
    }
    if max_range.is_nan() || max_range <= 0.0 {
        return Err(OccupancyError::InvalidParameter {
            name: "max_range",
            value: max_range,
            reason: "must be > 0 (infinity for no limit)",
        });
    }
    let finite = |p: &Point3<f64>| p.x.is_finite() && p.y.is_finite() && p.z.is_finite();
    for (index, (o, p)) in origins.iter().zip(points).enumerate() {
        if !finite(o) || !finite(p) {
            return Err(OccupancyError::InvalidRay {
                index,
                reason: "origin or end point is not finite",
            });
        }
    }
    Ok(())
}

/// Traces a checked scan into `marks` (untouched on entry), in two phases over shared
/// marks: first every crossed voxel is marked free (in parallel), then every hit voxel is
/// marked hit. Each phase only ever stores one constant value, so the marks do not depend on the
/// order in which rays or threads store, and hits overwrite passes as OctoMap's update
/// does.
fn trace_scan(
    planes: &LatticePlanes,
    marks: &ScanMarks,
    origins: &[Point3<f64>],
    points: &[Point3<f64>],
    max_range: f64,
    free: &[FreeRay],
) -> Traced {
    let geometry = planes.geometry();
    // Passes in parallel; each task also lists its rays' hit voxels and counts.
    let tasks = by_task(origins, points, |os, ps| {
        let mut touched = Vec::new();
        let mut hits = Vec::new();
        let (mut truncated, mut outside) = (0usize, 0usize);
        for (o, p) in os.iter().zip(ps) {
            let dist = trace_ray(planes, o, p, max_range, marks, &mut touched);
            if dist > max_range {
                truncated += 1;
            } else if let Some(h) = geometry.voxel_of(p).and_then(|v| geometry.linear(v)) {
                hits.push(h as u32);
            } else {
                outside += 1;
            }
        }
        (touched, hits, truncated, outside)
    });
    // Then the hits, after every pass (a few per ray: one thread is enough).
    let mut traced = Traced {
        touched: Vec::with_capacity(tasks.len() + 1),
        truncated: 0,
        hits_outside: 0,
    };
    // The free rays' passes, before any hit is marked.
    traced
        .touched
        .par_extend(free.par_chunks(RAYS_PER_TASK).map(|rays| {
            let mut touched = Vec::new();
            for r in rays {
                trace_ray(
                    planes,
                    &r.origin,
                    &r.end,
                    f64::INFINITY,
                    marks,
                    &mut touched,
                );
            }
            touched
        }));
    let mut hit_touched = Vec::new();
    for (touched, hits, t, o) in tasks {
        for h in hits {
            marks.hit(h as usize, &mut hit_touched);
        }
        traced.touched.push(touched);
        traced.truncated += t;
        traced.hits_outside += o;
    }
    traced.touched.push(hit_touched);
    traced
}

/// `task` over chunks of [`RAYS_PER_TASK`] rays, in parallel, results in chunk order; a
/// scan of one chunk (a scan line) runs on the calling thread.
fn by_task<T: Send>(
    origins: &[Point3<f64>],
    points: &[Point3<f64>],
    task: impl Fn(&[Point3<f64>], &[Point3<f64>]) -> T + Sync,
) -> Vec<T> {
    if origins.len() <= RAYS_PER_TASK {
        return vec![task(origins, points)];
    }
    origins
        .par_chunks(RAYS_PER_TASK)
        .zip(points.par_chunks(RAYS_PER_TASK))
        .map(|(os, ps)| task(os, ps))
        .collect()
}

/// Marks the voxels a ray crosses, up to `max_range`, as free (its hit voxel too: the hit
/// phase overwrites it), listing the ones it marked first in `touched`; returns the ray's
/// length.
fn trace_ray(
    planes: &LatticePlanes,
    o: &Point3<f64>,
    p: &Point3<f64>,
    max_range: f64,
    marks: &ScanMarks,
    touched: &mut Vec<u32>,
) -> f64 {
    let r = p - o;
    let dist = r.norm();
    if dist > 0.0 {
        // The direction is non-zero and finite: the traversal cannot fail.
        if let Ok(traversal) =
            VoxelTraversal::with_norm(planes.geometry(), o, &r, dist, dist.min(max_range))
        {
            traversal.find_map_linear_on(planes, |l, _| -> Option<()> {
                marks.pass(l, touched);
                None
            });
        }
    }
    dist
}

#[cfg(test)]
mod tests {
    use super::*;

    fn line_grid() -> OccupancyGrid {
        let g = GridGeometry::from_dims(Point3::origin(), 0.25, [8, 2, 2]).unwrap();
        OccupancyGrid::new(g, OccupancyParams::default()).unwrap()
    }

    fn p(x: f64, y: f64, z: f64) -> Point3<f64> {
        Point3::new(x, y, z)
    }

    #[test]
    fn hit_wins_over_pass_within_a_scan() {
        let mut grid = line_grid();
        let u = grid.params().hit_log_odds();
        // Ray A ends in voxel 3; ray B passes through voxel 3 to voxel 6; ray C ends in 3 too.
        let origins = [p(-1.0, 0.1, 0.1); 3];
        let points = [p(0.8, 0.1, 0.1), p(1.7, 0.1, 0.1), p(0.9, 0.12, 0.1)];
        let (voxels, _) = grid.scan_voxels(&origins, &points, 10.0).unwrap();
        assert_eq!(voxels.occupied, vec![3, 6]);
        assert_eq!(voxels.free, vec![0, 1, 2, 4, 5]);
        let up = grid.insert_rays(&origins, &points, 10.0).unwrap();
        assert_eq!((up.rays, up.occupied, up.free), (3, 2, 5));
        // Voxel 3 got exactly +u once (two hits, one pass in the same scan).
        assert_eq!(grid.value([3, 0, 0]), Some(u));
        assert_eq!(grid.value([6, 0, 0]), Some(u));
        assert_eq!(grid.value([0, 0, 0]), Some(-u));
        assert_eq!(grid.value([7, 0, 0]), Some(0.0));
        // The reverse order gives the same grid.
        let mut rev = line_grid();
        let o2: Vec<_> = origins.iter().rev().copied().collect();
        let p2: Vec<_> = points.iter().rev().copied().collect();
        rev.insert_rays(&o2, &p2, 10.0).unwrap();
        assert_eq!(rev, grid);
        // A second scan passing through voxel 3 only: it goes back to 0.
        grid.insert_rays(&[origins[0]], &[points[1]], 10.0).unwrap();
        assert_eq!(grid.value([3, 0, 0]), Some(0.0));
        assert_eq!(
            grid.value([6, 0, 0]),
            Some((2.0 * u).min(grid.params().clamp_max))
        );
        assert_eq!(grid.value([0, 0, 0]), Some(-2.0 * u));
    }

    #[test]
    fn free_rays_clear_to_their_end_stop_at_known_surface_and_lose_to_hits() {
        let mut grid = line_grid();
        let u = grid.params().hit_log_odds();
        let o = p(-1.0, 0.1, 0.1);
        // Voxel 5 is known surface; a free ray towards voxel 7 stops at its face.
        grid.insert_rays(&[o], &[p(1.3, 0.1, 0.1)], 10.0).unwrap();
        let before = grid.clone();
        let free = FreeRay {
            origin: o,
            end: p(1.9, 0.1, 0.1),
        };
        let up = grid.insert_scan(&[], &[], 10.0, &[free]).unwrap();
        assert_eq!((up.rays, up.occupied, up.free), (0, 0, 5));
        for i in 0..5 {
            assert_eq!(grid.value([i, 0, 0]), Some(-2.0 * u), "voxel {i}");
        }
        for i in 5..8 {
            assert_eq!(grid.value([i, 0, 0]), before.value([i, 0, 0]), "voxel {i}");
        }
        // In an unknown grid it clears up to its end only (voxels 0..=3 for x ≤ 0.9).
        let mut grid = line_grid();
        let free = FreeRay {
            origin: o,
            end: p(0.9, 0.1, 0.1),
        };
        grid.insert_scan(&[], &[], 10.0, &[free]).unwrap();
        assert_eq!(grid.indices_in_state(VoxelState::Empty), vec![0, 1, 2, 3]);
        // A hit of the same scan wins over a free ray's pass, once.
        let mut grid = line_grid();
        let up = grid
            .insert_scan(&[o], &[p(0.6, 0.1, 0.1)], 10.0, &[free])
            .unwrap();
        assert_eq!((up.occupied, up.free), (1, 3));
        assert_eq!(grid.value([2, 0, 0]), Some(u));
        // A free ray starting in a known surface voxel clears nothing; bad rays are errors.
        let mut grid = line_grid();
        grid.insert_rays(&[o], &[p(0.1, 0.1, 0.1)], 10.0).unwrap();
        let inside = FreeRay {
            origin: p(0.1, 0.1, 0.1),
            end: p(1.9, 0.1, 0.1),
        };
        let up = grid.insert_scan(&[], &[], 10.0, &[inside]).unwrap();
        assert_eq!(up.free, 0);
        let bad = FreeRay {
            origin: o,
            end: p(f64::NAN, 0.1, 0.1),
        };
        assert!(grid.insert_scan(&[], &[], 10.0, &[bad]).is_err());
    }

    proptest::proptest! {
        /// Free rays only ever pass: no voxel rises, none the grid held occupied changes,
        /// every voxel changes by at most one `−u` (clamped), and none beyond a ray's end.
        #[test]
        fn free_rays_only_lower_unknown_or_free_voxels(
            hits in proptest::collection::vec((0.0..2.0f64, 0.0..0.5f64, 0.0..0.5f64), 0..6),
            rays in proptest::collection::vec(
                (0.0..0.5f64, 0.0..0.5f64, 0.1..2.5f64, 0.0..0.5f64, 0.0..0.5f64), 1..8),
        ) {
            let mut grid = line_grid();
            let o = p(-0.5, 0.25, 0.25);
            let points: Vec<_> = hits.iter().map(|&(x, y, z)| p(x, y, z)).collect();
            grid.insert_rays(&vec![o; points.len()], &points, 10.0).unwrap();
            let before = grid.clone();
            let free: Vec<_> = rays
                .iter()
                .map(|&(y0, z0, x1, y1, z1)| FreeRay {
                    origin: p(-0.5, y0, z0),
                    end: p(x1, y1, z1),
                })
                .collect();
            grid.insert_scan(&[], &[], 10.0, &free).unwrap();
            let u = grid.params().hit_log_odds();
            let lo = grid.params().clamp_min;
            // A voxel a ray crossed has its centre within half a diagonal of the segment.
            let g = *grid.geometry();
            let near_a_ray = |l: usize| {
                let c = g.center(g.unlinear(l).unwrap());
                free.iter().any(|r| {
                    let d = r.end - r.origin;
                    let t = ((c - r.origin).dot(&d) / d.norm_squared()).clamp(0.0, 1.0);
                    (c - (r.origin + d * t)).norm() <= 0.5 * 3f64.sqrt() * g.resolution() + 1e-9
                })
            };
            for (l, (&a, &b)) in grid.log_odds().iter().zip(before.log_odds()).enumerate() {
                proptest::prop_assert!(a <= b);
                if a != b {
                    proptest::prop_assert_eq!(a, (b - u).max(lo));
                    proptest::prop_assert!(near_a_ray(l));
                    proptest::prop_assert!(before.state_linear(l) != Some(VoxelState::Occupied));
                }
            }
        }
    }

    #[test]
    fn repeated_scans_clamp() {
        let mut grid = line_grid();
        let c = *grid.params();
        for _ in 0..10 {
            grid.insert_rays(&[p(0.05, 0.1, 0.1)], &[p(1.1, 0.1, 0.1)], 10.0)
                .unwrap();
        }
        assert_eq!(grid.value([4, 0, 0]), Some(c.clamp_max));
        assert_eq!(grid.value([0, 0, 0]), Some(c.clamp_min));
        assert!((grid.probability([4, 0, 0]).unwrap() - 0.971).abs() < 1e-6);
        assert_eq!(grid.indices_in_state(VoxelState::Occupied), vec![4]);
        assert_eq!(grid.indices_in_state(VoxelState::Empty), vec![0, 1, 2, 3]);
        let counts = grid.state_counts();
        assert_eq!(
            (counts.occupied, counts.empty, counts.unknown),
            (1, 4, 32 - 5)
        );
    }

    #[test]
    fn max_range_and_outside_hits() {
        let mut grid = line_grid();
        // 1.5 m ray with a 1.0 m range: clears [0, 1.0] from x = 0.05, no hit.
        let up = grid
            .insert_rays(&[p(0.05, 0.1, 0.1)], &[p(1.55, 0.1, 0.1)], 1.0)
            .unwrap();
        assert_eq!((up.truncated, up.occupied, up.free), (1, 0, 5));
        assert_eq!(grid.state([4, 0, 0]), Some(VoxelState::Empty));
        assert_eq!(grid.state([5, 0, 0]), Some(VoxelState::Unknown));
        assert_eq!(grid.state([6, 0, 0]), Some(VoxelState::Unknown));
        // A hit beyond the grid: only the in-grid part is cleared, no hit counted.
        let mut grid = line_grid();
        let up = grid
            .insert_rays(&[p(-1.0, 0.1, 0.1)], &[p(3.0, 0.1, 0.1)], 10.0)
            .unwrap();
        assert_eq!((up.hits_outside, up.occupied, up.free), (1, 0, 8));
        // Zero-length ray: hit only.
        let mut grid = line_grid();
        let up = grid
            .insert_rays(&[p(0.3, 0.1, 0.1)], &[p(0.3, 0.1, 0.1)], 10.0)
            .unwrap();
        assert_eq!((up.occupied, up.free), (1, 0));
    }

    #[test]
    fn bad_scans() {
        let mut grid = line_grid();
        let o = [p(0.0, 0.0, 0.0)];
        assert!(matches!(
            grid.insert_rays(&o, &[], 1.0),
            Err(OccupancyError::LengthMismatch { .. })
        ));
        assert!(matches!(
            grid.insert_rays(&o, &[p(f64::NAN, 0.0, 0.0)], 1.0),
            Err(OccupancyError::InvalidRay { index: 0, .. })
        ));
        for r in [0.0, -1.0, f64::NAN] {
            assert!(matches!(
                grid.insert_rays(&o, &o, r),
                Err(OccupancyError::InvalidParameter { .. })
            ));
        }
        let cloud = PointCloud::from_points(vec![p(0.1, 0.1, 0.1)]);
        assert_eq!(
            grid.insert_cloud(&cloud, 1.0, &[]),
            Err(OccupancyError::MissingOrigins)
        );
        assert_eq!(
            OccupancyGrid::from_log_odds(*grid.geometry(), *grid.params(), vec![0.0; 3]),
            Err(OccupancyError::ValueCount {
                expected: 32,
                got: 3
            })
        );
        let mut v = vec![0.0; 32];
        v[7] = f32::NAN;
        assert_eq!(
            OccupancyGrid::from_log_odds(*grid.geometry(), *grid.params(), v),
            Err(OccupancyError::NonFiniteValue { index: 7 })
        );
        // An empty scan is fine and changes nothing.
        assert_eq!(grid.insert_rays(&[], &[], 1.0).unwrap().rays, 0);
    }

    proptest::proptest! {
        #[test]
        fn scan_sets_match_their_definition(
            rays in proptest::collection::vec(
                ((-1.0f64..3.0, -0.5f64..1.0, -0.5f64..1.0), (-0.5f64..2.5, -0.2f64..0.7, -0.2f64..0.7)),
                1..40),
            max_range in 0.5f64..4.0,
        ) {
            let grid = line_grid();
            let g = *grid.geometry();
            let origins: Vec<_> = rays.iter().map(|r| p(r.0.0, r.0.1, r.0.2)).collect();
            let points: Vec<_> = rays.iter().map(|r| p(r.1.0, r.1.1, r.1.2)).collect();
            let (voxels, update) = grid.scan_voxels(&origins, &points, max_range).unwrap();
            let mut hits = std::collections::BTreeSet::new();
            let mut crossed = std::collections::BTreeSet::new();
            for (o, q) in origins.iter().zip(&points) {
                let dist = (q - o).norm();
                if let Some(v) = g.voxel_of(q).filter(|_| dist <= max_range) {
                    hits.insert(g.linear(v).unwrap());
                }
                if dist > 0.0 {
                    for c in g.traverse(o, &(q - o), dist.min(max_range)).unwrap() {
                        crossed.insert(c.linear);
                    }
                }
            }
            let free: Vec<usize> = crossed.difference(&hits).copied().collect();
            proptest::prop_assert_eq!(&voxels.occupied, &hits.into_iter().collect::<Vec<_>>());
            proptest::prop_assert_eq!(&voxels.free, &free);
            let mut applied = grid.clone();
            let up = applied.insert_rays(&origins, &points, max_range).unwrap();
            proptest::prop_assert_eq!(up, update);
            let u = grid.params().hit_log_odds();
            for (l, &o) in applied.log_odds().iter().enumerate() {
                let expected = if voxels.occupied.binary_search(&l).is_ok() {
                    u
                } else if voxels.free.binary_search(&l).is_ok() {
                    -u
                } else {
                    0.0
                };
                proptest::prop_assert_eq!(o, expected);
            }
        }
    }

    /// A scan: origins and end points.
    type Scan = (Vec<Point3<f64>>, Vec<Point3<f64>>);

    /// The grid after `scans` by the definition: per scan, the hit set and the crossed set
    /// from the iterator traversal, then one full pass over every voxel of the grid.
    fn reference_scans(grid: &OccupancyGrid, scans: &[Scan], max_range: f64) -> Vec<f32> {
        let g = *grid.geometry();
        let params = *grid.params();
        let mut values = grid.log_odds().to_vec();
        for (origins, points) in scans {
            let mut marks = vec![0u8; g.len()];
            for (o, q) in origins.iter().zip(points) {
                let dist = (q - o).norm();
                if dist > 0.0 {
                    for c in g.traverse(o, &(q - o), dist.min(max_range)).unwrap() {
                        marks[c.linear] = MARK_FREE;
                    }
                }
            }
            for (o, q) in origins.iter().zip(points) {
                if let Some(v) = g.voxel_of(q).filter(|_| (q - o).norm() <= max_range) {
                    marks[g.linear(v).unwrap()] = MARK_HIT;
                }
            }
            for (v, m) in values.iter_mut().zip(&marks) {
                match *m {
                    MARK_HIT => *v = params.after_hit(*v),
                    MARK_FREE => *v = params.after_pass(*v),
                    _ => {}
                }
            }
        }
        values
    }

    fn random_scan(seed: u64, rays: usize) -> Scan {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let origin = p(
            rng.random_range(-1.0..3.0),
            rng.random_range(-0.5..1.0),
            0.9,
        );
        let mut origins = Vec::with_capacity(rays);
        let mut points = Vec::with_capacity(rays);
        for i in 0..rays {
            // Lines of a few rays share an origin; some end on voxel faces (k/4 of 0.25).
            let o = if i % 7 == 0 {
                p(origin.x + 0.01 * i as f64, origin.y, origin.z)
            } else {
                origin
            };
            let q = if i % 5 == 0 {
                p(
                    rng.random_range(-4i32..12) as f64 / 16.0,
                    rng.random_range(-2i32..8) as f64 / 16.0,
                    0.0625,
                )
            } else {
                p(
                    rng.random_range(-0.5..2.5),
                    rng.random_range(-0.2..0.7),
                    rng.random_range(-0.2..0.7),
                )
            };
            origins.push(o);
            points.push(q);
        }
        (origins, points)
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(48))]

        /// Scans applied one after another through the kept marks (touching only their own
        /// voxels) equal the definition applied with a full pass per scan; a clone taken
        /// between scans carries on the same; and the scans' order of rays does not matter.
        #[test]
        fn incremental_scans_equal_full_passes(
            seeds in proptest::collection::vec((0u64..1_000_000, 1usize..60), 1..8),
            max_range in 0.5f64..4.0,
            split in 0usize..8,
        ) {
            let scans: Vec<_> = seeds.iter().map(|&(s, n)| random_scan(s, n)).collect();
            let mut grid = line_grid();
            let mut copy = None;
            for (k, (o, q)) in scans.iter().enumerate() {
                if k == split {
                    copy = Some(grid.clone());
                }
                grid.insert_rays(o, q, max_range).unwrap();
            }
            let expected = reference_scans(&line_grid(), &scans, max_range);
            proptest::prop_assert_eq!(grid.log_odds(), &expected[..]);
            if let Some(mut copy) = copy {
                for (o, q) in &scans[split..] {
                    let (ro, rq): (Vec<_>, Vec<_>) = o.iter().rev().zip(q.iter().rev()).unzip();
                    copy.insert_rays(&ro, &rq, max_range).unwrap();
                }
                proptest::prop_assert_eq!(copy.log_odds(), &expected[..]);
            }
        }
    }

    /// Scans of several tasks' rays, one after another, give the definition's grid on 1
    /// and on 2 threads, and scan lines inserted one by one give the same grid on both.
    #[test]
    fn parallel_scans_equal_the_definition_at_any_thread_count() {
        let scans: Vec<_> = (0..4)
            .map(|s| random_scan(s, 3 * RAYS_PER_TASK + 17))
            .collect();
        let lines: Vec<_> = (10..60).map(|s| random_scan(s, 200)).collect();
        let run = |threads: usize, scans: &[Scan]| {
            let mut grid = line_grid();
            let updates: Vec<ScanUpdate> = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| {
                    scans
                        .iter()
                        .map(|(o, q)| grid.insert_rays(o, q, 2.5).unwrap())
                        .collect()
                });
            (grid, updates)
        };
        for scans in [&scans, &lines] {
            let (one, up1) = run(1, scans);
            let (two, up2) = run(2, scans);
            assert_eq!(
                one.log_odds(),
                &reference_scans(&line_grid(), scans, 2.5)[..]
            );
            assert_eq!(one, two);
            assert_eq!(up1, up2);
        }
    }

    #[test]
    fn many_rays_independent_of_threads() {
        let g = GridGeometry::new(p(0.3, -0.7, 0.23), p(1.5, 0.7, 0.83), 0.02).unwrap();
        let mut origins = Vec::new();
        let mut points = Vec::new();
        for i in 0..5000 {
            let a = i as f64 * 0.618_033_988_75;
            origins.push(p(
                0.2 + (i % 50) as f64 * 0.01,
                -0.9 + (i % 37) as f64 * 0.05,
                1.4,
            ));
            points.push(p(
                0.4 + a.fract(),
                -0.6 + (a * 1.3).fract() * 1.2,
                0.25 + (a * 2.1).fract() * 0.3,
            ));
        }
        let run = |threads| {
            let mut grid = OccupancyGrid::new(g, OccupancyParams::default()).unwrap();
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| grid.insert_rays(&origins, &points, 3.0).unwrap());
            grid
        };
        let one = run(1);
        assert_eq!(one, run(4));
        // Sequential reference, ray by ray: the maximum of pass (1) and hit (2) marks.
        let mut marks = vec![0u8; g.len()];
        for (o, q) in origins.iter().zip(&points) {
            let within = (q - o).norm() <= 3.0;
            let end = if within {
                *q
            } else {
                o + (q - o).normalize() * 3.0
            };
            for c in g.traverse_segment(o, &end).unwrap() {
                marks[c.linear] = marks[c.linear].max(MARK_FREE);
            }
            if let Some(v) = g.voxel_of(q).filter(|_| within) {
                marks[g.linear(v).unwrap()] = MARK_HIT;
            }
        }
        let u = one.params().hit_log_odds();
        for (l, &m) in marks.iter().enumerate() {
            let expected = match m {
                MARK_HIT => u,
                MARK_FREE => -u,
                _ => 0.0,
            };
            assert_eq!(one.log_odds()[l], expected);
        }
    }
}
