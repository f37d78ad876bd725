//! [`OccupancyGrid`]: the dense log-odds map over the workspace and its per-scan update by
//! ray casting (paper eq. (1)–(2)).

use nalgebra::Point3;
use rayon::prelude::*;
use std::sync::atomic::{AtomicU8, Ordering};

use super::OccupancyError;
use super::grid_geometry::{GridGeometry, VoxelIndex};
use super::log_odds::{OccupancyParams, VoxelState, probability};
use super::voxel_traversal::VoxelTraversal;
use crate::cloud::PointCloud;

/// Rays handed to one rayon task during a scan update.
const RAYS_PER_TASK: usize = 1024;

/// Voxel marks of a scan: 0 untouched, 1 free (passed), 2 occupied (hit). A voxel's scan
/// mark is the maximum over rays, so a hit wins over a pass whatever the order.
const MARK_FREE: u8 = 1;
const MARK_HIT: u8 = 2;

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
/// or order.
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
#[derive(Debug, Clone, PartialEq)]
pub struct OccupancyGrid {
    geometry: GridGeometry,
    params: OccupancyParams,
    log_odds: Vec<f32>,
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
        let (marks, mut update) = self.mark_scan(origins, points, max_range)?;
        let mut voxels = ScanVoxels::default();
        for (l, &m) in marks.iter().enumerate() {
            match m {
                MARK_HIT => voxels.occupied.push(l),
                MARK_FREE => voxels.free.push(l),
                _ => {}
            }
        }
        update.occupied = voxels.occupied.len();
        update.free = voxels.free.len();
        Ok((voxels, update))
    }

    /// Applies one scan of rays `origins[i] → points[i]`.
    pub fn insert_rays(
        &mut self,
        origins: &[Point3<f64>],
        points: &[Point3<f64>],
        max_range: f64,
    ) -> Result<ScanUpdate, OccupancyError> {
        let (marks, mut update) = self.mark_scan(origins, points, max_range)?;
        let params = self.params;
        let (occupied, free) = self
            .log_odds
            .par_iter_mut()
            .zip(marks.par_iter())
            .map(|(o, &m)| match m {
                MARK_HIT => {
                    *o = params.after_hit(*o);
                    (1, 0)
                }
                MARK_FREE => {
                    *o = params.after_pass(*o);
                    (0, 1)
                }
                _ => (0, 0),
            })
            .reduce(|| (0usize, 0usize), |a, b| (a.0 + b.0, a.1 + b.1));
        update.occupied = occupied;
        update.free = free;
        Ok(update)
    }

    /// Applies one scan given as a cloud with its `origins` column.
    pub fn insert_cloud(
        &mut self,
        cloud: &PointCloud,
        max_range: f64,
    ) -> Result<ScanUpdate, OccupancyError> {
        cloud.validate()?;
        let origins = cloud
            .origins
            .as_deref()
            .ok_or(OccupancyError::MissingOrigins)?;
        self.insert_rays(origins, &cloud.points, max_range)
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

    /// Traces the scan: one mark per voxel, and the ray counters.
    fn mark_scan(
        &self,
        origins: &[Point3<f64>],
        points: &[Point3<f64>],
        max_range: f64,
    ) -> Result<(Vec<u8>, ScanUpdate), OccupancyError> {
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
        // Two passes over shared marks: first every crossed voxel is marked free, then
        // every hit voxel is marked hit. Each pass only ever stores one constant value, so
        // the order in which rays or threads store does not matter, and hits overwrite
        // passes as OctoMap's update does: the result is the per-voxel maximum of the
        // old per-task arrays, without an array per task or their merge.
        let geometry = &self.geometry;
        let marks: Vec<AtomicU8> = std::iter::repeat_with(|| AtomicU8::new(0))
            .take(geometry.len())
            .collect();
        let (truncated, hits_outside) = origins
            .par_chunks(RAYS_PER_TASK)
            .zip(points.par_chunks(RAYS_PER_TASK))
            .map(|(os, ps)| {
                let (mut truncated, mut outside) = (0usize, 0usize);
                for (o, p) in os.iter().zip(ps) {
                    let (t, o2) = trace_ray(geometry, o, p, max_range, &marks);
                    truncated += t;
                    outside += o2;
                }
                (truncated, outside)
            })
            .reduce(|| (0, 0), |a, b| (a.0 + b.0, a.1 + b.1));
        origins
            .par_chunks(RAYS_PER_TASK)
            .zip(points.par_chunks(RAYS_PER_TASK))
            .for_each(|(os, ps)| {
                for (o, p) in os.iter().zip(ps) {
                    if let Some(h) = hit_voxel(geometry, o, p, max_range) {
                        marks[h].store(MARK_HIT, Ordering::Relaxed);
                    }
                }
            });
        let marks: Vec<u8> = marks.into_iter().map(AtomicU8::into_inner).collect();
        Ok((
            marks,
            ScanUpdate {
                rays: points.len(),
                truncated,
                hits_outside,
                ..ScanUpdate::default()
            },
        ))
    }
}

/// The voxel a ray's end point hits: `None` when the ray is longer than `max_range` or
/// ends outside the grid.
fn hit_voxel(g: &GridGeometry, o: &Point3<f64>, p: &Point3<f64>, max_range: f64) -> Option<usize> {
    if (p - o).norm() > max_range {
        return None;
    }
    g.voxel_of(p).and_then(|v| g.linear(v))
}

/// Marks the voxels a ray crosses as free (its hit voxel too: the hit pass overwrites
/// it); returns (truncated, hit outside the grid) as 0/1 counters.
fn trace_ray(
    g: &GridGeometry,
    o: &Point3<f64>,
    p: &Point3<f64>,
    max_range: f64,
    marks: &[AtomicU8],
) -> (usize, usize) {
    let r = p - o;
    let dist = r.norm();
    let truncated = dist > max_range;
    if dist > 0.0 {
        let reach = dist.min(max_range);
        // The direction is non-zero and finite: the traversal cannot fail.
        if let Ok(traversal) = VoxelTraversal::new(g, o, &r, reach) {
            for c in traversal {
                marks[c.linear].store(MARK_FREE, Ordering::Relaxed);
            }
        }
    }
    let outside = !truncated && g.voxel_of(p).is_none();
    (usize::from(truncated), usize::from(outside))
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
            grid.insert_cloud(&cloud, 1.0),
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
