//! The one place where the project's nalgebra `f64` math meets Rapier/parry's glam `f32`
//! math types.

use nalgebra::{Isometry3, Point3, Vector3};
use rapier3d::math::{Pose as RPose, Vector as RVector};

/// nalgebra `f64` pose → Rapier pose.
pub(crate) fn to_rapier_pose(p: &Isometry3<f64>) -> RPose {
    p.cast::<f32>().into()
}

/// Rapier pose → nalgebra `f64` pose.
pub(crate) fn from_rapier_pose(p: &RPose) -> Isometry3<f64> {
    let iso: Isometry3<f32> = (*p).into();
    iso.cast::<f64>()
}

/// nalgebra `f64` point → Rapier vector.
pub(crate) fn to_rapier_point(p: &Point3<f64>) -> RVector {
    RVector::new(p.x as f32, p.y as f32, p.z as f32)
}

/// nalgebra `f64` vector → Rapier vector.
pub(crate) fn to_rapier_vector(v: &Vector3<f64>) -> RVector {
    RVector::new(v.x as f32, v.y as f32, v.z as f32)
}

/// Rapier vector → nalgebra `f64` vector.
pub(crate) fn from_rapier_vector(v: RVector) -> Vector3<f64> {
    Vector3::new(f64::from(v.x), f64::from(v.y), f64::from(v.z))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pose_round_trip_is_f32_exact() {
        let p = Isometry3::new(Vector3::new(0.5, -0.25, 1.0), Vector3::new(0.1, 0.2, -0.3));
        let back = from_rapier_pose(&to_rapier_pose(&p));
        assert!((back.translation.vector - p.translation.vector).norm() < 1e-6);
        assert!(back.rotation.angle_to(&p.rotation) < 1e-6);
        let v = to_rapier_vector(&Vector3::new(1.0, 2.0, 3.0));
        assert_eq!(from_rapier_vector(v), Vector3::new(1.0, 2.0, 3.0));
        let q = to_rapier_point(&Point3::new(4.0, 5.0, 6.0));
        assert_eq!(q.z, 6.0);
    }
}
