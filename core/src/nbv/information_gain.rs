//! [`InformationGain`]: the paper's eq. (5), evaluated over the predicted visible set O_v
//! from the voxel probabilities before and after the observation.
//!
//! ```text
//! G = Σ_{m ∈ O_v} −p(m) · log( p(m | z_v) / p(m) )
//! ```
//!
//! with `p(m)` the occupancy probability before the view and `p(m | z_v)` after the grid
//! was updated with it (natural logarithm; `p = 1/(1 + e^(−o))` from the log-odds).
//!
//! # Sign and behaviour (implemented as printed)
//!
//! Each term is `p·ln(p/p')`: it is **positive** when the observation lowered the voxel's
//! occupancy probability (the voxel was seen free: `p' < p`), **negative** when it raised
//! it (the voxel was hit, or a hit confirmed: `p' > p`), and 0 for a voxel the observation
//! did not change. So G is not a divergence and can be negative: it is the first half of
//! the Bernoulli Kullback–Leibler divergence `p·ln(p/p') + (1−p)·ln((1−p)/(1−p'))`, without
//! the second half that would make it non-negative. With the default map (p̄ = 0.7):
//! - an unknown voxel (p = 0.5) seen free (p' = 0.3): `0.5·ln(0.5/0.3)` = +0.2554;
//! - an unknown voxel seen occupied (p' = 0.7): `0.5·ln(0.5/0.7)` = −0.1682;
//! - an occupied voxel (p = 0.7) hit again (p' = 0.8448): `0.7·ln(0.7/0.8448)` = −0.1316.
//!
//! A view that hits surface therefore gives a small or negative G, and one that only clears
//! unknown space a positive G. The stop rule ([`StopRule`](super::StopRule)) compares G
//! itself (not |G|) with `gain_thr`, as the paper does, so a negative gain stops the
//! exploration of the object; its doc gives the numbers of a simulated first view, for
//! which G is negative. [`InformationGain::bernoulli_kl`], the completed (non-negative)
//! divergence, is reported alongside and can drive the stop rule instead.

use super::NbvError;
use crate::occupancy::{OccupancyGrid, probability};

/// Eq. (5) over a voxel set, with its positive and negative parts.
///
/// ```
/// use nbv_core::nbv::InformationGain;
/// use nbv_core::occupancy::log_odds;
/// // An unknown voxel seen free (p 0.5 → 0.3) and one seen occupied (0.5 → 0.7).
/// let g = InformationGain::from_log_odds([
///     (0.0, log_odds(0.3) as f32),
///     (0.0, log_odds(0.7) as f32),
/// ]);
/// assert!((g.freed - 0.5 * (0.5f64 / 0.3).ln()).abs() < 1e-6);
/// assert!((g.filled - 0.5 * (0.5f64 / 0.7).ln()).abs() < 1e-6);
/// assert!((g.total - (g.freed + g.filled)).abs() < 1e-15);
/// assert_eq!((g.voxels, g.changed), (2, 2));
/// ```
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct InformationGain {
    /// G of eq. (5).
    pub total: f64,
    /// Sum of the positive terms (voxels whose probability decreased).
    pub freed: f64,
    /// Sum of the negative terms (voxels whose probability increased).
    pub filled: f64,
    /// Voxels summed over (|O_v|).
    pub voxels: usize,
    /// Voxels whose probability changed.
    pub changed: usize,
    /// The completed form of the printed term, the Bernoulli Kullback–Leibler divergence
    /// `Σ p·ln(p/p') + (1−p)·ln((1−p)/(1−p'))` over the same voxels: never negative, 0
    /// only if nothing changed. Not the paper's G; reported for comparison and selectable
    /// in the [`StopRule`](super::StopRule).
    pub bernoulli_kl: f64,
}

impl InformationGain {
    /// G from `(o_before, o_after)` log-odds pairs, one per voxel of O_v.
    pub fn from_log_odds(pairs: impl IntoIterator<Item = (f32, f32)>) -> Self {
        let mut g = Self::default();
        for (before, after) in pairs {
            g.voxels += 1;
            if before == after {
                continue;
            }
            g.changed += 1;
            let p = probability(f64::from(before));
            let q = probability(f64::from(after));
            let term = -p * (q / p).ln();
            g.bernoulli_kl += term + (1.0 - p) * ((1.0 - p) / (1.0 - q)).ln();
            if term >= 0.0 {
                g.freed += term;
            } else {
                g.filled += term;
            }
        }
        g.total = g.freed + g.filled;
        g
    }

