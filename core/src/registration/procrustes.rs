//! Closed-form rigid Procrustes (Kabsch): the rotation and translation that best move one
//! set of points onto corresponding points in the least-squares sense, with the reflection
//! guard, so the result is always a proper rotation (det R = +1).
//!
//! With x̄, c̄ the means and H = Σ (x − x̄)(c − c̄)ᵀ = U S Vᵀ (singular values in descending
//! order): R = V · diag(1, 1, det(V Uᵀ)) · Uᵀ and t = c̄ − R x̄. Sums run sequentially in
//! index order, so the result is bit-for-bit reproducible.

use nalgebra::{Matrix3, Point3, Rotation3, Translation3, UnitQuaternion, Vector3};

use super::RegistrationError;
use crate::math::Pose;

/// Singular value ratio s₂/s₁ below which the correspondences count as collinear.
const DEGENERATE_RATIO: f64 = 1e-9;

/// The rigid transform `T` minimising Σ |T·source\[k\] − target\[k\]|².
///
/// Needs at least three pairs that are not collinear; equal lengths.
///
/// ```
/// use nbv_core::registration::rigid_procrustes;
/// use nalgebra::{Isometry3, Point3, Vector3};
/// let truth = Isometry3::new(Vector3::new(0.1, -0.2, 0.3), Vector3::new(0.2, 0.1, -0.4));
/// let src = [Point3::new(0.0, 0.0, 0.0), Point3::new(1.0, 0.0, 0.0),
///            Point3::new(0.0, 1.0, 0.0), Point3::new(0.0, 0.0, 1.0)];
/// let dst: Vec<_> = src.iter().map(|p| truth * p).collect();
/// let fit = rigid_procrustes(&src, &dst).unwrap();
/// assert!((fit.to_homogeneous() - truth.to_homogeneous()).norm() < 1e-12);
/// ```
pub fn rigid_procrustes(
    source: &[Point3<f64>],
    target: &[Point3<f64>],
) -> Result<Pose, RegistrationError> {
    if source.len() != target.len() {
        return Err(RegistrationError::CorrespondenceMismatch {
            sources: source.len(),
            targets: target.len(),
        });
    }
    fit_pairs(source.len(), |k| (source[k], target[k]))
}

/// [`rigid_procrustes`] over `n` pairs given by `pair(k)`, `k` in `0..n`.
pub(crate) fn fit_pairs(
    n: usize,
    pair: impl Fn(usize) -> (Point3<f64>, Point3<f64>),
) -> Result<Pose, RegistrationError> {
    if n == 0 {
        return Err(RegistrationError::TooFewCorrespondences(0));
    }
    let (x0, c0) = pair(0);
    let mut acc = CrossCovariance::new(x0, c0);
    for k in 0..n {
        let (x, c) = pair(k);
        acc.add(&x, &c);
    }
    acc.solve()
}

/// Running sums for a rigid fit, pair by pair or given whole (p-ICP-GPA's
/// [`SetMoments`](super::gpa::set_moments::SetMoments)). Coordinates are shifted by a fixed pair
/// (`x0`, `c0`) close to the data to keep the one-pass sums well conditioned.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct CrossCovariance {
    shift_x: Vector3<f64>,
    shift_c: Vector3<f64>,
    n: usize,
    sum_x: Vector3<f64>,
    sum_c: Vector3<f64>,
    /// Σ (x − x0)(c − c0)ᵀ.
    sum_xc: Matrix3<f64>,
}

impl CrossCovariance {
    /// Empty sums, shifted by `(x0, c0)`.
    pub(crate) fn new(x0: Point3<f64>, c0: Point3<f64>) -> Self {
        Self {
            shift_x: x0.coords,
            shift_c: c0.coords,
            n: 0,
            sum_x: Vector3::zeros(),
            sum_c: Vector3::zeros(),
            sum_xc: Matrix3::zeros(),
        }
    }

    /// Sums already made, shifted by `(x0, c0)`: `n` pairs, `Σ (x − x0)`, `Σ (c − c0)` and
    /// `Σ (x − x0)(c − c0)ᵀ`.
    pub(crate) fn from_sums(
        x0: Point3<f64>,
        c0: Point3<f64>,
        n: usize,
        sum_x: Vector3<f64>,
        sum_c: Vector3<f64>,
        sum_xc: Matrix3<f64>,
    ) -> Self {
        Self {
            shift_x: x0.coords,
            shift_c: c0.coords,
            n,
            sum_x,
            sum_c,
            sum_xc,
        }
    }

    /// Adds the pair: `x` should move onto `c`.
    pub(crate) fn add(&mut self, x: &Point3<f64>, c: &Point3<f64>) {
        let dx = x.coords - self.shift_x;
        let dc = c.coords - self.shift_c;
        self.n += 1;
        self.sum_x += dx;
        self.sum_c += dc;
        self.sum_xc += dx * dc.transpose();
    }

    /// The rigid transform minimising Σ |T x − c|² over the accumulated pairs.
    pub(crate) fn solve(&self) -> Result<Pose, RegistrationError> {
        if self.n < 3 {
            return Err(RegistrationError::TooFewCorrespondences(self.n));
        }
        let n = self.n as f64;
        let mean_x = self.sum_x / n;
        let mean_c = self.sum_c / n;
        let h = self.sum_xc - n * mean_x * mean_c.transpose();
        let rotation = rotation_from_covariance(&h)?;
        let t = (mean_c + self.shift_c) - rotation * (mean_x + self.shift_x);
        Ok(Pose::from_parts(
            Translation3::from(t),
            UnitQuaternion::from_rotation_matrix(&rotation),
        ))
    }
}

