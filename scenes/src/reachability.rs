//! Viewpoints on the viewing sphere (the paper's eq. (3)) and the pluggable reachability
//! test used by `describe` and by the generator's filter.
//!
//! This crate does no kinematics. Whoever has inverse kinematics (nbv-core's `Robot` with
//! the closed-form IK of the `dinast` frame) passes it in as a [`Reachability`]; any
//! closure `Fn(&Pose) -> bool` is one:
//!
//! ```
//! use nbv_scenes::reachability::{count_reachable, viewing_sphere};
//! use nbv_scenes::schema::Nbv;
//! use nalgebra::Point3;
//! let views = viewing_sphere(&Point3::new(0.7, 0.0, 0.35), &Nbv::default());
//! assert_eq!(views.len(), 6 * 13); // θ = 0, 15, …, 75°; φ = −180°, −150°, …, 180°
//! // e.g. `|pose| robot.ik_sensor("dinast", pose).is_some()` once kinematics exist:
//! let within_reach = |pose: &nbv_core::math::Pose| pose.translation.vector.norm() < 1.0;
//! let n = count_reachable(&views, &within_reach);
//! assert!(n > 0 && n < views.len());
//! ```

use crate::schema::Nbv;
use nalgebra::{Matrix3, Point3, Rotation3, Translation3, UnitQuaternion};
use nbv_core::math::Pose;

/// "Can the arm put the short-range sensor frame at this world pose?" (collision-free
/// at the goal is the planner's business, not this test's).
pub trait Reachability {
    /// Whether the sensor pose (world frame, z = viewing direction) is reachable.
    fn is_reachable(&self, sensor_pose: &Pose) -> bool;
}

impl<F: Fn(&Pose) -> bool> Reachability for F {
    fn is_reachable(&self, sensor_pose: &Pose) -> bool {
        self(sensor_pose)
    }
}

/// Eq. (3): the sensor pose on the sphere of radius `r` around `centre`, at inclination
/// `theta` (from straight above) and azimuth `phi`, looking at the centre (sensor z axis
/// towards the centre).
///
/// ```
/// use nbv_scenes::reachability::viewpoint_pose;
/// use nalgebra::{Point3, Vector3};
/// let p = viewpoint_pose(&Point3::new(1.0, 0.0, 0.0), 0.3, 0.0, 0.0);
/// assert!((p.translation.vector - Vector3::new(1.0, 0.0, 0.3)).norm() < 1e-12);
/// let z = p.rotation * Vector3::z();
/// assert!((z - Vector3::new(0.0, 0.0, -1.0)).norm() < 1e-12);
/// ```
pub fn viewpoint_pose(centre: &Point3<f64>, r: f64, theta: f64, phi: f64) -> Pose {
    let (st, ct) = theta.sin_cos();
    let (sp, cp) = phi.sin_cos();
    #[rustfmt::skip]
    let m = Matrix3::new(
        ct * cp,  sp, -st * cp,
        ct * sp, -cp, -st * sp,
        -st,     0.0, -ct,
    );
    let rotation = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(m));
    let t = centre.coords + r * nalgebra::Vector3::new(st * cp, st * sp, ct);
    Pose::from_parts(Translation3::from(t), rotation)
}

/// All candidate viewpoints of Algorithm 2 (lines 2–10, before the reachability filter):
/// `θ = Δθ·i` for `i = 0..=⌊θ_max/Δθ⌋`, `φ = −π + Δφ·j` for `j = 0..=⌊2π/Δφ⌋`.
pub fn viewing_sphere(centre: &Point3<f64>, nbv: &Nbv) -> Vec<Pose> {
    let dtheta = nbv.dtheta_deg.to_radians();
    let dphi = nbv.dphi_deg.to_radians();
    if dtheta.is_nan() || dphi.is_nan() || dtheta <= 0.0 || dphi <= 0.0 {
        return Vec::new();
    }
    let ni = (nbv.theta_max_deg.to_radians() / dtheta + 1e-9)
        .floor()
        .max(0.0) as usize;
    let nj = (std::f64::consts::TAU / dphi + 1e-9).floor() as usize;
    let mut out = Vec::with_capacity((ni + 1) * (nj + 1));
    for i in 0..=ni {
        for j in 0..=nj {
            let theta = dtheta * i as f64;
            let phi = -std::f64::consts::PI + dphi * j as f64;
            out.push(viewpoint_pose(centre, nbv.radius, theta, phi));
        }
    }
    out
}

/// How many of `views` pass the reachability test.
pub fn count_reachable(views: &[Pose], reach: &dyn Reachability) -> usize {
    views.iter().filter(|v| reach.is_reachable(v)).count()
}
