//! Proximity count (PC), credited to Isler et al. ICRA 2016 in `rpg_ig_active_reconstruction`
//! (`ProximityCountIg`; the reference launch file's only weighted metric): unmeasured voxels
//! close behind measured surface, weighted by how close,
//!
//! ```text
//! G(v) = Σ_rays Σ_{x on r : unmeasured, occDist(x) > 0} (maxDist − occDist(x))
//! ```
//!
//! occDist is the voxel's step index behind the nearest measured point, written by the map
//! update ([`OcclusionDistances`](crate::occupancy::OcclusionDistances), out to 0.3 m), and
//! maxDist = 2·0.3 m / resolution (30 at 2 cm). No visibility, no entropy; unmarked unknown
//! voxels add 0.

use super::RayVoxel;

/// One ray's PC term, `max_steps` being maxDist.
///
/// ```
/// use nbv_core::nbv::{RayVoxel, proximity_count_ray};
/// let behind = |k| RayVoxel { log_odds: 0.0, occlusion: k };
/// assert_eq!(proximity_count_ray(&[behind(0), behind(3), behind(1)], 30), 27.0 + 29.0);
/// ```
pub fn proximity_count_ray(ray: &[RayVoxel], max_steps: u16) -> f64 {
    ray.iter()
        .filter(|v| !v.measured() && v.occlusion > 0)
        .map(|v| f64::from(max_steps.saturating_sub(v.occlusion)))
        .sum()
}

#[cfg(test)]
mod tests {
    use super::super::test_rays::{behind_occupied, empty, occluded_unknown};
    use super::*;

    #[test]
    fn hand_computed() {
        // Measured voxels only: nothing.
        assert_eq!(proximity_count_ray(&behind_occupied(), 6), 0.0);
        // The two unmeasured voxels 2 and 1 steps behind the far surface: (6−2) + (6−1).
        assert_eq!(proximity_count_ray(&occluded_unknown(), 6), 9.0);
        assert_eq!(proximity_count_ray(&empty(), 6), 0.0);
        // A measured voxel keeps no weight even if it was marked before it was measured.
        let seen = RayVoxel {
            log_odds: -0.8,
            occlusion: 1,
        };
        assert_eq!(proximity_count_ray(&[seen], 6), 0.0);
    }
}
