//! Rigid poses (`Isometry3<f64>`) and their URDF-style `xyz` + `rpy` form.
//!
//! `rpy` follows URDF/ROS: fixed-axis roll about x, then pitch about y, then yaw about z,
//! i.e. `R = Rz(yaw) · Ry(pitch) · Rx(roll)`.

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};

/// A rigid transform. `T_a_b` maps coordinates in frame `b` to frame `a`.
pub type Pose = Isometry3<f64>;

/// Builds a pose from a translation and URDF roll-pitch-yaw angles (radians).
///
/// ```
/// use nbv_core::math::{pose_from_xyz_rpy, pose_to_xyz_rpy};
/// let p = pose_from_xyz_rpy([0.1, 0.2, 0.3], [0.0, std::f64::consts::FRAC_PI_2, 0.0]);
/// // Pitching +90° about y maps the x axis onto -z.
/// let x = p.rotation * nalgebra::Vector3::x();
/// assert!((x - nalgebra::Vector3::new(0.0, 0.0, -1.0)).norm() < 1e-12);
/// let (xyz, _) = pose_to_xyz_rpy(&p);
/// assert!((xyz[2] - 0.3).abs() < 1e-12);
/// ```
pub fn pose_from_xyz_rpy(xyz: [f64; 3], rpy: [f64; 3]) -> Pose {
    Isometry3::from_parts(
        Translation3::new(xyz[0], xyz[1], xyz[2]),
        UnitQuaternion::from_euler_angles(rpy[0], rpy[1], rpy[2]),
    )
}

/// Splits a pose into its translation and URDF roll-pitch-yaw angles (radians).
pub fn pose_to_xyz_rpy(pose: &Pose) -> ([f64; 3], [f64; 3]) {
    let t: Vector3<f64> = pose.translation.vector;
    let (r, p, y) = pose.rotation.euler_angles();
    ([t.x, t.y, t.z], [r, p, y])
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #[test]
        fn rpy_round_trips(r in -3.1f64..3.1, p in -1.5f64..1.5, y in -3.1f64..3.1,
                           x in -2.0f64..2.0) {
            let pose = pose_from_xyz_rpy([x, -x, 2.0 * x], [r, p, y]);
            let (xyz, rpy) = pose_to_xyz_rpy(&pose);
            let back = pose_from_xyz_rpy(xyz, rpy);
            prop_assert!((back.to_homogeneous() - pose.to_homogeneous()).norm() < 1e-12);
        }
    }

    #[test]
    fn rpy_matches_urdf_order() {
        // Rz(yaw) * Ry(pitch) * Rx(roll) applied to x.
        let (r, p, y) = (0.3, -0.4, 1.1);
        let pose = pose_from_xyz_rpy([0.0; 3], [r, p, y]);
        let expected = nalgebra::Rotation3::from_axis_angle(&Vector3::z_axis(), y)
            * nalgebra::Rotation3::from_axis_angle(&Vector3::y_axis(), p)
            * nalgebra::Rotation3::from_axis_angle(&Vector3::x_axis(), r);
        let d = pose.rotation.to_rotation_matrix().matrix() - expected.matrix();
        assert!(d.norm() < 1e-12);
    }
}
