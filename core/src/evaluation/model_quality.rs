//! [`model_quality`]: a model cloud against the true surface at a stated tolerance τ, by
//! the protocol of Tanks and Temples (Knapitsch et al., SIGGRAPH 2017) — precision,
//! completeness and their F-score — plus the Chamfer distance.
//!
//! - **Precision**: the share of the model's (finite) points within τ of the true surface.
//! - **Completeness** (recall): the share of the true surface above a floor (the table
//!   hides what is below) within τ of a model point — the measure of
//!   [`surface_coverage`](super::surface_coverage), on the same samples.
//! - **F-score**: `2·P·C / (P + C)`, 0 when both are 0. A misaligned model touches more
//!   of the surface (completeness rises) but its points leave it (precision falls); the
//!   harmonic mean is never above the larger of the two and is pulled towards the smaller,
//!   so smearing the views cannot raise it the way it raises coverage.
//! - **Chamfer distance** (metres): the mean of the two directed mean nearest distances,
//!   `½·(mean over model points of the distance to the surface + mean over the surface
//!   samples above the floor of the distance to the model)`. It has no tolerance: it grows
//!   with how far wrong points are, where precision only counts them.
//!
//! The true surface is represented by `samples` seeded area-weighted samples
//! ([`sample_surface`]): the distance of a model point to the surface is its distance to
//! the nearest sample. A sample lies on the surface, so this never underestimates: a point
//! counted within τ is within τ; a point whose foot on the surface is δ from the nearest
//! sample is measured at most δ too far. For `n` uniform samples on area `A` the distance
//! from a surface point to the nearest sample is ½·√(A/n) on average and √(ln 100/π)·√(A/n)
//! ≈ 1.2·√(A/n) at the 99th percentile (planar Poisson points); [`quality_samples`] takes
//! the samples τ/10 apart, so only points within ~0.12·τ outside the tolerance can be
//! misjudged, and the Chamfer distance is at most about τ/20 too large (less for points
//! off the surface: √(d² + δ²) − d). Completeness is exact for the samples.

use crate::cloud::{PointCloud, nearest_distances};
use crate::mesh::TriMesh;
use nalgebra::Point3;
use serde::Serialize;

use super::sample_surface;

/// The result of [`model_quality`]; shares in `[0, 1]`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ModelQuality {
    /// The tolerance τ (m).
    pub tolerance: f64,
    /// Share of the model's points within τ of the true surface.
    pub precision: f64,
    /// Share of the true surface above the floor within τ of a model point (the coverage).
    pub completeness: f64,
    /// `2·P·C / (P + C)` ([`f_score`]).
    pub f_score: f64,
    /// Mean of the two directed mean nearest distances, model → surface and surface (above
    /// the floor) → model (m).
    pub chamfer: f64,
}

/// The F-score of a precision and a recall: their harmonic mean, 0 when both are 0.
///
/// ```
/// use nbv_core::evaluation::f_score;
/// assert_eq!(f_score(1.0, 1.0), 1.0);
/// assert_eq!(f_score(0.0, 0.0), 0.0);
/// assert!((f_score(0.5, 1.0) - 2.0 / 3.0).abs() < 1e-15);
/// ```
pub fn f_score(precision: f64, recall: f64) -> f64 {
    let sum = precision + recall;
    if sum > 0.0 {
        2.0 * precision * recall / sum
    } else {
        0.0
    }
}

/// Surface samples for [`model_quality`] on `mesh` at `tolerance`: one per (τ/10)² of area
/// (samples τ/10 apart; see the module doc), at least 1,000 and at most 2,000,000. For
/// τ = 1 cm that is 10⁶ per m²: 100,000 on an object of 0.1 m².
///
/// ```
/// use nbv_core::evaluation::quality_samples;
/// use nbv_core::mesh::TriMesh;
/// // A 10 cm cube: 0.06 m².
/// assert_eq!(quality_samples(&TriMesh::cuboid([0.05; 3]), 0.01), 60_000);
/// ```
pub fn quality_samples(mesh: &TriMesh, tolerance: f64) -> usize {
    let spacing = tolerance / 10.0;
    let n = (mesh.area() / (spacing * spacing)).round();
    if n.is_nan() {
        return 1_000;
    }
    (n as usize).clamp(1_000, 2_000_000)
}

