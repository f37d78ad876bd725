//! [`Planner`]: the joint-space bidirectional RRT and its post-processing.

use super::Check;
use crate::error::SceneError;
use nbv_core::planning::PlannerConfig;
use serde::{Deserialize, Serialize};

/// RRT-Connect's parameters; a key left out takes nbv-core's [`PlannerConfig`] default.
/// There is no goal bias (RRT-Connect grows a tree from each end towards the other), no
/// edge step (edges are checked every half voxel of any robot point's motion) and no
/// retry count (a viewpoint whose plan fails gives way to the next candidate).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Planner {
    /// Iterations per planning try. Default 4000 (OpenRAVE's BiRRT budget).
    pub max_iterations: u32,
    /// Extension step in joint space (rad, Euclidean norm). Default 0.2 (see
    /// [`PlannerConfig`]).
    pub step_rad: f64,
    /// Random shortcut attempts on a found path. Default 50.
    pub shortcut_iterations: u32,
}

impl Default for Planner {
    fn default() -> Self {
        let core = PlannerConfig::default();
        Self {
            max_iterations: core.max_iterations as u32,
            step_rad: core.step,
            shortcut_iterations: core.shortcut_iterations as u32,
        }
    }
}

impl Planner {
    /// Checks every value of `[planner]`; the error names the key.
    pub(crate) fn check(&self, c: &Check) -> Result<(), SceneError> {
        c.at_least("planner.max_iterations", self.max_iterations.into(), 1)?;
        c.within("planner.step_rad", self.step_rad, 1e-6, 3.15, "(0, π] rad")?;
        Ok(())
    }
}
