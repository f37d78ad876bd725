//! [`RayVoxel`] and [`cast_ray`]: a camera ray through the full log-odds grid, as the
//! information-gain objectives read it — the voxels x_1…x_n from the camera to the end
//! voxel x_n, with their probabilities, occupancy classes and entropies.
//!
//! As the reference caster (OctoMap `castRay` with unknown cells ignored): the ray walks the
//! grid's DDA from the camera and stops at the **first measured voxel with p ≥ 0.5** (here
//! log-odds > 0: unmeasured voxels, exactly at the prior 0, are passed), or at the maximum
//! range; that voxel is x_n. Every voxel up to it is visited, one per DDA step. A ray
//! that leaves the bounded grid ends at its last voxel inside (OctoMap's unbounded tree
//! would go on through prior voxels; this workspace has none). A ray can thus end on a
//! voxel the classes call unknown (0.5 < p ≤ 0.8).
//!
//! Classes as the reference code: **unknown** ⇔ 0.2 ≤ p ≤ 0.8, **occupied** ⇔ p > 0.8,
//! **free** ⇔ p < 0.2. Entropy `h(p) = −p ln p − (1−p) ln(1−p)` in nats.

use nalgebra::{Point3, Vector3};

use super::super::NbvError;
use crate::occupancy::{OcclusionDistances, OccupancyGrid, probability};

/// A voxel's class for the information-gain objectives (thresholds 0.2 and 0.8).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum VoxelClass {
    /// p < 0.2.
    Free,
    /// 0.2 ≤ p ≤ 0.8 (unmeasured voxels, p = 0.5, included).
    Unknown,
    /// p > 0.8.
    Occupied,
}

/// One voxel on a ray: its log-odds and its [`OcclusionDistances`] step (0: none).
///
/// ```
/// use nbv_core::nbv::{RayVoxel, VoxelClass};
/// let v = RayVoxel { log_odds: 0.0, occlusion: 0 };
/// assert_eq!((v.class(), v.measured()), (VoxelClass::Unknown, false));
/// assert!((v.entropy() - std::f64::consts::LN_2).abs() < 1e-15);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RayVoxel {
    /// Log-odds of occupancy.
    pub log_odds: f32,
    /// Steps behind the nearest measured surface point (0: not marked).
    pub occlusion: u16,
}

impl RayVoxel {
    /// Occupancy probability p.
    pub fn probability(&self) -> f64 {
        probability(f64::from(self.log_odds))
    }

    /// Whether the voxel was ever measured (log-odds not exactly the prior 0).
    pub fn measured(&self) -> bool {
        self.log_odds != 0.0
    }

    /// Its class by p.
    pub fn class(&self) -> VoxelClass {
        let p = self.probability();
        if p < 0.2 {
            VoxelClass::Free
        } else if p > 0.8 {
            VoxelClass::Occupied
        } else {
            VoxelClass::Unknown
        }
    }

    /// h(p) in nats.
    pub fn entropy(&self) -> f64 {
        entropy(self.probability())
    }
}

/// `h(p) = −p ln p − (1−p) ln(1−p)` (nats), 0 at p = 0 and p = 1.
///
/// ```
/// assert!((nbv_core::nbv::entropy(0.2) - 0.500_402_4).abs() < 1e-7);
/// assert_eq!(nbv_core::nbv::entropy(1.0), 0.0);
/// ```
pub fn entropy(p: f64) -> f64 {
    let term = |q: f64| if q > 0.0 { -q * q.ln() } else { 0.0 };
    term(p) + term(1.0 - p)
}

/// Casts the ray `origin + t·direction`, `0 ≤ t ≤ max_range`, through `grid`, writing
/// x_1…x_n into `out` (cleared first; empty if the ray misses the grid). `occlusion`
/// supplies the voxels' steps behind surface (all 0 without it).
pub fn cast_ray(
    grid: &OccupancyGrid,
    occlusion: Option<&OcclusionDistances>,
    origin: &Point3<f64>,
    direction: &Vector3<f64>,
    max_range: f64,
    out: &mut Vec<RayVoxel>,
) -> Result<(), NbvError> {
    out.clear();
    let values = grid.log_odds();
    grid.geometry()
        .traverse(origin, direction, max_range)?
        .find_map_linear(|l, _| {
            let v = values[l];
            out.push(RayVoxel {
                log_odds: v,
                occlusion: occlusion.map_or(0, |o| o.step(l)),
            });
            (v > 0.0).then_some(())
        });
    Ok(())
}
