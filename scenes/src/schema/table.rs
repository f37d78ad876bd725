//! [`Table`]: the box the objects stand on.

use super::Check;
use crate::error::SceneError;
use serde::{Deserialize, Serialize};

/// The table: an axis-aligned box. Objects rest on its top face (`max[2]`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Table {
    /// Lower corner `[x, y, z]` (m). Required.
    pub min: [f64; 3],
    /// Upper corner `[x, y, z]` (m); `max[2]` is the height of the top surface. Required.
    pub max: [f64; 3],
}

impl Table {
    /// Height of the top surface.
    pub fn top(&self) -> f64 {
        self.max[2]
    }
}

impl Table {
    /// Checks every value of `[table]`; the error names the key.
    pub(crate) fn check(&self, c: &Check) -> Result<(), SceneError> {
        c.boxed("table", self.min, self.max)?;
        Ok(())
    }
}
