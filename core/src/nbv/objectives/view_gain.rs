//! [`view_gain`]: an information-gain objective's G(v) for one viewpoint — the sensor's
//! subsampled rays ([`SensorRays`], the same set as eq. (4)'s O_v) cast through the full
//! log-odds grid ([`cast_ray`]), each ray's term by the objective's formula, combined.
//!
//! Rays are cast in parallel (rayon); their terms are collected in ray order and combined
//! sequentially, so G is bit-identical at any thread count.

use nalgebra::Point3;
use rayon::prelude::*;

use super::super::{NbvError, SensorRays};
use super::{
    AreaRay, Objective, area_factor_ray, area_factor_view, average_entropy_ray,
    average_entropy_view, cast_ray, occlusion_aware_ray, proximity_count_ray,
    rear_side_entropy_ray, rear_side_voxel_ray, unobserved_voxel_ray,
};
use crate::math::Pose;
use crate::occupancy::{OcclusionDistances, OccupancyGrid};

/// What the information-gain objectives read: the grid, and the occlusion distances the
/// map update keeps (needed by proximity count and the area factor only).
#[derive(Debug, Clone, Copy)]
pub struct GainMap<'a> {
    /// The log-odds grid.
    pub grid: &'a OccupancyGrid,
    /// Steps behind measured surface ([`Objective::needs_occlusion`]).
    pub occlusion: Option<&'a OcclusionDistances>,
}

/// One ray's contribution.
enum RayTerm {
    Sum(f64),
    Area(AreaRay),
    Average(Option<(f64, usize)>),
}

/// G(v) of `objective` for the camera at `pose` (optical frame, z forward) with `rays`:
/// each ray from the camera out to the range's far end `rays.range[1]`.
///
/// Errors for [`Objective::Paper`] (eq. (4) scores the reduced map:
/// [`ScoreWeights`](crate::nbv::ScoreWeights)), for proximity count or area factor without
/// occlusion distances, and for a non-finite pose.
///
/// ```
/// use nbv_core::nbv::{GainMap, Objective, SensorRays, view_gain};
/// use nbv_core::occupancy::{GridGeometry, OccupancyGrid, OccupancyParams};
/// use nalgebra::{Point3, Vector3};
/// // A row: unmeasured, unmeasured, occupied (p ≈ 0.9); the camera looks along +x.
/// let g = GridGeometry::from_dims(Point3::origin(), 0.1, [3, 1, 1])?;
/// let grid = OccupancyGrid::from_log_odds(g, OccupancyParams::default(), vec![0.0, 0.0, 2.2])?;
/// let pose = nbv_core::math::pose_from_xyz_rpy([-0.05, 0.05, 0.05], [0.0, std::f64::consts::FRAC_PI_2, 0.0]);
/// let rays = SensorRays::new(vec![Vector3::z()], [0.1, 0.8])?;
/// let map = GainMap { grid: &grid, occlusion: None };
/// assert_eq!(view_gain(Objective::RearSideVoxel, &map, &pose, &rays)?, 1.0);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn view_gain(
    objective: Objective,
    map: &GainMap<'_>,
    pose: &Pose,
    rays: &SensorRays,
) -> Result<f64, NbvError> {
    if objective == Objective::Paper {
        return Err(NbvError::InvalidInput(
            "eq. (4) is scored on the reduced map, not by view_gain",
        ));
    }
    let occlusion = if objective.needs_occlusion() {
        Some(map.occlusion.ok_or(NbvError::InvalidInput(
            "proximity count and area factor need the map's occlusion distances",
        ))?)
    } else {
        None
    };
    super::super::visibility::check_pose(pose)?;
    let max_steps = occlusion.map_or(0, |o| o.max_steps(map.grid.geometry().resolution()));
    let origin = Point3::from(pose.translation.vector);
    let terms = rays
        .directions
        .par_iter()
        .map_init(Vec::new, |ray, d| -> Result<RayTerm, NbvError> {
            cast_ray(
                map.grid,
                occlusion,
                &origin,
                &(pose.rotation * d),
                rays.range[1],
                ray,
            )?;
            Ok(match objective {
                Objective::OcclusionAware => RayTerm::Sum(occlusion_aware_ray(ray)),
                Objective::UnobservedVoxel => RayTerm::Sum(unobserved_voxel_ray(ray)),
                Objective::RearSideVoxel => RayTerm::Sum(rear_side_voxel_ray(ray)),
                Objective::RearSideEntropy => RayTerm::Sum(rear_side_entropy_ray(ray)),
                Objective::ProximityCount => RayTerm::Sum(proximity_count_ray(ray, max_steps)),
                Objective::AreaFactor => RayTerm::Area(area_factor_ray(ray)),
                Objective::AverageEntropy | Objective::Paper => {
                    RayTerm::Average(average_entropy_ray(ray))
                }
            })
        })
        .collect::<Result<Vec<_>, NbvError>>()?;
    Ok(match objective {
        Objective::AreaFactor => area_factor_view(terms.iter().filter_map(|t| match t {
            RayTerm::Area(a) => Some(*a),
            _ => None,
        })),
        Objective::AverageEntropy => average_entropy_view(terms.iter().map(|t| match t {
            RayTerm::Average(a) => *a,
            _ => None,
        })),
        _ => terms
            .iter()
            .map(|t| match t {
                RayTerm::Sum(s) => *s,
                _ => 0.0,
            })
            .sum(),
    })
}

