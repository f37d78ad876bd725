//! Rear side voxel (RSV), Isler et al. ICRA 2016 (`RearSideVoxelIg` in
//! `rpg_ig_active_reconstruction`): the number of rays that enter an **occupied** voxel
//! directly from an **unknown** one,
//!
//! ```text
//! G(v) = |{ r : x_n occupied, x_{n−1} unknown }|
//! ```
//!
//! — camera → unknown → occupied: the ray meets a seen surface from behind, its unseen rear
//! side (not "occupied, then unknown behind it"). Unmeasured voxels are unknown. No entropy,
//! no visibility. Only the end voxel can qualify, since the cast stops at p ≥ 0.5.

use super::{RayVoxel, VoxelClass};

/// One ray's RSV term: 1 or 0.
///
/// ```
/// use nbv_core::nbv::{RayVoxel, rear_side_voxel_ray};
/// let unknown = RayVoxel { log_odds: 0.0, occlusion: 0 };
/// let occupied = RayVoxel { log_odds: 2.2, occlusion: 0 };
/// assert_eq!(rear_side_voxel_ray(&[unknown, occupied]), 1.0);
/// assert_eq!(rear_side_voxel_ray(&[occupied]), 0.0);
/// ```
pub fn rear_side_voxel_ray(ray: &[RayVoxel]) -> f64 {
    match ray {
        [.., before, end]
            if end.class() == VoxelClass::Occupied && before.class() == VoxelClass::Unknown =>
        {
            1.0
        }
        _ => 0.0,
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_rays::{behind_occupied, empty, occluded_unknown};
    use super::*;

    #[test]
    fn hand_computed() {
        // free, free, occupied: a front face, not a rear side.
        assert_eq!(rear_side_voxel_ray(&behind_occupied()), 0.0);
        // free, unknown, unknown, occupied: a rear side.
        assert_eq!(rear_side_voxel_ray(&occluded_unknown()), 1.0);
        assert_eq!(rear_side_voxel_ray(&empty()), 0.0);
    }
}