/// `model` (world frame) against `surface` at tolerance `tolerance`: of `samples`
/// area-weighted samples of the surface (seeded: the same seed gives the same figures),
/// all stand for the surface in the model → surface direction (precision, its half of the
/// Chamfer distance), those with `z > floor` in the surface → model direction
/// (completeness, the other half). `None` for a model without a finite point, or a surface
/// without a sample above the floor.
///
/// ```
/// use nbv_core::cloud::PointCloud;
/// use nbv_core::evaluation::{model_quality, sample_surface};
/// use nbv_core::mesh::TriMesh;
/// use nalgebra::Point3;
/// let cube = TriMesh::cuboid([0.05, 0.05, 0.05]);
/// // The very samples the quality is measured against: a perfect model.
/// let mut points = sample_surface(&cube, 6_000, 2);
/// let q = model_quality(&cube, &PointCloud::from_points(points.clone()), 0.01, f64::MIN, 6_000, 2)
///     .unwrap();
/// assert_eq!((q.precision, q.completeness, q.f_score, q.chamfer), (1.0, 1.0, 1.0, 0.0));
/// // 2,000 more at the cube's centre, 5 cm from every face: precision 3/4, completeness
/// // unchanged, F = 6/7; the model → surface mean is 1/4 of 5 cm, the Chamfer half that.
/// points.extend(std::iter::repeat_n(Point3::origin(), 2_000));
/// let q = model_quality(&cube, &PointCloud::from_points(points), 0.01, f64::MIN, 6_000, 2)
///     .unwrap();
/// assert_eq!((q.precision, q.completeness), (0.75, 1.0));
/// assert!((q.f_score - 6.0 / 7.0).abs() < 1e-12);
/// assert!((q.chamfer - 0.05 / 8.0).abs() < 2e-4, "{}", q.chamfer);
/// ```
pub fn model_quality(
    surface: &TriMesh,
    model: &PointCloud,
    tolerance: f64,
    floor: f64,
    samples: usize,
    seed: u64,
) -> Option<ModelQuality> {
    let all = sample_surface(surface, samples, seed);
    let above: Vec<Point3<f64>> = all.iter().filter(|p| p.z > floor).copied().collect();
    let finite: Vec<Point3<f64>> = model
        .points
        .iter()
        .filter(|p| p.iter().all(|c| c.is_finite()))
        .copied()
        .collect();
    if above.is_empty() || finite.is_empty() {
        return None;
    }
    let to_surface = nearest_distances(&all, &finite);
    let to_model = nearest_distances(&finite, &above);
    let share = |d: &[f64]| d.iter().filter(|&&d| d <= tolerance).count() as f64 / d.len() as f64;
    let mean = |d: &[f64]| d.iter().sum::<f64>() / d.len() as f64;
    let (precision, completeness) = (share(&to_surface), share(&to_model));
    Some(ModelQuality {
        tolerance,
        precision,
        completeness,
        f_score: f_score(precision, completeness),
        chamfer: 0.5 * (mean(&to_surface) + mean(&to_model)),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::evaluation::surface_coverage;
    use nalgebra::{Translation3, Vector3};
    use proptest::prelude::*;

    const TAU: f64 = 0.01;

    /// A 10 cm cube, and a model of it sampled with another seed than the evaluation's.
    fn cube_and_model(n: usize, seed: u64) -> (TriMesh, Vec<Point3<f64>>) {
        let cube = TriMesh::cuboid([0.05; 3]);
        let model = sample_surface(&cube, n, seed);
        (cube, model)
    }

    fn quality(cube: &TriMesh, points: Vec<Point3<f64>>, samples: usize) -> ModelQuality {
        model_quality(
            cube,
            &PointCloud::from_points(points),
            TAU,
            f64::MIN,
            samples,
            7,
        )
        .unwrap()
    }

    /// The cube's model shifted 2 cm along x, against the cube, by hand: points of the
    /// four side faces slide in their plane, those pushed past the +x edge by e lie e from
    /// the surface (beyond τ for a tenth of each face); the +x face stands 2 cm out (none
    /// within τ); the −x face moves 2 cm in, where a point lies min(2 cm, its distances to
    /// the side faces) from the surface: within τ on the 1 cm rim, 1 − 0.8² = 0.36 of it.
    /// Precision (4·0.9 + 0.36)/6 = 0.66, and completeness the same (the cube is symmetric
    /// under x → −x); F = 0.66. Model → surface mean: side faces 4/6 · (0.2 · 1 cm), +x face
    /// 1/6 · 2 cm, −x face 1/6 · ∫₀^2cm (1 − s/5cm)² ds = 1/6 · 1.30667 cm; 6.844 mm in
    /// all, and the same surface → model: Chamfer 6.844 mm.
    #[test]
    fn shifted_cube_by_hand() {
        let (cube, model) = cube_and_model(30_000, 1);
        let samples = quality_samples(&cube, TAU);
        let exact = quality(&cube, model.clone(), samples);
        assert!(
            exact.precision > 0.999 && exact.completeness > 0.999,
            "{exact:?}"
        );
        assert!(exact.chamfer < 1e-3, "{exact:?}");
        let shift = Translation3::new(0.02, 0.0, 0.0);
        let shifted: Vec<_> = model.iter().map(|p| shift * p).collect();
        let q = quality(&cube, shifted, samples);
        assert!((q.precision - 0.66).abs() < 0.01, "{q:?}");
        assert!((q.completeness - 0.66).abs() < 0.01, "{q:?}");
        assert!((q.f_score - 0.66).abs() < 0.01, "{q:?}");
        // Measured against samples, a distance is never short and comes out long by less
        // than for the perfect model (whose points all lie on the surface): 7.19 mm.
        let bias = q.chamfer - 6.844e-3;
        assert!(bias >= 0.0 && bias < exact.chamfer, "{q:?}");
    }

    /// Completeness is the coverage: the same samples, the same floor, the same count.
    #[test]
    fn completeness_is_the_coverage() {
        let (cube, model) = cube_and_model(2_000, 4);
        let top: Vec<_> = model.into_iter().filter(|p| p.x > 0.0).collect();
        let cloud = PointCloud::from_points(top);
        let q = model_quality(&cube, &cloud, TAU, -0.03, 20_000, 5).unwrap();
        let c = surface_coverage(&cube, &cloud, TAU, -0.03, 20_000, 5);
        assert_eq!(q.completeness, c.share());
        assert_eq!(q.precision, 1.0);
    }

    #[test]
    fn nothing_to_measure() {
        let cube = TriMesh::cuboid([0.05; 3]);
        let nan = PointCloud::from_points(vec![Point3::new(f64::NAN, 0.0, 0.0)]);
        assert!(model_quality(&cube, &nan, TAU, f64::MIN, 1_000, 1).is_none());
        let one = PointCloud::from_points(vec![Point3::origin()]);
        // Nothing of the cube above z = 1.
        assert!(model_quality(&cube, &one, TAU, 1.0, 1_000, 1).is_none());
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]

        /// The harmonic mean lies between the two shares, below their mean, and is 0 when
        /// either is.
        #[test]
        fn f_between_precision_and_recall(p in 0.0f64..=1.0, r in 0.0f64..=1.0) {
            let f = f_score(p, r);
            prop_assert!(f >= p.min(r) - 1e-15 && f <= p.max(r) + 1e-15);
            prop_assert!(f <= (p + r) / 2.0 + 1e-15);
            prop_assert_eq!(f, f_score(r, p));
            if p == 0.0 || r == 0.0 {
                prop_assert_eq!(f, 0.0);
            }
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(12))]

        /// Points farther than τ from the surface (outside the cube's box grown by 2τ)
        /// never raise precision or F, and leave completeness as it was.
        #[test]
        fn far_points_never_help(
            keep in 100usize..2_000,
            far in prop::collection::vec((-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0), 1..200),
        ) {
            let (cube, mut model) = cube_and_model(keep, 3);
            let before = quality(&cube, model.clone(), 6_000);
            model.extend(far.into_iter().map(|(x, y, z)| {
                let v = Vector3::new(x, y, z);
                let v = if v.amax() < 1e-6 { Vector3::x() } else { v };
                // Pushed out to at least 0.05 + 2τ along its largest coordinate.
                Point3::from(v * ((0.05 + 2.0 * TAU) / v.amax()).max(1.0))
            }));
            let after = quality(&cube, model, 6_000);
            prop_assert!(after.precision <= before.precision);
            prop_assert!(after.f_score <= before.f_score);
            prop_assert_eq!(after.completeness, before.completeness);
        }

        /// A perfect sampled model moved rigidly by 2τ or more (so a pair of faces moves
        /// more than τ along its normal: one coordinate is at least 2τ/√3) has a lower F.
        #[test]
        fn misalignment_lowers_f(
            theta in 0.0f64..std::f64::consts::PI,
            phi in -std::f64::consts::PI..std::f64::consts::PI,
            size in 2.0f64..5.0,
        ) {
            let (cube, model) = cube_and_model(3_000, 5);
            let perfect = quality(&cube, model.clone(), 6_000);
            let t = Vector3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos())
                * (size * TAU);
            let moved = quality(&cube, model.iter().map(|p| p + t).collect(), 6_000);
            prop_assert!(moved.f_score < perfect.f_score - 0.05, "{:?} -> {:?}", perfect, moved);
            prop_assert!(moved.chamfer > perfect.chamfer);
        }
    }
}
