//! The sensor pose of a viewpoint on the viewing sphere: the paper's eq. (3).
//!
//! ```text
//!            ⎡ cθ·cφ   sφ   −sθ·cφ   x_c + r·sθ·cφ ⎤
//! T(p_c,r,θ,φ) = ⎢ cθ·sφ  −cφ   −sθ·sφ   y_c + r·sθ·sφ ⎥
//!            ⎢ −sθ     0    −cθ      z_c + r·cθ    ⎥
//!            ⎣ 0       0     0       1             ⎦
//! ```
//!
//! Checked here (and in the tests): the third column is `−(sθcφ, sθsφ, cθ)`, the unit
//! vector from the viewpoint to the centroid, so the sensor's z axis looks at `p_c`; the
//! first column × the second column equals the third, so the matrix is a proper rotation
//! (det = +1) as printed — no sign correction is needed. θ = 0 puts the sensor straight
//! above the centroid looking down (world −z).
//!
//! The paper's sensor frame S has z along the optical axis, as our optical frames do
//! (`dinast`: z forward, x to the image's right, y down the image), so eq. (3) is used as
//! the pose of the camera frame itself. The roll about the optical axis is not constrained
//! by the task; eq. (3) fixes it so that the image's x axis is the direction of increasing
//! θ (the image's "right" points away from the pole) and its y axis `(sφ, −cφ, 0)` is
//! horizontal. [`view_pose_rolled`] turns the frame about its own z axis.

use nalgebra::{Matrix3, Point3, Rotation3, Translation3, UnitQuaternion, Vector3};

use crate::math::Pose;

/// The rotation of eq. (3), as printed.
///
/// ```
/// use nbv_core::nbv::view_rotation;
/// let r = view_rotation(0.3, -1.2);
/// assert!((r.matrix().determinant() - 1.0).abs() < 1e-12);
/// ```
pub fn view_rotation(theta: f64, phi: f64) -> Rotation3<f64> {
    let (st, ct) = theta.sin_cos();
    let (sp, cp) = phi.sin_cos();
    #[rustfmt::skip]
    let m = Matrix3::new(
        ct * cp,  sp, -st * cp,
        ct * sp, -cp, -st * sp,
        -st,     0.0, -ct,
    );
    Rotation3::from_matrix_unchecked(m)
}

/// The viewpoint's position on the sphere of radius `radius` around `centroid`:
/// `p_c + r·(sθcφ, sθsφ, cθ)` (the translation of eq. (3)).
pub fn view_position(centroid: &Point3<f64>, radius: f64, theta: f64, phi: f64) -> Point3<f64> {
    let (st, ct) = theta.sin_cos();
    let (sp, cp) = phi.sin_cos();
    centroid + radius * Vector3::new(st * cp, st * sp, ct)
}

/// The sensor pose of eq. (3) (`T_base_sensor`): at [`view_position`], z axis towards the
/// centroid.
///
/// ```
/// use nbv_core::nbv::view_pose;
/// use nalgebra::{Point3, Vector3};
/// let c = Point3::new(0.8, 0.1, 0.3);
/// let pose = view_pose(&c, 0.3, 0.0, 0.0);
/// // θ = 0: straight above, looking down.
/// assert!((pose.translation.vector - Vector3::new(0.8, 0.1, 0.6)).norm() < 1e-12);
/// assert!((pose.rotation * Vector3::z() + Vector3::z()).norm() < 1e-12);
/// ```
pub fn view_pose(centroid: &Point3<f64>, radius: f64, theta: f64, phi: f64) -> Pose {
    let p = view_position(centroid, radius, theta, phi);
    let r = view_rotation(theta, phi);
    Pose::from_parts(
        Translation3::from(p.coords),
        UnitQuaternion::from_rotation_matrix(&r),
    )
}

/// `pose` turned by `roll` radians about its own z axis (the optical axis): same position,
/// same viewing direction, the image rotated.
pub fn view_pose_rolled(pose: &Pose, roll: f64) -> Pose {
    if roll == 0.0 {
        return *pose;
    }
    pose * UnitQuaternion::from_axis_angle(&Vector3::z_axis(), roll)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use std::f64::consts::{FRAC_PI_2, PI};

    proptest! {
        #[test]
        fn eq3_is_a_proper_rotation_looking_at_the_centroid(
            theta in 0.0f64..PI, phi in -PI..PI,
            c in (-1.0f64..1.0, -1.0f64..1.0, 0.0f64..1.0), r in 0.05f64..1.0,
        ) {
            let c = Point3::new(c.0, c.1, c.2);
            let m = *view_rotation(theta, phi).matrix();
            // Orthonormal with det +1.
            prop_assert!((m.transpose() * m - Matrix3::identity()).norm() < 1e-12);
            prop_assert!((m.determinant() - 1.0).abs() < 1e-12);
            // Column 1 × column 2 = column 3 (right-handed as printed).
            let (x, y, z) = (m.column(0), m.column(1), m.column(2));
            prop_assert!((x.cross(&y) - z).norm() < 1e-12);
            // z points from the viewpoint to the centroid, at distance r.
            let pose = view_pose(&c, r, theta, phi);
            let p = Point3::from(pose.translation.vector);
            prop_assert!(((p - c).norm() - r).abs() < 1e-12);
            let axis = pose.rotation * Vector3::z();
            prop_assert!((axis - (c - p) / r).norm() < 1e-12);
            // The optical axis passes through the centroid.
            let along = (c - p).dot(&axis);
            prop_assert!((p + along * axis - c).norm() < 1e-12);
            // A roll keeps position and axis.
            let rolled = view_pose_rolled(&pose, 1.3);
            prop_assert!((rolled.translation.vector - pose.translation.vector).norm() < 1e-15);
            prop_assert!((rolled.rotation * Vector3::z() - axis).norm() < 1e-12);
        }
    }

    #[test]
    fn hand_computed_poses() {
        let c = Point3::new(1.0, 2.0, 3.0);
        // θ = 90°, φ = 0: on the +x side, looking along −x; image x = down, y = −y.
        let pose = view_pose(&c, 0.5, FRAC_PI_2, 0.0);
        assert!((pose.translation.vector - Vector3::new(1.5, 2.0, 3.0)).norm() < 1e-12);
        let r = pose.rotation.to_rotation_matrix();
        let expect = Matrix3::new(0.0, 0.0, -1.0, 0.0, -1.0, 0.0, -1.0, 0.0, 0.0);
        assert!((r.matrix() - expect).norm() < 1e-12);
        // θ = 90°, φ = 90°: on the +y side looking along −y; image y = world +x.
        let pose = view_pose(&c, 0.5, FRAC_PI_2, FRAC_PI_2);
        assert!((pose.translation.vector - Vector3::new(1.0, 2.5, 3.0)).norm() < 1e-12);
        assert!((pose.rotation * Vector3::y() - Vector3::x()).norm() < 1e-12);
        // θ = 0, φ = −π (the first sample of Algorithm 2): above, image x = world −x.
        let pose = view_pose(&c, 0.3, 0.0, -PI);
        assert!((pose.translation.vector - Vector3::new(1.0, 2.0, 3.3)).norm() < 1e-12);
        assert!((pose.rotation * Vector3::x() + Vector3::x()).norm() < 1e-12);
        assert!((pose.rotation * Vector3::z() + Vector3::z()).norm() < 1e-12);
        // A quarter roll maps the image x axis onto the former y axis.
        let rolled = view_pose_rolled(&pose, FRAC_PI_2);
        assert!((rolled.rotation * Vector3::x() - pose.rotation * Vector3::y()).norm() < 1e-12);
    }
}