    /// G over the voxels `observed` (linear indices, e.g. [`VisibleVoxels::all`]) between
    /// the grid before the observation and the grid after it was updated with the acquired
    /// frame. Errors if the grids' lattices differ or an index is outside the grid.
    ///
    /// [`VisibleVoxels::all`]: super::VisibleVoxels::all
    pub fn between(
        before: &OccupancyGrid,
        after: &OccupancyGrid,
        observed: &[usize],
    ) -> Result<Self, NbvError> {
        if before.geometry() != after.geometry() {
            return Err(NbvError::GeometryMismatch);
        }
        let (a, b) = (before.log_odds(), after.log_odds());
        let mut pairs = Vec::with_capacity(observed.len());
        for &l in observed {
            match (a.get(l), b.get(l)) {
                (Some(&x), Some(&y)) => pairs.push((x, y)),
                _ => {
                    return Err(NbvError::VoxelOutOfRange {
                        linear: l,
                        len: a.len(),
                    });
                }
            }
        }
        Ok(Self::from_log_odds(pairs))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::occupancy::{GridGeometry, OccupancyParams, log_odds};
    use nalgebra::Point3;

    #[test]
    fn hand_computed_terms() {
        let params = OccupancyParams::default();
        let u = params.hit_log_odds();
        // Unknown seen free: 0.5·ln(0.5/0.3) = 0.255413; KL adds 0.5·ln(0.5/0.7).
        let g = InformationGain::from_log_odds([(0.0, -u)]);
        assert!((g.total - 0.255_412_811_882_995_3).abs() < 1e-7);
        assert!((g.bernoulli_kl - (0.255_412_811_882_995_3 - 0.168_236_118_310_606)).abs() < 1e-7);
        // Unknown seen occupied: 0.5·ln(0.5/0.7) = −0.168236.
        let g = InformationGain::from_log_odds([(0.0, u)]);
        assert!((g.total + 0.168_236_118_310_606).abs() < 1e-7);
        // Occupied (one hit) hit again: p 0.7 → 1/(1+(3/7)²) = 0.844828;
        // 0.7·ln(0.7/0.844828) = −0.131637.
        let g = InformationGain::from_log_odds([(u, 2.0 * u)]);
        let q = 1.0 / (1.0 + (3.0f64 / 7.0).powi(2));
        assert!((q - 0.844_827_586_206_896_6).abs() < 1e-12);
        assert!((g.total - 0.7 * (0.7 / q).ln()).abs() < 1e-6);
        assert!((g.total + 0.131_636_6).abs() < 1e-6);
        // Unchanged voxels count in `voxels` but add nothing.
        let g = InformationGain::from_log_odds([(0.0, 0.0), (1.0, 1.0), (0.0, -u)]);
        assert_eq!((g.voxels, g.changed), (3, 1));
        assert!((g.total - 0.255_412_8).abs() < 1e-6);
        assert_eq!(
            InformationGain::from_log_odds([]),
            InformationGain::default()
        );
    }

    #[test]
    fn between_grids() {
        let g = GridGeometry::from_dims(Point3::origin(), 0.1, [4, 1, 1]).unwrap();
        let p = OccupancyParams::default();
        let before = OccupancyGrid::from_log_odds(g, p, vec![0.0, 0.0, 0.0, 0.0]).unwrap();
        let mut after = before.clone();
        // A ray along x from outside hitting voxel 2: voxels 0, 1 free, 2 occupied.
        after
            .insert_rays(
                &[Point3::new(-0.5, 0.05, 0.05)],
                &[Point3::new(0.25, 0.05, 0.05)],
                5.0,
            )
            .unwrap();
        let gain = InformationGain::between(&before, &after, &[0, 1, 2, 3]).unwrap();
        let free = 0.5 * (0.5f64 / 0.3).ln();
        let occ = 0.5 * (0.5f64 / 0.7).ln();
        assert!((gain.freed - 2.0 * free).abs() < 1e-6);
        assert!((gain.filled - occ).abs() < 1e-6);
        assert!((gain.total - (2.0 * free + occ)).abs() < 1e-6);
        assert_eq!((gain.voxels, gain.changed), (4, 3));
        // Only the occupied voxel in O_v: negative gain.
        assert!(
            InformationGain::between(&before, &after, &[2])
                .unwrap()
                .total
                < 0.0
        );
        assert!(matches!(
            InformationGain::between(&before, &after, &[4]),
            Err(NbvError::VoxelOutOfRange { linear: 4, len: 4 })
        ));
        let other = OccupancyGrid::new(
            GridGeometry::from_dims(Point3::origin(), 0.1, [2, 2, 1]).unwrap(),
            p,
        )
        .unwrap();
        assert_eq!(
            InformationGain::between(&before, &other, &[0]),
            Err(NbvError::GeometryMismatch)
        );
        assert!((log_odds(0.5)).abs() < 1e-15);
    }
}
