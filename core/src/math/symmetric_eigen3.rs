//! [`symmetric_eigen3`]: the eigen-decomposition of a symmetric 3×3 matrix by cyclic
//! Jacobi rotations — what a point neighbourhood's covariance needs (its normal, its
//! spread along each axis), in a few hundred operations instead of a general
//! tridiagonal QR's thousands.
//!
//! Each rotation zeroes one off-diagonal entry (Golub & Van Loan, "Matrix Computations",
//! §8.5, the symmetric Schur decomposition); sweeps over the three entries repeat until
//! every off-diagonal entry is negligible against its two diagonal entries. Jacobi
//! computes the small eigenvalues of a positive semi-definite matrix to high relative
//! accuracy (Demmel & Veselić, 1992): the thickness of a nearly flat neighbourhood is
//! not lost in the rounding of its extent.

use nalgebra::{Matrix3, Vector3};

/// Sweeps after which the iteration stops (3–6 suffice in practice).
const MAX_SWEEPS: usize = 32;

/// The eigenvalues of the symmetric matrix `m` (its lower triangle is ignored) and
/// their unit eigenvectors as the columns of an orthogonal matrix, in no particular
/// order: `m ≈ V·diag(λ)·Vᵀ`.
///
/// ```
/// use nalgebra::{Matrix3, Vector3};
/// use nbv_core::math::symmetric_eigen3;
/// let m = Matrix3::new(2.0, 1.0, 0.0, 1.0, 2.0, 0.0, 0.0, 0.0, 5.0);
/// let (values, vectors) = symmetric_eigen3(&m);
/// let mut sorted = [values[0], values[1], values[2]];
/// sorted.sort_by(f64::total_cmp);
/// assert!((sorted[0] - 1.0).abs() < 1e-12 && (sorted[2] - 5.0).abs() < 1e-12);
/// let back = vectors * Matrix3::from_diagonal(&values) * vectors.transpose();
/// assert!((back - m).norm() < 1e-12);
/// ```
pub fn symmetric_eigen3(m: &Matrix3<f64>) -> (Vector3<f64>, Matrix3<f64>) {
    // The diagonal and the upper triangle.
    let mut d = [m[(0, 0)], m[(1, 1)], m[(2, 2)]];
    // off[r] is the entry off the diagonal in the row and column that are not r:
    // off[0] = m₁₂, off[1] = m₀₂, off[2] = m₀₁.
    let mut off = [m[(1, 2)], m[(0, 2)], m[(0, 1)]];
    let mut v = Matrix3::identity();
    for _ in 0..MAX_SWEEPS {
        let mut rotated = false;
        // The pairs (p, q) and the third index r.
        for (p, q, r) in [(0, 1, 2), (0, 2, 1), (1, 2, 0)] {
            let apq = off[r];
            let (app, aqq) = (d[p], d[q]);
            // Negligible against both diagonal entries (relative accuracy), or zero.
            if apq == 0.0 || apq.abs() <= f64::EPSILON * 0.5 * (app * aqq).abs().sqrt() {
                continue;
            }
            rotated = true;
            // The rotation that zeroes the (p, q) entry: t = tan θ, the smaller root.
            let theta = (aqq - app) / (2.0 * apq);
            let t = if theta.abs() > 1e150 {
                0.5 / theta
            } else {
                theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt())
            };
            let c = 1.0 / (t * t + 1.0).sqrt();
            let s = t * c;
            // Jᵀ·a·J: the (p, q) entry vanishes, the diagonal takes ∓t·a_pq, and the
            // entries (r, p) and (r, q) turn by the rotation.
            d[p] = app - t * apq;
            d[q] = aqq + t * apq;
            off[r] = 0.0;
            let (arp, arq) = (off[q], off[p]);
            off[q] = c * arp - s * arq;
            off[p] = s * arp + c * arq;
            for k in 0..3 {
                let (vkp, vkq) = (v[(k, p)], v[(k, q)]);
                v[(k, p)] = c * vkp - s * vkq;
                v[(k, q)] = s * vkp + c * vkq;
            }
        }
        if !rotated {
            break;
        }
    }
    (Vector3::from(d), v)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn check(m: &Matrix3<f64>) -> Result<(), TestCaseError> {
        let (values, vectors) = symmetric_eigen3(m);
        let scale = m.norm().max(f64::MIN_POSITIVE);
        // Orthonormal vectors, and V·Λ·Vᵀ = m.
        prop_assert!((vectors.transpose() * vectors - Matrix3::identity()).norm() < 1e-13);
        let back = vectors * Matrix3::from_diagonal(&values) * vectors.transpose();
        prop_assert!((back - m).norm() <= 1e-13 * scale, "{} vs {}", back, m);
        // The same eigenvalues as nalgebra's QR.
        let mut ours = [values[0], values[1], values[2]];
        ours.sort_by(f64::total_cmp);
        let reference = m.symmetric_eigenvalues();
        let mut theirs = [reference[0], reference[1], reference[2]];
        theirs.sort_by(f64::total_cmp);
        for (a, b) in ours.iter().zip(&theirs) {
            prop_assert!((a - b).abs() <= 1e-13 * scale, "{:?} vs {:?}", ours, theirs);
        }
        // Each column an eigenvector: m·v = λ·v.
        for c in 0..3 {
            let col = vectors.column(c);
            prop_assert!((m * col - col * values[c]).norm() <= 1e-13 * scale);
        }
        Ok(())
    }

    proptest! {
        #[test]
        fn decomposes_symmetric_matrices(
            e in prop::array::uniform6(-1.0f64..1.0),
            spread in prop::array::uniform3(-12i32..=0),
            angles in prop::array::uniform3(-3.2f64..3.2),
        ) {
            // Arbitrary symmetric matrices.
            let m = Matrix3::new(e[0], e[1], e[2], e[1], e[3], e[4], e[2], e[4], e[5]);
            check(&m)?;
            // Covariances of neighbourhoods: a rotated diagonal of spreads from 1 down to
            // 10⁻¹² (flat, thin, degenerate, repeated).
            let r = nalgebra::Rotation3::from_euler_angles(angles[0], angles[1], angles[2]);
            let d = Vector3::new(10f64.powi(spread[0]), 10f64.powi(spread[1]), 10f64.powi(spread[2]));
            let cov = r.matrix() * Matrix3::from_diagonal(&d) * r.matrix().transpose();
            let cov = (cov + cov.transpose()) * 0.5;
            check(&cov)?;
        }
    }

    #[test]
    fn small_eigenvalues_keep_their_relative_accuracy() {
        // A flat patch: spread 1 in the plane, 1e-10 across, tilted.
        let r = nalgebra::Rotation3::from_euler_angles(0.3, -0.7, 1.1);
        let d = Vector3::new(1.0, 0.5, 1e-10);
        let m = r.matrix() * Matrix3::from_diagonal(&d) * r.matrix().transpose();
        let (values, vectors) = symmetric_eigen3(&m);
        let smallest = (0..3)
            .min_by(|&a, &b| values[a].total_cmp(&values[b]))
            .unwrap();
        assert!((values[smallest] - 1e-10).abs() < 1e-15);
        let normal = vectors.column(smallest);
        assert!(normal.dot(&r.matrix().column(2)).abs() > 1.0 - 1e-12);
        assert_eq!(symmetric_eigen3(&Matrix3::zeros()).0, Vector3::zeros());
        let (v, e) = symmetric_eigen3(&Matrix3::from_diagonal(&Vector3::new(3.0, 1.0, 2.0)));
        assert_eq!((v, e), (Vector3::new(3.0, 1.0, 2.0), Matrix3::identity()));
    }
}
