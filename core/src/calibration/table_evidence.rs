//! [`TableEvidence`]: what the table around an object tells about a camera view's pose.
//!
//! The laser sweep measures the table top over a metre to a fraction of a millimetre, and
//! every close-up view of an object sees the table around it: thousands of points whose
//! only error is the camera's range noise along their rays. Where they fall off the plane
//! fixes three of the view's six pose directions — the height along the plane's normal
//! and the two tilts — and, the table being flat, free of the bias the camera's noise
//! leaves on a curved object (a noisy point on a convex surface lies outside it on
//! average, by `σ²·sin²θ / 2R`). The views look at the table from many directions, so
//! together they see every direction of the camera's mount: the self-calibration
//! ([`estimate_hand_eye`](super::estimate_hand_eye)) adds this evidence to each view's
//! registration.
//!
//! A point `p` seen from `o` at range `d` is off the plane `n·x + c = 0` by
//! `r = n·p + c`; a world-frame correction `ξ = (ω, t)` about `o` moves it to
//! `r + ((p − o) × n)·ω + n·t`. Its noise along the normal is the range noise times
//! `|n·u|` (`u` the ray). The correction is the robust (Tukey's biweight) weighted least-squares
//! solution over the points whose ray goes down onto the plane, started with a wide scale
//! that shrinks to the noise's, so a view reported centimetres off still finds its table.

use super::hand_eye::{correction_of, correction_pose};
use crate::cloud::PlaneFit;
use crate::math::Pose;
use crate::registration::RangeNoise;
use nalgebra::{Matrix6, Point3, Vector3, Vector6};

/// Rays closer to the plane than this cosine of incidence do not count (the table seen
/// edge-on: its points are few and the noise along the normal is hardly smaller than the
/// rays' own reach over the object's foot).
const MIN_INCIDENCE_COS: f64 = 0.3;
/// Points farther off the plane at the reported pose (m) are not the table's: beyond what
/// five times the scenes' pose errors move a view's table.
const GATE: f64 = 0.05;
/// Tukey's biweight scale in units of a point's σ (95 % efficiency under Gaussian noise;
/// a point farther off has no weight).
const TUKEY: f64 = 4.685;
/// Scale (m) of the first reweighting round (the gate's); each round halves it down to
/// the noise's.
const START_SCALE: f64 = GATE;
/// Reweighting rounds at most.
const ROUNDS: usize = 12;
/// The round after which the scale (halved from the gate's 5 cm) lies below every
/// point's noise floor (`4.685σ`), so the weights no longer shrink with it.
const SETTLED_ROUND: usize = 4;
/// A step (rad, m) below which the fit has converged.
const STEP_TOLERANCE: f64 = 1e-9;
/// Points a view's fit uses at most (an even subset of its table's).
const MAX_POINTS: usize = 8192;
/// Fewest points that make the evidence.
const MIN_POINTS: usize = 50;

/// Three of a camera view's pose directions, as the table plane determines them.
///
/// ```
/// use nbv_core::cloud::PlaneFit;
/// use nbv_core::calibration::TableEvidence;
/// use nbv_core::registration::RangeNoise;
/// use nalgebra::{Point3, Unit, Vector3};
/// // The table z = 0; the camera 0.4 m above it, its view 3 mm too high.
/// let table = PlaneFit { normal: Unit::new_normalize(Vector3::z()), offset: 0.0, inliers: vec![], rms: 0.0 };
/// let o = Point3::new(0.0, 0.0, 0.4);
/// let points: Vec<_> = (0..400)
///     .map(|k| Point3::new((k % 20) as f64 * 0.01 - 0.1, (k / 20) as f64 * 0.01 - 0.1, 0.003))
///     .collect();
/// let noise = RangeNoise { sigma_at_1m: 0.014, exponent: 1.0 };
/// let e = TableEvidence::of_view(&points, &o, &table, noise, 1.0, |_| true).unwrap();
/// assert!((e.correction[5] + 0.003).abs() < 1e-9); // 3 mm down
/// assert_eq!(e.points, 400);
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct TableEvidence {
    /// Information of the world-frame correction `ξ = (ω, t)` about the sensor origin
    /// (rank 3: the height and the two tilts).
    pub information: Matrix6<f64>,
    /// The correction that puts the view's table points on the plane, of least norm (zero
    /// along the directions the plane leaves free).
    pub correction: Vector6<f64>,
    /// Points that count as the table's (within 4.685σ of the plane the correction puts them on).
    pub points: usize,
}

