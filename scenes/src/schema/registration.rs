//! [`Registration`]: p-ICP-GPA (and the sequential ICP baseline).

use serde::{Deserialize, Serialize};

/// Global registration of an object's views.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Registration {
    /// Largest mutual-nearest-neighbour distance `d_max` (m). Default 0.03 (about twice
    /// the short-range noise at working distance; assumed).
    pub d_max: f64,
    /// Iteration cap. Default 100.
    pub max_iterations: u32,
    /// Stop when the mean squared distance to the centroids changes by less than this
    /// fraction between iterations. Default 1e-6.
    pub tolerance: f64,
    /// Points per view after undersampling. Default 2000 (paper).
    pub points_per_view: u32,
}

impl Default for Registration {
    fn default() -> Self {
        Self {
            d_max: 0.03,
            max_iterations: 100,
            tolerance: 1e-6,
            points_per_view: 2000,
        }
    }
}
