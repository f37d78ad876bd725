//! [`Layout`]: the tolerances that validation applies to the placement of objects.

use super::Check;
use crate::error::SceneError;
use serde::{Deserialize, Serialize};

/// Placement rules checked on load (the paper: objects lie on a plane, with a minimum
/// distance between each pair, not touching).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Layout {
    /// Smallest allowed distance (m) between the surfaces of two objects, and between an
    /// object and an obstacle (exact triangle-to-triangle distance of the placed meshes).
    /// Default 0.03: above the segmentation's cluster tolerance (0.02), so separate objects
    /// stay separate clusters.
    pub min_object_distance: f64,
    /// How far (m) an object's lowest point may be from the table top (above or below) and
    /// still count as resting on it. Default 0.002.
    pub rest_tolerance: f64,
}

impl Default for Layout {
    fn default() -> Self {
        Self {
            min_object_distance: 0.03,
            rest_tolerance: 0.002,
        }
    }
}

impl Layout {
    /// Checks every value of `[layout]`; the error names the key.
    pub(crate) fn check(&self, c: &Check) -> Result<(), SceneError> {
        c.within(
            "layout.min_object_distance",
            self.min_object_distance,
            0.0,
            1.0,
            "[0, 1] m",
        )?;
        c.within(
            "layout.rest_tolerance",
            self.rest_tolerance,
            0.0,
            0.05,
            "[0, 0.05] m",
        )?;
        Ok(())
    }
}