#[cfg(test)]
mod tests {
    use super::super::test_rays::{FREE, H01, OCCUPIED, row};
    use super::*;
    use crate::math::pose_from_xyz_rpy;
    use nalgebra::Vector3;
    use proptest::prelude::*;
    use std::f64::consts::{FRAC_PI_2, LN_2};

    /// The camera at x = −0.05 looking along +x, with the given ray directions (sensor frame).
    fn gain(objective: Objective, values: &[f32], steps: &[u16], dirs: Vec<Vector3<f64>>) -> f64 {
        let (grid, marks) = row(values, steps);
        let pose = pose_from_xyz_rpy([-0.05, 0.05, 0.05], [0.0, FRAC_PI_2, 0.0]);
        let rays = SensorRays::new(dirs, [0.1, 1.0]).unwrap();
        let map = GainMap {
            grid: &grid,
            occlusion: Some(&marks),
        };
        view_gain(objective, &map, &pose, &rays).unwrap()
    }

    #[test]
    fn whole_views_by_hand() {
        // The occluded-unknown row seen by two identical rays: twice each ray's term.
        let values = [FREE, 0.0, 0.0, OCCUPIED, FREE];
        let steps = [0, 2, 1, 0, 0];
        let two = vec![Vector3::z(), Vector3::z()];
        let oa = H01 * 1.225 + LN_2 * 1.35;
        let cases = [
            (Objective::OcclusionAware, 2.0 * oa),
            (Objective::UnobservedVoxel, 2.0 * LN_2 * 1.35),
            (Objective::RearSideVoxel, 2.0),
            (
                Objective::RearSideEntropy,
                2.0 * (LN_2 * 1.35 + 0.225 * H01),
            ),
            // maxDist at 0.1 m: 2·0.3/0.1 = 6.
            (Objective::ProximityCount, 18.0),
            // Both rays on the occlusion plane: x_p = 1, f(1; 0.8) = 0.
            (Objective::AreaFactor, 0.0),
            (Objective::AverageEntropy, (2.0 * H01 + 2.0 * LN_2) / 4.0),
        ];
        for (o, want) in cases {
            let g = gain(o, &values, &steps, two.clone());
            assert!((g - want).abs() < 1e-6, "{o}: {g} vs {want}");
        }
        // An empty view (the rays look away from the grid): 0 for every objective.
        for o in &Objective::ALL[1..] {
            assert_eq!(
                gain(*o, &values, &steps, vec![-Vector3::z(); 3]),
                0.0,
                "{o}"
            );
        }
        // eq. (4) is not scored here; PC without occlusion distances is an error.
        let (grid, _) = row(&values, &steps);
        let map = GainMap {
            grid: &grid,
            occlusion: None,
        };
        let rays = SensorRays::new(vec![Vector3::z()], [0.1, 1.0]).unwrap();
        for o in [
            Objective::Paper,
            Objective::ProximityCount,
            Objective::AreaFactor,
        ] {
            assert!(view_gain(o, &map, &Pose::identity(), &rays).is_err());
        }
    }

