//! Unobserved voxel (UV), Isler et al. ICRA 2016 (`UnobservedVoxelIg` in
//! `rpg_ig_active_reconstruction`): occlusion aware restricted to unknown voxels,
//!
//! ```text
//! G(v) = Σ_rays Σ_{k: x_k unknown} P_v(x_k) · h(p_k)
//! ```
//!
//! with the visibility still updated at every voxel (free and occupied ones lower it) —
//! the papers' `Π (1 − p_i)`, not the reference code's `Π p_i`. Unknown: 0.2 ≤ p ≤ 0.8.

use super::visibility_probability::visible_entropy;
use super::{RayVoxel, VoxelClass};

/// One ray's UV term.
///
/// ```
/// use nbv_core::nbv::{RayVoxel, unobserved_voxel_ray};
/// // A free voxel (p ≈ 0.1) then an unmeasured one: only the second counts, at P_v = 0.9.
/// let ray = [RayVoxel { log_odds: -2.197_224_6, occlusion: 0 }, RayVoxel { log_odds: 0.0, occlusion: 0 }];
/// assert!((unobserved_voxel_ray(&ray) - 0.9 * std::f64::consts::LN_2).abs() < 1e-6);
/// ```
pub fn unobserved_voxel_ray(ray: &[RayVoxel]) -> f64 {
    visible_entropy(ray, |v| v.class() == VoxelClass::Unknown)
}

#[cfg(test)]
mod tests {
    use super::super::test_rays::{behind_occupied, empty, occluded_unknown};
    use super::*;

    #[test]
    fn hand_computed() {
        // No unknown voxel before the occupied one: nothing.
        assert_eq!(unobserved_voxel_ray(&behind_occupied()), 0.0);
        // The two unknown voxels at P_v = 0.9 and 0.45.
        let g = std::f64::consts::LN_2 * 1.35;
        assert!((unobserved_voxel_ray(&occluded_unknown()) - g).abs() < 1e-6);
        assert_eq!(unobserved_voxel_ray(&empty()), 0.0);
    }
}