impl TableEvidence {
    /// The evidence of a view's `points` (world frame, at the reported pose) seen from
    /// `origin`, with the world's table `plane` and the view's range `noise`. A point
    /// counts when its ray meets the plane nearer than `max_range` and `keep` accepts the
    /// point where it meets it: the caller leaves out the object's footprint, the known
    /// obstacles, and the ranges where the camera's range limit cuts a frame's noise on
    /// one side. Both tests read where the ray meets the plane, not the noisy point, so
    /// they select no noise: a cut at the measured point (an object's region whose floor
    /// lies a centimetre above the table) keeps the points the noise put low and drops
    /// those it put high. `None` with fewer than 50 table points or a degenerate fit.
    pub fn of_view(
        points: &[Point3<f64>],
        origin: &Point3<f64>,
        plane: &PlaneFit,
        noise: RangeNoise,
        max_range: f64,
        keep: impl Fn(&Point3<f64>) -> bool,
    ) -> Option<Self> {
        let n = plane.normal.into_inner();
        let table: Vec<Point3<f64>> = points
            .iter()
            .filter(|p| {
                Row::of(p, origin, &n, plane.offset, noise).is_some_and(|row| {
                    row.residual.abs() <= GATE
                        && row.plane_range < max_range
                        && keep(&(origin + (*p - origin).normalize() * row.plane_range))
                })
            })
            .copied()
            .collect();
        if table.len() < MIN_POINTS {
            return None;
        }
        // An even subset: beyond a few thousand points the view's table is far more precise
        // than its standstill (0.02° against 0.1°), which caps its weight anyway.
        let stride = table.len().div_ceil(MAX_POINTS);
        let table: Vec<Point3<f64>> = table.into_iter().step_by(stride).collect();
        // Gauss–Newton on the pose: each round's rows at the points as corrected so far.
        let rows_at = |c: &Pose| -> (Point3<f64>, Vec<Row>) {
            let o = c * origin;
            let rows = table
                .iter()
                .filter_map(|p| Row::of(&(c * p), &o, &n, plane.offset, noise))
                .collect();
            (o, rows)
        };
        let mut corrected = Pose::identity();
        let mut scale = START_SCALE;
        for round in 0..ROUNDS {
            let (o, rows) = rows_at(&corrected);
            let (h, g, _) = normal_equations(&rows, scale);
            let step = -(pseudo_inverse(&h)? * g);
            corrected = correction_pose(&step, &o) * corrected;
            scale *= 0.5;
            // Once the scale is the noise's, a step this small ends it.
            if round >= SETTLED_ROUND && step.amax() < STEP_TOLERANCE {
                break;
            }
        }
        let (_, rows) = rows_at(&corrected);
        let (information, _, counted) = normal_equations(&rows, 0.0);
        let correction = correction_of(&corrected, origin);
        (counted >= MIN_POINTS && correction.iter().all(|v| v.is_finite())).then_some(Self {
            information,
            correction,
            points: counted,
        })
    }
}

/// One table point's residual row.
struct Row {
    jacobian: Vector6<f64>,
    residual: f64,
    sigma: f64,
    /// Where the point's ray meets the plane: its range without noise.
    plane_range: f64,
}

impl Row {
    /// The row of `p` seen from `o`, or `None` when its ray does not go down onto the
    /// plane `n·x + c = 0` steeply enough. Only the residual reads the noisy point: the
    /// noise and the lever are those of the range where the ray meets the plane. Weights
    /// that grow as the noise brings a point nearer would pull the fit towards the camera
    /// (by `2σ²/d`, 0.2 mm at 0.5 m).
    fn of(
        p: &Point3<f64>,
        o: &Point3<f64>,
        n: &Vector3<f64>,
        c: f64,
        noise: RangeNoise,
    ) -> Option<Self> {
        let ray = p - o;
        let cos = -n.dot(&ray) / ray.norm();
        if cos.is_nan() || cos < MIN_INCIDENCE_COS {
            return None;
        }
        let plane_range = (n.dot(&o.coords) + c) / cos;
        // The lever of the turn from where the ray meets the plane: the noisy point's own
        // would grow with the noise that also makes its residual, and the two together
        // turn the fit towards the camera's viewing direction (by ~σ²/d², 0.03° here).
        let lever = (ray * (plane_range / ray.norm())).cross(n);
        Some(Self {
            jacobian: Vector6::new(lever.x, lever.y, lever.z, n.x, n.y, n.z),
            residual: n.dot(&p.coords) + c,
            sigma: noise.sigma(plane_range.max(0.0)) * cos,
            plane_range,
        })
    }
}