/// The proper rotation maximising tr(R H): R = V · diag(1, 1, det(V Uᵀ)) · Uᵀ.
fn rotation_from_covariance(h: &Matrix3<f64>) -> Result<Rotation3<f64>, RegistrationError> {
    if !h.iter().all(|v| v.is_finite()) {
        return Err(RegistrationError::DegenerateCorrespondences);
    }
    let svd = nalgebra::SVD::try_new(*h, true, true, f64::EPSILON, 0)
        .ok_or(RegistrationError::DegenerateCorrespondences)?;
    let (Some(u), Some(v_t)) = (svd.u, svd.v_t) else {
        return Err(RegistrationError::DegenerateCorrespondences);
    };
    let s = svd.singular_values;
    if s[0].partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater)
        || s[1] <= DEGENERATE_RATIO * s[0]
    {
        return Err(RegistrationError::DegenerateCorrespondences);
    }
    let v = v_t.transpose();
    let d = if (v * u.transpose()).determinant() < 0.0 {
        -1.0
    } else {
        1.0
    };
    let r = v * Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, d)) * u.transpose();
    Ok(Rotation3::from_matrix_unchecked(r))
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Isometry3;
    use proptest::prelude::*;

    fn point() -> impl Strategy<Value = Point3<f64>> {
        (-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0).prop_map(|(x, y, z)| Point3::new(x, y, z))
    }

    fn pose() -> impl Strategy<Value = Pose> {
        (
            prop::array::uniform3(-2.0f64..2.0),
            prop::array::uniform3(-3.0f64..3.0),
        )
            .prop_map(|(t, r)| Isometry3::new(Vector3::from(t), Vector3::from(r)))
    }

    fn spread(points: &[Point3<f64>]) -> bool {
        // Keep samples that are clearly not collinear: the second singular value of the
        // centred point matrix is not tiny.
        let n = points.len() as f64;
        let mean = points.iter().fold(Vector3::zeros(), |s, p| s + p.coords) / n;
        let mut c = Matrix3::zeros();
        for p in points {
            c += (p.coords - mean) * (p.coords - mean).transpose();
        }
        c.symmetric_eigenvalues()
            .iter()
            .filter(|&&e| e > 1e-3)
            .count()
            >= 2
    }

    proptest! {
        #[test]
        fn recovers_any_rigid_transform(truth in pose(),
                                        src in prop::collection::vec(point(), 3..40)) {
            prop_assume!(spread(&src));
            let dst: Vec<_> = src.iter().map(|p| truth * p).collect();
            let fit = rigid_procrustes(&src, &dst).unwrap();
            let err = (fit.to_homogeneous() - truth.to_homogeneous()).norm();
            prop_assert!(err < 1e-9, "error {err}");
        }

        #[test]
        fn always_a_proper_rotation(src in prop::collection::vec(point(), 3..30),
                                    dst in prop::collection::vec(point(), 30)) {
            prop_assume!(spread(&src));
            let dst = &dst[..src.len()];
            if let Ok(fit) = rigid_procrustes(&src, dst) {
                let r = fit.rotation.to_rotation_matrix().into_inner();
                prop_assert!((r.determinant() - 1.0).abs() < 1e-9);
                prop_assert!((r.transpose() * r - Matrix3::identity()).norm() < 1e-9);
            }
        }

        #[test]
        fn reflection_guard_on_mirrored_targets(src in prop::collection::vec(point(), 4..30)) {
            prop_assume!(spread(&src));
            // The best orthogonal fit to a mirror image is the mirror (det −1); the guard
            // must return a proper rotation instead.
            let dst: Vec<_> = src.iter().map(|p| Point3::new(p.x, p.y, -p.z)).collect();
            let fit = rigid_procrustes(&src, &dst).unwrap();
            let r = fit.rotation.to_rotation_matrix().into_inner();
            prop_assert!((r.determinant() - 1.0).abs() < 1e-9);
        }
    }

    #[test]
    fn planar_points_still_fit() {
        // Coplanar points give a rank-2 H: the guard picks the proper rotation.
        let truth = Isometry3::new(Vector3::new(0.5, 0.0, 0.1), Vector3::new(0.0, 0.3, 0.2));
        let src = [
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(1.0, 0.0, 0.0),
            Point3::new(0.0, 2.0, 0.0),
            Point3::new(1.0, 1.0, 0.0),
        ];
        let dst: Vec<_> = src.iter().map(|p| truth * p).collect();
        let fit = rigid_procrustes(&src, &dst).unwrap();
        assert!((fit.to_homogeneous() - truth.to_homogeneous()).norm() < 1e-12);
    }

    #[test]
    fn rejects_bad_input() {
        let p = [Point3::origin(), Point3::new(1.0, 0.0, 0.0)];
        assert_eq!(
            rigid_procrustes(&p, &p),
            Err(RegistrationError::TooFewCorrespondences(2))
        );
        assert_eq!(
            rigid_procrustes(&p, &p[..1]),
            Err(RegistrationError::CorrespondenceMismatch {
                sources: 2,
                targets: 1
            })
        );
        let line: Vec<_> = (0..5).map(|i| Point3::new(i as f64, 0.0, 0.0)).collect();
        assert_eq!(
            rigid_procrustes(&line, &line),
            Err(RegistrationError::DegenerateCorrespondences)
        );
        let same = vec![Point3::new(1.0, 2.0, 3.0); 4];
        assert_eq!(
            rigid_procrustes(&same, &same),
            Err(RegistrationError::DegenerateCorrespondences)
        );
    }
}
