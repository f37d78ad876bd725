//! Occlusion aware (OA), Isler et al. ICRA 2016 (`OcclusionAwareIg` in
//! `rpg_ig_active_reconstruction`): the entropy of every voxel a ray traverses, weighted by
//! its visibility probability,
//!
//! ```text
//! G(v) = Σ_rays Σ_{k=1..n} P_v(x_k) · h(p_k),   P_v(x_k) = Π_{i<k} (1 − p_i)
//! ```
//!
//! over x_1…x_n up to and including the end voxel ([`cast_ray`](super::cast_ray)). The
//! visibility is the papers' ([`Visibility`](super::Visibility)), not the reference code's.
//! The code's "void ray" term (2 ln 2 for a ray without an end point) never fires there,
//! and has no counterpart here: every ray has its voxels.

use super::RayVoxel;
use super::visibility_probability::visible_entropy;

/// One ray's OA term.
///
/// ```
/// use nbv_core::nbv::{RayVoxel, occlusion_aware_ray};
/// // Two unmeasured voxels (p = 0.5): h = ln 2 seen with P_v = 1, then 0.5.
/// let ray = [RayVoxel { log_odds: 0.0, occlusion: 0 }; 2];
/// assert!((occlusion_aware_ray(&ray) - 1.5 * std::f64::consts::LN_2).abs() < 1e-15);
/// ```
pub fn occlusion_aware_ray(ray: &[RayVoxel]) -> f64 {
    visible_entropy(ray, |_| true)
}

#[cfg(test)]
mod tests {
    use super::super::test_rays::{behind_occupied, empty, occluded_unknown};
    use super::*;

    #[test]
    fn hand_computed() {
        // free 0.1, free 0.1, occupied 0.9: h = 0.325083 each, P_v = 1, 0.9, 0.81.
        assert!((occlusion_aware_ray(&behind_occupied()) - 0.325_082_973 * 2.71).abs() < 1e-6);
        // free 0.1, unknown 0.5, unknown 0.5, occupied 0.9: P_v = 1, 0.9, 0.45, 0.225.
        let g = 0.325_082_973 * 1.225 + std::f64::consts::LN_2 * 1.35;
        assert!((occlusion_aware_ray(&occluded_unknown()) - g).abs() < 1e-6);
        assert_eq!(occlusion_aware_ray(&empty()), 0.0);
    }
}
