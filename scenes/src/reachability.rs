//! Viewpoints on the viewing sphere (the paper's eq. (3)) and the pluggable reachability
//! test used by `describe` and by the generator's filter.
//!
//! This crate does no kinematics. Whoever has inverse kinematics (nbv-core's `Robot` with
//! the closed-form IK of the `dinast` frame) passes it in as a [`Reachability`]; any
//! closure `Fn(&Pose) -> bool` is one:
//!
//! ```
//! use nbv_scenes::reachability::{count_reachable, viewing_sphere};
//! use nbv_scenes::schema::{Nbv, NbvPreset};
//! use nalgebra::Point3;
//! let views = viewing_sphere(&Point3::new(0.7, 0.0, 0.35), &Nbv::preset(NbvPreset::Paper));
//! assert_eq!(views.len(), 1 + 5 * 12); // θ = 0 once; θ = 15…75°, φ = −180°…150°
//! // e.g. `|pose| robot.ik_sensor("dinast", pose).is_some()` once kinematics exist:
//! let within_reach = |pose: &nbv_core::math::Pose| pose.translation.vector.norm() < 1.0;
//! let n = count_reachable(&views, &within_reach);
//! assert!(n > 0 && n < views.len());
//! ```

use crate::schema::Nbv;
use nalgebra::Point3;
use nbv_core::math::Pose;
use nbv_core::nbv::view_pose;

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

/// All candidate viewpoints of Algorithm 2 (lines 2–10, before the reachability filter):
/// the samples of the scene's viewing sphere ([`nbv_core::nbv::ViewSphere`], without the
/// repeated azimuth at φ = π and the repeats at the pole) at the poses of eq. (3)
/// ([`nbv_core::nbv::view_pose`]). Invalid sphere parameters give no viewpoint.
pub fn viewing_sphere(centre: &Point3<f64>, nbv: &Nbv) -> Vec<Pose> {
    let sphere = nbv.params().sphere;
    sphere
        .samples()
        .map(|samples| {
            samples
                .iter()
                .map(|s| view_pose(centre, sphere.radius, s.theta, s.phi))
                .collect()
        })
        .unwrap_or_default()
}

/// How many of `views` pass the reachability test.
pub fn count_reachable(views: &[Pose], reach: &dyn Reachability) -> usize {
    views.iter().filter(|v| reach.is_reachable(v)).count()
}
