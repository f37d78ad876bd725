//! [`Sweep`]: the phase-1 joint trajectory that carries the laser over the table.

use nbv_core::kinematics::Joints;
use serde::{Deserialize, Serialize};

/// The mid-range observation (phase 1): the arm moves from home to the first waypoint
/// (not scanned), then through the waypoints in order while the laser streams lines.
///
/// Each segment's duration is `max_j |Δq_j| / (joint_speed_fraction · vmax_j)` with the
/// URDF's joint velocity limits, so all joints arrive together.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Sweep {
    /// Joint waypoints J1..J6 (degrees), at least two. Default: forearm raised
    /// (J2 = −30°, J3 = −90°), the wrist pitching J5 from 120° to 75° so the scan line
    /// travels from the front edge of the table to the back (≈ 1.0–1.5 m from the laser,
    /// inside its 0.7–3.0 m range). An estimate to be confirmed with forward kinematics.
    pub waypoints_deg: Vec<[f64; 6]>,
    /// Fraction (0, 1] of each joint's maximum speed. Default 0.12: the 45° wrist sweep
    /// (J5 at up to 375°/s) takes ≈ 1 s, ≈ 190 lines of 281 rays, close to the paper's
    /// ~55K-point raw cloud.
    pub joint_speed_fraction: f64,
}

impl Default for Sweep {
    fn default() -> Self {
        Self {
            waypoints_deg: vec![
                [0.0, -30.0, -90.0, 0.0, 120.0, 0.0],
                [0.0, -30.0, -90.0, 0.0, 75.0, 0.0],
            ],
            joint_speed_fraction: 0.12,
        }
    }
}

impl Sweep {
    /// The waypoints in radians.
    ///
    /// ```
    /// let w = nbv_scenes::schema::Sweep::default().joint_waypoints();
    /// assert!(w.len() >= 2);
    /// ```
    pub fn joint_waypoints(&self) -> Vec<Joints> {
        self.waypoints_deg
            .iter()
            .map(|w| Joints::from_iterator(w.iter().map(|d| d.to_radians())))
            .collect()
    }
}
