//! [`Sweep`]: the phase-1 joint trajectory that carries the laser over the table.

use super::Check;
use crate::error::{Problem, SceneError};
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
    /// Joint waypoints J1..J6 (degrees), at least two. Default: upper arm leaning back
    /// (J2 = −40°), forearm horizontal (J3 = −90°), the wrist pitching J5 from 112° to 84°,
    /// so the laser, about 1.2 m above the floor and 0.35 m in front of the base axis,
    /// carries its line from x ≈ 0.6 m on the table to the back obstacles at 0.85–1.5 m range
    /// (inside its 0.7–3.0 m). Checked in the twin: collision-free from the home
    /// configuration and along the sweep (J5 beyond ≈ 115° folds the sensor bracket onto
    /// the forearm).
    pub waypoints_deg: Vec<[f64; 6]>,
    /// Fraction (0, 1] of each joint's maximum speed. Default 0.06: the 28° wrist sweep (J5
    /// at up to 375°/s) takes 1.24 s, 237 lines of 281 rays, ≈ 57K points on the paper
    /// scenes (the paper's raw cloud: ~55K points).
    pub joint_speed_fraction: f64,
}

impl Default for Sweep {
    fn default() -> Self {
        Self {
            waypoints_deg: vec![
                [0.0, -40.0, -90.0, 0.0, 112.0, 0.0],
                [0.0, -40.0, -90.0, 0.0, 84.0, 0.0],
            ],
            joint_speed_fraction: 0.06,
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

impl Sweep {
    /// Checks every value of `[sweep]`; the error names the key.
    pub(crate) fn check(&self, c: &Check) -> Result<(), SceneError> {
        if self.waypoints_deg.len() < 2 {
            return Err(c.err(
                "sweep.waypoints_deg",
                Problem::OutOfRange {
                    value: format!("{} waypoints", self.waypoints_deg.len()),
                    expected: "at least 2".into(),
                },
            ));
        }
        for (i, w) in self.waypoints_deg.iter().enumerate() {
            c.finite(&format!("sweep.waypoints_deg[{i}]"), w)?;
        }
        c.within(
            "sweep.joint_speed_fraction",
            self.joint_speed_fraction,
            1e-6,
            1.0,
            "(0, 1]",
        )?;
        Ok(())
    }
}
