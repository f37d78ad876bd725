//! Rear side entropy (RSE), Isler et al. ICRA 2016 (`RearSideEntropyIg` in
//! `rpg_ig_active_reconstruction`): the visibility-weighted entropy of the unknown voxels
//! right in front of a rear-side hit,
//!
//! ```text
//! S ← S + P_v(x_k)·h(p_k) over each run of consecutive unknown voxels (a free or occupied
//!     voxel resets S to 0);
//! G(v) = Σ_{r : x_n occupied} ( S + P_v(x_n)·h(p_n) )
//! ```
//!
//! Rays whose end voxel is not occupied add 0. Visibility as the papers
//! (`Π (1 − p_i)`), not the reference code's `Π p_i`.

use super::{RayVoxel, Visibility, VoxelClass};

/// One ray's RSE term.
///
/// ```
/// use nbv_core::nbv::{RayVoxel, rear_side_entropy_ray};
/// let unknown = RayVoxel { log_odds: 0.0, occlusion: 0 };
/// let occupied = RayVoxel { log_odds: 2.197_224_6, occlusion: 0 }; // p ≈ 0.9
/// let g = rear_side_entropy_ray(&[unknown, occupied]);
/// assert!((g - (std::f64::consts::LN_2 + 0.5 * 0.325_083)).abs() < 1e-6);
/// ```
pub fn rear_side_entropy_ray(ray: &[RayVoxel]) -> f64 {
    let Some((end, before)) = ray.split_last() else {
        return 0.0;
    };
    if end.class() != VoxelClass::Occupied {
        return 0.0;
    }
    let mut visibility = Visibility::default();
    let mut run = 0.0;
    for v in before {
        let p = v.probability();
        if v.class() == VoxelClass::Unknown {
            run += visibility.get() * super::entropy(p);
        } else {
            run = 0.0;
        }
        visibility.pass(p);
    }
    run + visibility.get() * end.entropy()
}

#[cfg(test)]
mod tests {
    use super::super::test_rays::{H01, behind_occupied, empty, occluded_unknown};
    use super::*;

    #[test]
    fn hand_computed() {
        // free, free, occupied: no unknown run; the end voxel at P_v = 0.81.
        assert!((rear_side_entropy_ray(&behind_occupied()) - 0.81 * H01).abs() < 1e-6);
        // free, unknown, unknown, occupied: ln 2·(0.9 + 0.45) + 0.225·h(0.9).
        let g = std::f64::consts::LN_2 * 1.35 + 0.225 * H01;
        assert!((rear_side_entropy_ray(&occluded_unknown()) - g).abs() < 1e-6);
        assert_eq!(rear_side_entropy_ray(&empty()), 0.0);
        // A run broken by a free voxel restarts; a ray not ending occupied adds nothing.
        let u = RayVoxel {
            log_odds: 0.0,
            occlusion: 0,
        };
        let f = RayVoxel {
            log_odds: -2.197_224_6,
            occlusion: 0,
        };
        let o = RayVoxel {
            log_odds: 2.197_224_6,
            occlusion: 0,
        };
        let g = rear_side_entropy_ray(&[u, f, u, o]);
        // P_v: 1, 0.5, 0.45, 0.225; the run restarts at the third voxel.
        assert!((g - (0.45 * std::f64::consts::LN_2 + 0.225 * H01)).abs() < 1e-6);
        assert_eq!(rear_side_entropy_ray(&[u, u]), 0.0);
    }
}
