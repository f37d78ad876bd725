//! [`DensePoses`]: the oracle's dense set of camera poses around an object — every
//! combination of several radii within the camera's range, fine inclination and azimuth
//! steps and rolls about the optical axis, each looking at the object's centre by the
//! paper's eq. (3).

use nalgebra::Point3;
use nbv_core::math::Pose;
use nbv_core::nbv::{ViewSphere, view_pose, view_pose_rolled};
use serde::Serialize;
use std::f64::consts::PI;

/// The dense pose set's parameters.
///
/// Rolls: a pinhole image is symmetric under a half turn about its optical axis (pixel
/// `(u, v)` looks where `(w − 1 − u, h − 1 − v)` looked), so rolls `k·180°/n` for
/// `k = 0..n` give every distinct footprint at that step; a roll counts as reachable when
/// the arm reaches it or its half turn.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DensePoses {
    /// Distances (m) from the object's centre.
    pub radii: Vec<f64>,
    /// Inclination step (degrees) from straight above.
    pub delta_theta_deg: f64,
    /// Largest inclination (degrees; 90 looks horizontally at the centre).
    pub theta_max_deg: f64,
    /// Azimuth step (degrees).
    pub delta_phi_deg: f64,
    /// Distinct rolls about the optical axis (spread over 180°).
    pub rolls: usize,
}

impl Default for DensePoses {
    /// Three radii, 0.25, 0.45 and 0.65 m (the Dinast sees 0.1–0.8 m; an object's near
    /// side is ~5–15 cm nearer than its centre), every 15° of inclination down to the
    /// horizontal, every 20° of azimuth, two rolls (0° and 90°): 3 × 109 positions × 2
    /// rolls = 654 poses, beside Algorithm 2's own. On paper-env1 it gives the ceilings of
    /// a set of 1,736 poses (four radii 0.25–0.7 m, 10° × 15°) within 0.1 point, in a third
    /// of the time.
    fn default() -> Self {
        Self {
            radii: vec![0.25, 0.45, 0.65],
            delta_theta_deg: 15.0,
            theta_max_deg: 90.0,
            delta_phi_deg: 20.0,
            rolls: 2,
        }
    }
}

/// One dense pose: its place on the spheres and the two rolls that give its footprint.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DensePose {
    /// The pose at the roll (world frame).
    pub pose: Pose,
    /// The same footprint a half turn about the optical axis away.
    pub turned: Pose,
}

impl DensePoses {
    /// Checks the parameters: radii positive and finite, steps in (0, 360], θ_max in
    /// [0, 180], at least one roll.
    pub fn validate(&self) -> Result<(), String> {
        if self.radii.is_empty() || self.radii.iter().any(|r| !(r.is_finite() && *r > 0.0)) {
            return Err("radii must be finite and > 0 (at least one)".into());
        }
        let step = |v: f64| v.is_finite() && v > 0.0 && v <= 360.0;
        if !step(self.delta_theta_deg) || !step(self.delta_phi_deg) {
            return Err("the angular steps must be in (0, 360] degrees".into());
        }
        if !(0.0..=180.0).contains(&self.theta_max_deg) {
            return Err("theta_max_deg must be in [0, 180]".into());
        }
        if self.rolls == 0 {
            return Err("rolls must be at least 1".into());
        }
        Ok(())
    }

    /// Every pose around `centre`: radius outer, then the sphere's samples in Algorithm 2's
    /// order (poles once), then the rolls.
    ///
    /// ```
    /// use nbv_sweep::oracle::DensePoses;
    /// use nalgebra::Point3;
    /// let poses = DensePoses::default().poses(&Point3::new(0.8, 0.0, 0.3)).unwrap();
    /// assert_eq!(poses.len(), 3 * (1 + 6 * 18) * 2);
    /// // Every pose looks at the centre.
    /// for p in &poses {
    ///     let axis = p.pose.rotation * nalgebra::Vector3::z();
    ///     let to_centre = (Point3::new(0.8, 0.0, 0.3) - Point3::from(p.pose.translation.vector)).normalize();
    ///     assert!((axis - to_centre).norm() < 1e-9);
    /// }
    /// ```
    pub fn poses(&self, centre: &Point3<f64>) -> Result<Vec<DensePose>, String> {
        self.validate()?;
        let mut out = Vec::new();
        for &radius in &self.radii {
            let sphere = ViewSphere {
                radius,
                delta_theta: self.delta_theta_deg.to_radians(),
                theta_max: self.theta_max_deg.to_radians(),
                delta_phi: self.delta_phi_deg.to_radians(),
                near_radius: 0.0,
            };
            let samples = sphere.samples().map_err(|e| e.to_string())?;
            for s in samples {
                let base = view_pose(centre, radius, s.theta, s.phi);
                for k in 0..self.rolls {
                    let roll = PI * k as f64 / self.rolls as f64;
                    out.push(DensePose {
                        pose: view_pose_rolled(&base, roll),
                        turned: view_pose_rolled(&base, roll + PI),
                    });
                }
            }
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bad_parameters_are_refused() {
        let bad = [
            DensePoses {
                radii: vec![],
                ..DensePoses::default()
            },
            DensePoses {
                radii: vec![0.3, f64::NAN],
                ..DensePoses::default()
            },
            DensePoses {
                delta_phi_deg: 0.0,
                ..DensePoses::default()
            },
            DensePoses {
                rolls: 0,
                ..DensePoses::default()
            },
        ];
        for d in bad {
            assert!(d.poses(&Point3::origin()).is_err(), "{d:?}");
        }
    }

    #[test]
    fn a_half_turn_keeps_position_and_axis() {
        let poses = DensePoses::default()
            .poses(&Point3::new(0.7, 0.1, 0.35))
            .unwrap();
        for p in poses {
            let d = p.pose.translation.vector - p.turned.translation.vector;
            assert!(d.norm() < 1e-12);
            let z = nalgebra::Vector3::z();
            assert!((p.pose.rotation * z - p.turned.rotation * z).norm() < 1e-9);
            let x = nalgebra::Vector3::x();
            assert!((p.pose.rotation * x + p.turned.rotation * x).norm() < 1e-9);
        }
    }
}
