//! Predicted visibility O_v of a viewpoint (Algorithm 2, lines 11–24): for every ray of the
//! sensor, the closest voxel of the reduced map M̄ it meets, kept if its distance lies in
//! the sensor's range.
//!
//! Two implementations that give identical sets:
//! - [`visible_voxels`], the fast form: each ray walks the dense lattice with the 3-D DDA
//!   ([`GridGeometry::traverse`](crate::occupancy::GridGeometry::traverse)) and stops at the
//!   first voxel the reduced map's bitsets report — O(voxels crossed) per ray;
//! - [`visible_voxels_literal`], the paper's literal form: each ray is intersected with the
//!   cube of **every** voxel of M̄ (slab test) and the closest is kept — O(|M̄|) per ray.
//!
//! # Definitions shared by both forms
//!
//! - A ray starts at the viewpoint's position `o` with unit direction `d` (the sensor ray
//!   rotated into the base frame); it meets a voxel if it crosses the voxel over a positive
//!   length. Voxels are half-open boxes `[min + i·res, min + (i+1)·res)` as in the
//!   occupancy grid: a ray that only touches an edge or a corner does not meet the voxel,
//!   and a ray lying in a face plane belongs to the voxel on the higher-index side.
//! - The distance of a voxel is its **entry distance** `t_enter`: the smallest `t ≥ 0` with
//!   `o + t·d` in the voxel (the DDA's [`VoxelCrossing::t_enter`]; the slab test's
//!   `max(0, max over axes of the near-plane distances)`); plane distances are computed the
//!   same way in both forms, `(min + k·res − o)/d`. It is 0 if the viewpoint lies inside the
//!   voxel.
//! - The ray's voxel is the one of smallest entry distance (no tie is possible between
//!   voxels met over a positive length). It joins O_v iff `r_min ≤ t_enter ≤ r_max`; a voxel
//!   closer than `r_min` blocks the ray (the paper's `m_min` is the closest voxel whatever
//!   the range, lines 14–22), so nothing behind it is seen.
//!
//! [`VoxelCrossing::t_enter`]: crate::occupancy::VoxelCrossing::t_enter
//!
//! Rays are processed in parallel (rayon) and the result is a sorted set, so it does not
//! depend on the thread count.

use nalgebra::{Point3, Vector3};
use rayon::prelude::*;

use super::{NbvError, SensorRays};
use crate::math::Pose;
use crate::occupancy::{ReducedMap, VoxelState};

/// The voxels of M̄ a viewpoint is predicted to observe, split by state, and ray counts.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct VisibleVoxels {
    /// O_v^u: unknown voxels of M̄ observed (linear indices, ascending, each once).
    pub unknown: Vec<usize>,
    /// O_v^o: occupied voxels of M̄ observed (linear indices, ascending, each once).
    pub occupied: Vec<usize>,
    /// Rays cast.
    pub rays: usize,
    /// Rays whose closest voxel lies within the range (counted per ray: several rays may
    /// observe the same voxel).
    pub rays_in_range: usize,
    /// Rays whose closest voxel is nearer than `r_min` (blocked).
    pub rays_blocked: usize,
}

impl VisibleVoxels {
    /// |O_v|.
    pub fn len(&self) -> usize {
        self.unknown.len() + self.occupied.len()
    }

    /// Whether O_v is empty.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// O_v as one ascending list.
    pub fn all(&self) -> Vec<usize> {
        let mut v: Vec<usize> = self.unknown.iter().chain(&self.occupied).copied().collect();
        v.sort_unstable();
        v
    }

    fn from_hits(hits: Vec<RayOutcome>, rays: usize) -> Self {
        let mut out = Self {
            rays,
            ..Self::default()
        };
        for h in hits {
            match h {
                RayOutcome::Observed(linear, VoxelState::Unknown) => {
                    out.rays_in_range += 1;
                    out.unknown.push(linear);
                }
                RayOutcome::Observed(linear, _) => {
                    out.rays_in_range += 1;
                    out.occupied.push(linear);
                }
                RayOutcome::Blocked => out.rays_blocked += 1,
                RayOutcome::Nothing => {}
            }
        }
        for v in [&mut out.unknown, &mut out.occupied] {
            v.sort_unstable();
            v.dedup();
        }
        out
    }
}

