//! [`VisitedViews`]: the sensor poses already used for an object, and the test that drops
//! candidate viewpoints close to one of them (Algorithm 2's "viewpoints that are close to
//! already visited viewpoints are discarded").

use nalgebra::Vector3;

use super::NbvError;
use crate::math::Pose;

/// The visited sensor poses and the closeness test.
///
/// A candidate is *close* to a visited pose when its position is within `distance` metres
/// of it **and** its optical axis (z) is within `angle` radians of the visited one's. Set
/// `angle` to π to test positions only, or `distance` to infinity to test directions only.
///
/// Defaults: 0.08 m (about one Δθ step on the twin's sphere: 0.45 m × 10° = 0.079 m) and
/// 20°: a visited pose removes its own sample, even after the centroid moved by a few
/// centimetres, and its nearest neighbours.
///
/// ```
/// use nbv_core::nbv::{VisitedViews, view_pose};
/// use nalgebra::Point3;
/// let c = Point3::new(0.8, 0.0, 0.3);
/// let mut visited = VisitedViews::default();
/// visited.push(view_pose(&c, 0.3, 0.5, 1.0));
/// // The same sample around a centroid moved by 1 cm is close; the opposite side is not.
/// assert!(visited.is_close(&view_pose(&(c + nalgebra::Vector3::x() * 0.01), 0.3, 0.5, 1.0)));
/// assert!(!visited.is_close(&view_pose(&c, 0.3, 0.5, 1.0 - std::f64::consts::PI)));
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct VisitedViews {
    /// Visited sensor poses (`T_base_sensor`).
    pub poses: Vec<Pose>,
    /// Position threshold (m), ≥ 0.
    pub distance: f64,
    /// Optical-axis angle threshold (rad), in [0, π].
    pub angle: f64,
}

impl Default for VisitedViews {
    fn default() -> Self {
        Self {
            poses: Vec::new(),
            distance: 0.08,
            angle: 20f64.to_radians(),
        }
    }
}

impl VisitedViews {
    /// Empty, with the given thresholds.
    pub fn new(distance: f64, angle: f64) -> Result<Self, NbvError> {
        let v = Self {
            poses: Vec::new(),
            distance,
            angle,
        };
        v.validate()?;
        Ok(v)
    }

    /// Checks the thresholds.
    pub fn validate(&self) -> Result<(), NbvError> {
        if self.distance.is_nan() || self.distance < 0.0 {
            return Err(NbvError::InvalidParameter {
                name: "visited distance",
                value: self.distance,
                reason: "must be >= 0",
            });
        }
        if !(self.angle >= 0.0 && self.angle <= std::f64::consts::PI) {
            return Err(NbvError::InvalidParameter {
                name: "visited angle",
                value: self.angle,
                reason: "must be in [0, π]",
            });
        }
        Ok(())
    }

    /// Records a visited sensor pose.
    pub fn push(&mut self, pose: Pose) {
        self.poses.push(pose);
    }

    /// Whether `pose` is close to a visited pose (see the type's doc).
    pub fn is_close(&self, pose: &Pose) -> bool {
        let axis = pose.rotation * Vector3::z();
        let cos_limit = self.angle.cos();
        self.poses.iter().any(|v| {
            let d = (v.translation.vector - pose.translation.vector).norm();
            let cos = (v.rotation * Vector3::z()).dot(&axis);
            d <= self.distance && cos >= cos_limit - 1e-12
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nbv::view_pose;
    use nalgebra::Point3;

    #[test]
    fn thresholds_apply_together() {
        let c = Point3::origin();
        let a = view_pose(&c, 0.3, 0.6, 0.0);
        let mut v = VisitedViews::new(0.05, 0.2).unwrap();
        v.push(a);
        assert!(v.is_close(&a));
        // 4 cm away, same direction: close.
        let mut b = a;
        b.translation.vector.x += 0.04;
        assert!(v.is_close(&b));
        // 6 cm away: not close.
        b.translation.vector.x += 0.02;
        assert!(!v.is_close(&b));
        // Same position, axis turned by 0.25 rad > 0.2: not close.
        let turned = a * nalgebra::UnitQuaternion::from_axis_angle(&Vector3::x_axis(), 0.25);
        assert!(!v.is_close(&turned));
        let turned = a * nalgebra::UnitQuaternion::from_axis_angle(&Vector3::x_axis(), 0.15);
        assert!(v.is_close(&turned));
        // Roll about the optical axis does not matter.
        let rolled = a * nalgebra::UnitQuaternion::from_axis_angle(&Vector3::z_axis(), 2.0);
        assert!(v.is_close(&rolled));
        assert!(VisitedViews::new(-1.0, 0.1).is_err());
        assert!(VisitedViews::new(0.1, 4.0).is_err());
    }

    #[test]
    fn a_visited_sample_removes_itself_and_near_neighbours_only() {
        let c = Point3::new(0.8, 0.0, 0.3);
        // The paper's sphere (r = 0.3 m, Δθ = 15°, Δφ = 30°) and 0.05 m / 20°.
        let samples = crate::nbv::NbvPreset::Paper.sphere().samples().unwrap();
        let pose = |i: usize| view_pose(&c, 0.3, samples[i].theta, samples[i].phi);
        let close_to = |visited: usize| {
            let mut v = VisitedViews::new(0.05, 20f64.to_radians()).unwrap();
            v.push(pose(visited));
            (0..samples.len())
                .filter(|&i| v.is_close(&pose(i)))
                .collect::<Vec<_>>()
        };
        // The pole (index 0) is 0.078 m from ring 1: only itself.
        assert_eq!(close_to(0), vec![0]);
        // Ring 1 (θ = 15°): neighbours in φ are 0.040 m and 7.7° apart.
        assert_eq!(close_to(5), vec![4, 5, 6]);
        // Ring 3 (θ = 45°): neighbours 0.110 m apart: itself only.
        assert_eq!(close_to(30), vec![30]);
    }
}
