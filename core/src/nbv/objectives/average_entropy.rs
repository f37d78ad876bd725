//! Average entropy (AE), Kriegel et al. (2015) as implemented in
//! `rpg_ig_active_reconstruction` (`AverageEntropyIg`): the mean entropy of the voxels on
//! the rays that end on an occupied voxel,
//!
//! ```text
//! G(v) = Σ_{r : x_n occupied} Σ_{k=1..n} h(p_k)  /  Σ_{r : x_n occupied} n
//! ```
//!
//! (0 when no ray ends on an occupied voxel). No visibility.

use super::{RayVoxel, VoxelClass};

/// One ray's entropy sum and voxel count, if it ends on an occupied voxel.
///
/// ```
/// use nbv_core::nbv::{RayVoxel, average_entropy_ray};
/// let unknown = RayVoxel { log_odds: 0.0, occlusion: 0 };
/// let occupied = RayVoxel { log_odds: 2.2, occlusion: 0 };
/// let (sum, n) = average_entropy_ray(&[unknown, occupied]).unwrap();
/// assert_eq!(n, 2);
/// assert!(average_entropy_ray(&[unknown]).is_none());
/// ```
pub fn average_entropy_ray(ray: &[RayVoxel]) -> Option<(f64, usize)> {
    let end = ray.last()?;
    (end.class() == VoxelClass::Occupied)
        .then(|| (ray.iter().map(RayVoxel::entropy).sum(), ray.len()))
}

/// The view's AE from its rays' sums (in ray order).
///
/// ```
/// use nbv_core::nbv::average_entropy_view;
/// assert_eq!(average_entropy_view([Some((1.0, 2)), None, Some((2.0, 2))]), 0.75);
/// assert_eq!(average_entropy_view([None]), 0.0);
/// ```
pub fn average_entropy_view(rays: impl IntoIterator<Item = Option<(f64, usize)>>) -> f64 {
    let (mut sum, mut n) = (0.0, 0usize);
    for (s, k) in rays.into_iter().flatten() {
        sum += s;
        n += k;
    }
    if n == 0 { 0.0 } else { sum / n as f64 }
}

#[cfg(test)]
mod tests {
    use super::super::test_rays::{H01, behind_occupied, empty, occluded_unknown};
    use super::*;
    use std::f64::consts::LN_2;

    #[test]
    fn hand_computed() {
        let a = average_entropy_ray(&behind_occupied()).unwrap();
        assert_eq!(a.1, 3);
        assert!((a.0 - 3.0 * H01).abs() < 1e-6);
        let b = average_entropy_ray(&occluded_unknown()).unwrap();
        assert_eq!(b.1, 4);
        assert!((b.0 - (2.0 * H01 + 2.0 * LN_2)).abs() < 1e-6);
        assert_eq!(average_entropy_ray(&empty()), None);
        // Both rays: (5·h(0.1) + 2 ln 2) / 7.
        let g = average_entropy_view([Some(a), Some(b), None]);
        assert!((g - (5.0 * H01 + 2.0 * LN_2) / 7.0).abs() < 1e-6);
    }
}