/// The closest voxel of M̄ met by one ray.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RayHit {
    /// Linear index of the voxel.
    pub linear: usize,
    /// Its state in M̄ (occupied or unknown).
    pub state: VoxelState,
    /// Entry distance (m).
    pub distance: f64,
}

#[derive(Debug, Clone, Copy)]
enum RayOutcome {
    Observed(usize, VoxelState),
    Blocked,
    Nothing,
}

fn classify(hit: Option<RayHit>, range: [f64; 2]) -> RayOutcome {
    match hit {
        Some(h) if h.distance < range[0] => RayOutcome::Blocked,
        Some(h) if h.distance <= range[1] => RayOutcome::Observed(h.linear, h.state),
        _ => RayOutcome::Nothing,
    }
}

pub(crate) fn check_pose(pose: &Pose) -> Result<(), NbvError> {
    let finite = pose.translation.vector.iter().all(|v| v.is_finite())
        && pose.rotation.coords.iter().all(|v| v.is_finite());
    if finite {
        Ok(())
    } else {
        Err(NbvError::InvalidInput("viewpoint pose is not finite"))
    }
}

/// The closest voxel of M̄ along the ray `origin + t·direction`, `t ≥ 0`, by DDA, if its
/// entry distance is at most `max_distance` (nearer ones are always found; `None` if there
/// is none that near).
pub fn first_hit(
    map: &ReducedMap,
    origin: &Point3<f64>,
    direction: &Vector3<f64>,
    max_distance: f64,
) -> Result<Option<RayHit>, NbvError> {
    // Walk a little beyond max_distance: a voxel entered at exactly max_distance is crossed
    // over a positive length only past it.
    let limit = max_distance + map.geometry().resolution();
    let hit = map
        .geometry()
        .traverse(origin, direction, limit)?
        .find_map_linear(|linear, t_enter| {
            if t_enter > max_distance {
                return Some(None);
            }
            map.state(linear).map(|state| {
                Some(RayHit {
                    linear,
                    state,
                    distance: t_enter,
                })
            })
        });
    Ok(hit.flatten())
}

/// O_v by DDA through the dense lattice (the fast form; see the module doc).
///
/// ```
/// use nbv_core::nbv::{SensorRays, visible_voxels};
/// use nbv_core::occupancy::{GridGeometry, OccupancyGrid, OccupancyParams, ReducedMap};
/// use nalgebra::{Point3, Vector3};
/// // A 1-D row of voxels: empty, empty, unknown (crust), occupied.
/// let g = GridGeometry::from_dims(Point3::origin(), 0.1, [4, 1, 1]).unwrap();
/// let grid = OccupancyGrid::from_log_odds(
///     g, OccupancyParams::default(), vec![-1.0, -1.0, 0.0, 1.0]).unwrap();
/// let map = ReducedMap::from_grid(&grid);
/// // A sensor at x = 0.05 looking along +x (its z axis).
/// let pose = nbv_core::math::pose_from_xyz_rpy([0.05, 0.05, 0.05], [0.0, std::f64::consts::FRAC_PI_2, 0.0]);
/// let rays = SensorRays::new(vec![Vector3::z()], [0.1, 0.8])?;
/// let seen = visible_voxels(&map, &pose, &rays)?;
/// assert_eq!(seen.unknown, vec![2]); // entered at 0.15 m; the occupied voxel is hidden
/// assert!(seen.occupied.is_empty());
/// # Ok::<(), nbv_core::nbv::NbvError>(())
/// ```
pub fn visible_voxels(
    map: &ReducedMap,
    pose: &Pose,
    rays: &SensorRays,
) -> Result<VisibleVoxels, NbvError> {
    check_pose(pose)?;
    let origin = Point3::from(pose.translation.vector);
    let hits = rays
        .directions
        .par_iter()
        .map(|d| {
            let dir = pose.rotation * d;
            Ok(classify(
                first_hit(map, &origin, &dir, rays.range[1])?,
                rays.range,
            ))
        })
        .collect::<Result<Vec<_>, NbvError>>()?;
    Ok(VisibleVoxels::from_hits(hits, rays.len()))
}

