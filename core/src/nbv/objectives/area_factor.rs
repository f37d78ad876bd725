//! Area factor (AF), Vasquez-Gomez et al. (IJARS 2014) as implemented in
//! `rpg_ig_active_reconstruction` (`VasquezGomezAreaFactorIg`): the view is best when a
//! target share of its rays hits known surface (for registration) and another share lands
//! on the occlusion plane behind it (for new surface).
//!
//! Each ray is registered once, as the first of (walking x_1…x_n):
//! - **occupied**: the first occupied voxel, if the voxel before it was free (a front face);
//! - **occplane**: the first unmeasured voxel marked behind surface
//!   ([`OcclusionDistances`](crate::occupancy::OcclusionDistances));
//! - **unobserved**: neither.
//!
//! A ray that reaches an occupied voxel through a non-free one is registered but counted in
//! none. With N = n_occ + n_occplane + n_unobs, x_o = n_occ/N, x_p = n_occplane/N:
//!
//! ```text
//! G(v) = f(x_o; 0.2) + f(x_p; 0.8)   (0 if N = 0)
//! f(x; α) = 3x²/α² − 2x³/α³                              for x ≤ α
//!         = [−2x³ + 3(α+1)x² − 6αx + 3α − 1] / (α − 1)³  for x > α
//! ```
//!
//! f(0) = f(1) = 0, f(α) = 1, so G ≤ 2. The target shares 0.2 and 0.8 are the code's only
//! constants (no α/β/γ weights of the original utility). The reference lets leading
//! unmeasured voxels count as free until the first measured voxel of *any* ray (its flag is
//! never reset); here that holds per ray (the camera side of each ray is free space).

use super::{RayVoxel, VoxelClass};

/// How a ray is registered.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AreaRay {
    /// Enters an occupied voxel from a free one.
    Occupied,
    /// Meets an unmeasured voxel behind surface first.
    OcclusionPlane,
    /// Neither.
    Unobserved,
    /// Reaches an occupied voxel through a non-free one: counted in none.
    Uncounted,
}

/// One ray's registration.
///
/// ```
/// use nbv_core::nbv::{AreaRay, RayVoxel, area_factor_ray};
/// let free = RayVoxel { log_odds: -2.2, occlusion: 0 };
/// let occupied = RayVoxel { log_odds: 2.2, occlusion: 0 };
/// assert_eq!(area_factor_ray(&[free, occupied]), AreaRay::Occupied);
/// assert_eq!(area_factor_ray(&[free]), AreaRay::Unobserved);
/// ```
pub fn area_factor_ray(ray: &[RayVoxel]) -> AreaRay {
    let (mut previous_free, mut measured_seen) = (true, false);
    for v in ray {
        if !v.measured() && v.occlusion > 0 {
            return AreaRay::OcclusionPlane;
        }
        let class = v.class();
        if class == VoxelClass::Occupied {
            return if previous_free {
                AreaRay::Occupied
            } else {
                AreaRay::Uncounted
            };
        }
        measured_seen |= v.measured();
        previous_free = class == VoxelClass::Free || !measured_seen;
    }
    AreaRay::Unobserved
}

/// The view's AF from its rays' registrations.
///
/// ```
/// use nbv_core::nbv::{AreaRay, area_factor_view};
/// // One ray in five on surface, four on the occlusion plane: both targets met.
/// let rays = [AreaRay::Occupied, AreaRay::OcclusionPlane, AreaRay::OcclusionPlane,
///             AreaRay::OcclusionPlane, AreaRay::OcclusionPlane];
/// assert!((area_factor_view(rays) - 2.0).abs() < 1e-12);
/// ```
pub fn area_factor_view(rays: impl IntoIterator<Item = AreaRay>) -> f64 {
    let (mut occupied, mut plane, mut unobserved) = (0usize, 0usize, 0usize);
    for r in rays {
        match r {
            AreaRay::Occupied => occupied += 1,
            AreaRay::OcclusionPlane => plane += 1,
            AreaRay::Unobserved => unobserved += 1,
            AreaRay::Uncounted => {}
        }
    }
    let n = (occupied + plane + unobserved) as f64;
    if n == 0.0 {
        return 0.0;
    }
    area_function(occupied as f64 / n, 0.2) + area_function(plane as f64 / n, 0.8)
}

/// f(x; α): 0 at 0 and 1, 1 at α, zero slope at all three.
fn area_function(x: f64, alpha: f64) -> f64 {
    if x <= alpha {
        3.0 * x * x / (alpha * alpha) - 2.0 * x.powi(3) / alpha.powi(3)
    } else {
        (-2.0 * x.powi(3) + 3.0 * (alpha + 1.0) * x * x - 6.0 * alpha * x + 3.0 * alpha - 1.0)
            / (alpha - 1.0).powi(3)
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_rays::{behind_occupied, empty, occluded_unknown};
    use super::*;

    #[test]
    fn hand_computed() {
        assert_eq!(area_factor_ray(&behind_occupied()), AreaRay::Occupied);
        assert_eq!(
            area_factor_ray(&occluded_unknown()),
            AreaRay::OcclusionPlane
        );
        assert_eq!(area_factor_ray(&empty()), AreaRay::Unobserved);
        // A measured unknown voxel (p 0.3) before the occupied one: counted in none.
        let unknown = RayVoxel {
            log_odds: -0.847,
            occlusion: 0,
        };
        let occupied = RayVoxel {
            log_odds: 2.2,
            occlusion: 0,
        };
        assert_eq!(area_factor_ray(&[unknown, occupied]), AreaRay::Uncounted);
        // An unmeasured unmarked voxel first still counts as free space.
        let prior = RayVoxel {
            log_odds: 0.0,
            occlusion: 0,
        };
        assert_eq!(area_factor_ray(&[prior, occupied]), AreaRay::Occupied);
        // x_o = 1/4: f = (−2/64 + 3.6/16 − 0.3 − 0.4)/(−0.512) = 0.988770;
        // x_p = 2/4: f = 3·0.25/0.64 − 2·0.125/0.512 = 0.683594.
        let g = area_factor_view([
            AreaRay::Occupied,
            AreaRay::OcclusionPlane,
            AreaRay::OcclusionPlane,
            AreaRay::Unobserved,
            AreaRay::Uncounted,
        ]);
        assert!((g - (0.988_769_531_25 + 0.683_593_75)).abs() < 1e-9, "{g}");
        assert_eq!(area_factor_view([]), 0.0);
        assert_eq!(area_factor_view([AreaRay::Uncounted]), 0.0);
        for alpha in [0.2, 0.8] {
            assert!(area_function(0.0, alpha).abs() < 1e-12);
            assert!((area_function(alpha, alpha) - 1.0).abs() < 1e-12);
            assert!(area_function(1.0, alpha).abs() < 1e-12);
        }
    }
}