/// `H = Σ w·J·Jᵀ/σ²` and `g = Σ w·J·r/σ²`, with Tukey's biweight at `max(scale, 4.685σ)`,
/// and the count of rows inside the kernel.
fn normal_equations(rows: &[Row], scale: f64) -> (Matrix6<f64>, Vector6<f64>, usize) {
    let mut h = Matrix6::zeros();
    let mut g = Vector6::zeros();
    let mut counted = 0;
    for row in rows {
        let r = row.residual;
        let s = scale.max(TUKEY * row.sigma);
        let x = r / s;
        if x.abs() >= 1.0 {
            continue;
        }
        counted += 1;
        let w = (1.0 - x * x).powi(2);
        let k = w / (row.sigma * row.sigma);
        h.ger(k, &row.jacobian, &row.jacobian, 1.0);
        g += row.jacobian * (k * r);
    }
    (h, g, counted)
}

/// The pseudo-inverse of a symmetric positive semi-definite `h` (its null space: the
/// directions the table leaves free).
fn pseudo_inverse(h: &Matrix6<f64>) -> Option<Matrix6<f64>> {
    let eps = 1e-9 * h.norm();
    (eps.is_finite() && eps > 0.0)
        .then(|| h.pseudo_inverse(eps).ok())
        .flatten()
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Unit;
    use proptest::prelude::*;
    use rand::{Rng, SeedableRng};
    use rand_distr::StandardNormal;

    fn table() -> PlaneFit {
        PlaneFit {
            normal: Unit::new_normalize(Vector3::z()),
            offset: -0.2,
            inliers: vec![],
            rms: 0.0,
        }
    }

    /// Where the camera is reported to be.
    const ORIGIN: Point3<f64> = Point3::new(0.35, 0.1, 0.6);

    /// The table points a camera sees on a grid of rays, reported through a pose off by
    /// the correction `xi` (true = `correction_pose(xi, ORIGIN)` · reported), with
    /// Gaussian range noise `sigma_at_1m` times the range.
    fn view(xi: &Vector6<f64>, sigma_at_1m: f64, seed: u64) -> Vec<Point3<f64>> {
        let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
        let truth = correction_pose(xi, &ORIGIN);
        let o = truth * ORIGIN;
        let mut out = Vec::new();
        for i in 0..60 {
            for j in 0..60 {
                let target = Point3::new(
                    0.5 + (f64::from(i) - 30.0) * 0.006,
                    (f64::from(j) - 30.0) * 0.006,
                    0.2,
                );
                let u = (target - o).normalize();
                let d = (0.2 - o.z) / u.z;
                let noisy = d + sigma_at_1m * d * rng.sample::<f64, _>(StandardNormal);
                out.push(truth.inverse() * (o + u * noisy));
            }
        }
        out
    }

    /// The evidence of `points` seen from [`ORIGIN`], every table point counting.
    fn fit(points: &[Point3<f64>]) -> Option<TableEvidence> {
        TableEvidence::of_view(points, &ORIGIN, &table(), noise(), 1.0, |_| true)
    }

    fn noise() -> RangeNoise {
        RangeNoise {
            sigma_at_1m: 0.014,
            exponent: 1.0,
        }
    }

    /// σ of the fixed directions ω_x, ω_y and t_z (the plane's normal is z) by the
    /// evidence's own information.
    fn sigmas(e: &TableEvidence) -> [f64; 3] {
        let cov = e
            .information
            .pseudo_inverse(1e-12 * e.information.norm())
            .unwrap();
        [0, 1, 5].map(|k| cov[(k, k)].sqrt())
    }

    #[test]
    fn the_plane_fixes_three_directions_within_its_sigma_and_leaves_the_others_at_zero() {
        let xi = Vector6::new(0.004, -0.003, 0.01, 0.002, -0.003, 0.004);
        for seed in 0..4 {
            let e = fit(&view(&xi, 0.014, seed)).unwrap();
            let sigma = sigmas(&e);
            // 6 mm of range noise, 3600 points: ~1 mrad of tilt per view, ~0.4 mm of height.
            assert!(sigma[0] < 2e-3 && sigma[2] < 1e-3, "{sigma:?}");
            for (k, s) in [0, 1, 5].into_iter().zip(sigma) {
                assert!(
                    (e.correction[k] - xi[k]).abs() < 4.0 * s,
                    "{k}: {} {s}",
                    e.correction
                );
            }
            // The free directions (about the normal, along the plane) stay at zero.
            for k in [2, 3, 4] {
                assert!(e.correction[k].abs() < 1e-5, "{}", e.correction);
            }
            let eig = e.information.symmetric_eigenvalues();
            assert_eq!(eig.iter().filter(|v| **v > 1e-9 * eig.max()).count(), 3);
            assert!(e.points > 3500, "{}", e.points);
        }
    }

    /// The mean over many noisy views is the truth: neither the noise's reach into the
    /// lever nor weights read from the noisy range bias the fit (the camera looks at the
    /// table obliquely, where both would turn it towards its viewing direction).
    #[test]
    fn the_fit_is_unbiased_over_many_noisy_views() {
        let xi = Vector6::new(0.002, -0.001, 0.0, 0.0, 0.0, 0.003);
        let n = 48;
        let mut mean = Vector6::zeros();
        let mut sigma = [0.0; 3];
        for seed in 0..n {
            let e = fit(&view(&xi, 0.014, 100 + seed)).unwrap();
            mean += (e.correction - xi) / n as f64;
            sigma = sigmas(&e);
        }
        for (k, s) in [0, 1, 5].into_iter().zip(sigma) {
            // Three σ of the mean of 48.
            assert!(
                mean[k].abs() < 3.0 * s / (n as f64).sqrt(),
                "{k}: {} against σ {s}",
                mean[k]
            );
        }
    }

    #[test]
    fn an_objects_foot_in_a_corner_of_the_view_does_not_pull_it() {
        let xi = Vector6::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.005);
        let mut points = view(&xi, 0.014, 2);
        // Something's lowest 4 cm standing in a tenth of the view (its first six rows).
        for p in points.iter_mut().take(360) {
            p.z += 0.04;
        }
        let table_only = fit(&points[360..]).unwrap();
        let e = fit(&points).unwrap();
        let sigma = sigmas(&table_only);
        for (k, s) in [0, 1, 5].into_iter().zip(sigma) {
            let moved = (e.correction[k] - table_only.correction[k]).abs();
            assert!(moved < 0.05 * s, "{k}: {moved} against σ {s}");
        }
        // Of the raised points only those the noise brought within the kernel count.
        assert!((table_only.points..table_only.points + 8).contains(&e.points));
    }

    #[test]
    fn too_few_table_points_give_no_evidence() {
        let points = view(&Vector6::zeros(), 0.0, 3);
        assert!(fit(&points[..49]).is_none());
        assert!(fit(&points[..60]).is_some());
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(24))]
        /// Without noise, any reported offset within the gate is undone exactly along the
        /// three directions the plane fixes: the corrected points lie on the table.
        #[test]
        fn a_noise_free_view_is_put_back_on_the_table(
            wx in -0.02f64..0.02, wy in -0.02f64..0.02, wz in -0.05f64..0.05,
            tx in -0.01f64..0.01, ty in -0.01f64..0.01, tz in -0.01f64..0.01,
        ) {
            let xi = Vector6::new(wx, wy, wz, tx, ty, tz);
            let points = view(&xi, 0.0, 4);
            let e = fit(&points).unwrap();
            let back = correction_pose(&e.correction, &ORIGIN);
            let off = points.iter().map(|p| table().signed_distance(&(back * p)).abs()).fold(0.0, f64::max);
            prop_assert!(off < 1e-9, "{}", off);
            prop_assert_eq!(e.points, 3600);
        }
    }
}