/// One voxel of M̄ as a box, for the literal form.
#[derive(Debug, Clone, Copy)]
struct VoxelBox {
    linear: usize,
    state: VoxelState,
    lo: [f64; 3],
    hi: [f64; 3],
}

fn voxel_boxes(map: &ReducedMap) -> Vec<VoxelBox> {
    let g = map.geometry();
    let min = g.min();
    let res = g.resolution();
    map.iter()
        .filter_map(|(linear, state)| {
            let idx = g.unlinear(linear)?;
            Some(VoxelBox {
                linear,
                state,
                lo: std::array::from_fn(|a| min[a] + idx[a] as f64 * res),
                hi: std::array::from_fn(|a| min[a] + (idx[a] + 1) as f64 * res),
            })
        })
        .collect()
}

/// Entry distance of the ray into a half-open box, if it crosses it over a positive length.
fn slab_entry(o: &[f64; 3], d: &[f64; 3], inv: &[f64; 3], b: &VoxelBox) -> Option<f64> {
    let (mut t0, mut t1) = (0.0f64, f64::INFINITY);
    for a in 0..3 {
        if d[a] == 0.0 {
            if !(o[a] >= b.lo[a] && o[a] < b.hi[a]) {
                return None;
            }
        } else {
            let ta = (b.lo[a] - o[a]) * inv[a];
            let tb = (b.hi[a] - o[a]) * inv[a];
            t0 = t0.max(ta.min(tb));
            t1 = t1.min(ta.max(tb));
        }
    }
    (t0 < t1).then_some(t0)
}

fn first_hit_in_boxes(
    boxes: &[VoxelBox],
    origin: &Point3<f64>,
    direction: &Vector3<f64>,
) -> Option<RayHit> {
    // The same normalisation as the DDA's.
    let d = direction / direction.norm();
    let o = [origin.x, origin.y, origin.z];
    let dv = [d.x, d.y, d.z];
    let inv = dv.map(|x| if x == 0.0 { 0.0 } else { 1.0 / x });
    let mut best: Option<RayHit> = None;
    for b in boxes {
        if let Some(t) = slab_entry(&o, &dv, &inv, b) {
            let closer = match best {
                None => true,
                Some(h) => t < h.distance || (t == h.distance && b.linear < h.linear),
            };
            if closer {
                best = Some(RayHit {
                    linear: b.linear,
                    state: b.state,
                    distance: t,
                });
            }
        }
    }
    best
}

/// The closest voxel of M̄ along the ray by testing every voxel (the literal form of
/// [`first_hit`], without a distance bound).
pub fn first_hit_literal(
    map: &ReducedMap,
    origin: &Point3<f64>,
    direction: &Vector3<f64>,
) -> Result<Option<RayHit>, NbvError> {
    check_ray(origin, direction)?;
    Ok(first_hit_in_boxes(&voxel_boxes(map), origin, direction))
}

fn check_ray(origin: &Point3<f64>, direction: &Vector3<f64>) -> Result<(), NbvError> {
    let n = direction.norm();
    if origin.iter().all(|v| v.is_finite()) && n.is_finite() && n > 0.0 {
        Ok(())
    } else {
        Err(NbvError::InvalidInput(
            "ray origin or direction is not finite or zero",
        ))
    }
}

