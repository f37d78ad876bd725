//! Small geometric subproblems the closed-form IK is made of: the angle of a rotation about
//! an axis that carries one vector onto another, rotations about an axis, and the common
//! perpendicular of two lines.

use nalgebra::{Rotation3, Unit, Vector3};

/// Rotation by `angle` about the unit vector `axis`.
pub(crate) fn rot(axis: &Vector3<f64>, angle: f64) -> Rotation3<f64> {
    Rotation3::from_axis_angle(&Unit::new_unchecked(*axis), angle)
}

/// Component of `v` orthogonal to the unit vector `axis`.
pub(crate) fn reject(v: &Vector3<f64>, axis: &Vector3<f64>) -> Vector3<f64> {
    v - axis * axis.dot(v)
}

/// Angle θ in (-π, π] such that rotating `a` by θ about the unit `axis` points it along `b`,
/// both taken orthogonally to the axis. `None` if either projection is (numerically) zero.
pub(crate) fn angle_about(axis: &Vector3<f64>, a: &Vector3<f64>, b: &Vector3<f64>) -> Option<f64> {
    let a = reject(a, axis);
    let b = reject(b, axis);
    if a.norm() == 0.0 || b.norm() == 0.0 {
        return None;
    }
    Some(axis.dot(&a.cross(&b)).atan2(a.dot(&b)))
}

/// The closest points of two lines (point, unit direction), or `None` if they are parallel
/// (|u × w| below `parallel_tol`).
pub(crate) fn closest_points(
    a: &Vector3<f64>,
    u: &Vector3<f64>,
    b: &Vector3<f64>,
    w: &Vector3<f64>,
    parallel_tol: f64,
) -> Option<(Vector3<f64>, Vector3<f64>)> {
    let n = u.cross(w);
    let n2 = n.norm_squared();
    if n2.sqrt() < parallel_tol {
        return None;
    }
    let d = b - a;
    let t = d.cross(w).dot(&n) / n2;
    let s = d.cross(u).dot(&n) / n2;
    Some((a + u * t, b + w * s))
}

/// Distance between two parallel lines (point, unit direction of the first).
pub(crate) fn parallel_distance(a: &Vector3<f64>, u: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    reject(&(b - a), u).norm()
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn unit(x: f64, y: f64, z: f64) -> Option<Vector3<f64>> {
        let v = Vector3::new(x, y, z);
        (v.norm() > 0.1).then(|| v.normalize())
    }

    proptest! {
        #[test]
        fn angle_about_inverts_rotation(x in -1.0f64..1.0, y in -1.0f64..1.0, z in -1.0f64..1.0,
                                        px in -1.0f64..1.0, py in -1.0f64..1.0, pz in -1.0f64..1.0,
                                        angle in -3.1f64..3.1) {
            let Some(axis) = unit(x, y, z) else { return Ok(()) };
            let p = Vector3::new(px, py, pz);
            prop_assume!(reject(&p, &axis).norm() > 1e-3);
            let q = rot(&axis, angle) * p;
            let back = angle_about(&axis, &p, &q).unwrap();
            prop_assert!((back - angle).abs() < 1e-9);
        }
    }

    #[test]
    fn closest_points_of_skew_lines() {
        let (p, q) = closest_points(
            &Vector3::zeros(),
            &Vector3::x(),
            &Vector3::new(0.0, 0.0, 2.0),
            &Vector3::y(),
            1e-9,
        )
        .unwrap();
        assert!((p - Vector3::zeros()).norm() < 1e-15);
        assert!((q - Vector3::new(0.0, 0.0, 2.0)).norm() < 1e-15);
        assert!(closest_points(&p, &Vector3::x(), &q, &Vector3::x(), 1e-9).is_none());
        assert!((parallel_distance(&p, &Vector3::x(), &q) - 2.0).abs() < 1e-15);
        assert_eq!(
            angle_about(&Vector3::z(), &Vector3::z(), &Vector3::x()),
            None
        );
    }
}