    fn random_view(
        values: &[i8],
        steps: &[u8],
        yaw: f64,
    ) -> (Vec<f32>, Vec<u16>, Pose, SensorRays) {
        let v = values.iter().map(|&x| f32::from(x) * 0.7).collect();
        let s = steps.iter().map(|&x| u16::from(x % 4)).collect();
        let pose = pose_from_xyz_rpy([-0.05, 0.21, 0.13], [0.0, FRAC_PI_2, yaw]);
        let dirs = (0..7)
            .flat_map(|i| {
                (0..7).map(move |j| {
                    Vector3::new((i as f64 - 3.0) * 0.15, (j as f64 - 3.0) * 0.15, 1.0)
                })
            })
            .collect();
        (v, s, pose, SensorRays::new(dirs, [0.0, 0.9]).unwrap())
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(40))]

        /// Non-negative, and bit-identical on one and on two rayon threads.
        #[test]
        fn non_negative_and_thread_count_free(
            values in prop::collection::vec(-4i8..=4, 6 * 5 * 4),
            steps in prop::collection::vec(0u8..8, 6 * 5 * 4),
            yaw in -0.6f64..0.6,
        ) {
            let (v, s, pose, rays) = random_view(&values, &steps, yaw);
            let g = crate::occupancy::GridGeometry::from_dims(Point3::origin(), 0.08, [6, 5, 4]).unwrap();
            let grid = OccupancyGrid::from_log_odds(g, crate::occupancy::OccupancyParams::default(), v).unwrap();
            let marks = OcclusionDistances::from_steps(s);
            let map = GainMap { grid: &grid, occlusion: Some(&marks) };
            for o in &Objective::ALL[1..] {
                let pool = |n| rayon::ThreadPoolBuilder::new().num_threads(n).build().unwrap();
                let one = pool(1).install(|| view_gain(*o, &map, &pose, &rays)).unwrap();
                let two = pool(2).install(|| view_gain(*o, &map, &pose, &rays)).unwrap();
                prop_assert!(one >= 0.0, "{} {}", o, one);
                prop_assert_eq!(one.to_bits(), two.to_bits());
            }
        }

        /// Turning a free voxel into an unmeasured one never lowers the unobserved-voxel
        /// gain of a view whose rays meet no occupied voxel.
        #[test]
        fn unobserved_gain_grows_with_unknown_voxels(
            free in prop::collection::vec(prop::bool::ANY, 6 * 5 * 4),
            pick in 0usize..120,
        ) {
            let v: Vec<f32> = free.iter().map(|&f| if f { FREE } else { 0.0 }).collect();
            let mut more = v.clone();
            more[pick] = 0.0;
            let (_, _, pose, rays) = random_view(&[0; 120], &[0; 120], 0.0);
            let g = crate::occupancy::GridGeometry::from_dims(Point3::origin(), 0.08, [6, 5, 4]).unwrap();
            let p = crate::occupancy::OccupancyParams::default();
            let at = |values: Vec<f32>| {
                let grid = OccupancyGrid::from_log_odds(g, p, values).unwrap();
                view_gain(Objective::UnobservedVoxel, &GainMap { grid: &grid, occlusion: None }, &pose, &rays).unwrap()
            };
            prop_assert!(at(more) >= at(v) - 1e-12);
        }
    }
}