/// O_v by the paper's literal procedure (every ray against every voxel of M̄; see the
/// module doc). The reference for [`visible_voxels`], which gives the same result.
pub fn visible_voxels_literal(
    map: &ReducedMap,
    pose: &Pose,
    rays: &SensorRays,
) -> Result<VisibleVoxels, NbvError> {
    check_pose(pose)?;
    let origin = Point3::from(pose.translation.vector);
    let boxes = voxel_boxes(map);
    let hits = rays
        .directions
        .par_iter()
        .map(|d| {
            let dir = pose.rotation * d;
            classify(first_hit_in_boxes(&boxes, &origin, &dir), rays.range)
        })
        .collect();
    Ok(VisibleVoxels::from_hits(hits, rays.len()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::pose_from_xyz_rpy;
    use crate::occupancy::{GridGeometry, OccupancyGrid, OccupancyParams};
    use proptest::prelude::*;

    fn map_from(dims: [usize; 3], res: f64, values: Vec<f32>) -> ReducedMap {
        let g = GridGeometry::from_dims(Point3::new(-0.1, -0.2, 0.05), res, dims).unwrap();
        ReducedMap::from_grid(
            &OccupancyGrid::from_log_odds(g, OccupancyParams::default(), values).unwrap(),
        )
    }

    #[test]
    fn ray_hits_by_hand() {
        // Row along x at res 0.1: E E U O E O; min x = −0.1.
        let map = map_from([6, 1, 1], 0.1, vec![-1.0, -1.0, 0.0, 1.0, -1.0, 1.0]);
        let o = Point3::new(-0.05, -0.15, 0.1);
        let hit = first_hit(&map, &o, &Vector3::x(), 1.0).unwrap().unwrap();
        assert_eq!((hit.linear, hit.state), (2, VoxelState::Unknown));
        assert!((hit.distance - 0.15).abs() < 1e-12);
        assert_eq!(
            first_hit_literal(&map, &o, &Vector3::x()).unwrap(),
            Some(hit)
        );
        // Backwards from inside voxel 5 (occupied): distance 0.
        let o5 = Point3::new(0.43, -0.15, 0.1);
        let hit = first_hit(&map, &o5, &-Vector3::x(), 1.0).unwrap().unwrap();
        assert_eq!((hit.linear, hit.distance), (5, 0.0));
        assert_eq!(
            first_hit_literal(&map, &o5, &-Vector3::x()).unwrap(),
            Some(hit)
        );
        // From voxel 4 backwards: voxel 3 entered at 0.03.
        let o4 = Point3::new(0.33, -0.15, 0.1);
        let hit = first_hit(&map, &o4, &-Vector3::x(), 1.0).unwrap().unwrap();
        assert_eq!(hit.linear, 3);
        assert!((hit.distance - 0.03).abs() < 1e-12);
        // Bounded: nothing within 0.1 m.
        assert_eq!(first_hit(&map, &o, &Vector3::x(), 0.1).unwrap(), None);
        // Missing the grid.
        assert_eq!(first_hit(&map, &o, &Vector3::z(), 1.0).unwrap(), None);
        assert_eq!(first_hit_literal(&map, &o, &Vector3::z()).unwrap(), None);
        assert!(first_hit(&map, &o, &Vector3::zeros(), 1.0).is_err());
        assert!(first_hit_literal(&map, &o, &Vector3::zeros()).is_err());
    }

    #[test]
    fn range_and_blocking() {
        // Row E E U O E O as above; sensor looking along +x from x = −0.05.
        let map = map_from([6, 1, 1], 0.1, vec![-1.0, -1.0, 0.0, 1.0, -1.0, 1.0]);
        let pose = pose_from_xyz_rpy([-0.05, -0.15, 0.1], [0.0, std::f64::consts::FRAC_PI_2, 0.0]);
        let ray = |range| SensorRays::new(vec![Vector3::z()], range).unwrap();
        for form in [visible_voxels, visible_voxels_literal] {
            // In range [0.1, 0.8]: the unknown voxel 2 at 0.15.
            let v = form(&map, &pose, &ray([0.1, 0.8])).unwrap();
            assert_eq!((v.unknown.clone(), v.occupied.clone()), (vec![2], vec![]));
            assert_eq!((v.rays, v.rays_in_range, v.rays_blocked), (1, 1, 0));
            // r_min = 0.2: voxel 2 blocks the ray, nothing behind it is seen.
            let v = form(&map, &pose, &ray([0.2, 0.8])).unwrap();
            assert!(v.is_empty());
            assert_eq!(v.rays_blocked, 1);
            // r_max = the entry distance exactly (0.15 up to rounding): closed interval.
            let d = first_hit(&map, &pose.translation.vector.into(), &Vector3::x(), 1.0)
                .unwrap()
                .unwrap()
                .distance;
            assert!((d - 0.15).abs() < 1e-12);
            let v = form(&map, &pose, &ray([d, d])).unwrap();
            assert_eq!(v.unknown, vec![2]);
            // r_max just below: too far.
            let v = form(&map, &pose, &ray([0.0, d - 1e-9])).unwrap();
            assert!(v.is_empty() && v.rays_blocked == 0);
        }
    }

    #[test]
    fn each_voxel_counted_once_and_split_by_state() {
        // A wall of voxels at x index 3 in a 5×5×5 grid: occupied where y+z even, unknown
        // crust otherwise (the rest empty).
        let dims = [5, 5, 5];
        let mut values = vec![-1.0f32; 125];
        for z in 0..5 {
            for y in 0..5 {
                values[3 + 5 * (y + 5 * z)] = if (y + z) % 2 == 0 { 1.0 } else { 0.0 };
            }
        }
        let map = map_from(dims, 0.1, values);
        // Many rays from x = 0 fanning towards the wall.
        let dirs: Vec<_> = (0..21)
            .flat_map(|i| {
                (0..21).map(move |j| {
                    Vector3::new(1.0, (i as f64 - 10.0) * 0.06, (j as f64 - 10.0) * 0.06)
                })
            })
            .collect();
        let rays = SensorRays::new(dirs, [0.0, 1.0]).unwrap();
        let pose = pose_from_xyz_rpy([-0.07, 0.051, 0.301], [0.0, 0.0, 0.0]);
        // The rays are along x in the pose's frame here (pose z is irrelevant for this test).
        let fast = visible_voxels(&map, &pose, &rays).unwrap();
        let lit = visible_voxels_literal(&map, &pose, &rays).unwrap();
        assert_eq!(fast, lit);
        assert_eq!(fast.len(), 25);
        assert_eq!((fast.occupied.len(), fast.unknown.len()), (13, 12));
        assert_eq!(fast.rays_in_range, 441);
    }

    fn random_map(dims: (usize, usize, usize), values: &[i8]) -> ReducedMap {
        let n = dims.0 * dims.1 * dims.2;
        map_from(
            [dims.0, dims.1, dims.2],
            0.05,
            values[..n].iter().map(|&v| f32::from(v) * 0.5).collect(),
        )
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(200))]

        #[test]
        fn fast_equals_literal_on_random_grids(
            dims in (1usize..8, 1usize..8, 1usize..8),
            values in prop::collection::vec(-2i8..=2, 512),
            o in (-0.3f64..0.5, -0.4f64..0.3, -0.1f64..0.5),
            rpy in (-3.2f64..3.2, -1.6f64..1.6, -3.2f64..3.2),
            range in (0.0f64..0.2, 0.1f64..0.8),
        ) {
            let map = random_map(dims, &values);
            let pose = pose_from_xyz_rpy([o.0, o.1, o.2], [rpy.0, rpy.1, rpy.2]);
            let dirs: Vec<_> = (0..9)
                .flat_map(|i| (0..9).map(move |j| Vector3::new((i as f64 - 4.0) * 0.2, (j as f64 - 4.0) * 0.15, 1.0)))
                .collect();
            let rays = SensorRays::new(dirs, [range.0, range.0 + range.1]).unwrap();
            let fast = visible_voxels(&map, &pose, &rays).unwrap();
            let lit = visible_voxels_literal(&map, &pose, &rays).unwrap();
            prop_assert_eq!(&fast, &lit);
            // Per ray too, with distances equal to the bit.
            let origin = Point3::from(pose.translation.vector);
            for d in &rays.directions {
                let dir = pose.rotation * d;
                let a = first_hit(&map, &origin, &dir, 10.0).unwrap();
                let b = first_hit_literal(&map, &origin, &dir).unwrap();
                prop_assert_eq!(a, b);
            }
            // Observed voxels are in M̄ with the right state.
            for &l in &fast.unknown {
                prop_assert_eq!(map.state(l), Some(VoxelState::Unknown));
            }
            for &l in &fast.occupied {
                prop_assert_eq!(map.state(l), Some(VoxelState::Occupied));
            }
        }
    }
}
