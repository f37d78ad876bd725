//! [`Model`]: the fused surface of each object (`[model]`): a TSDF of its registered
//! camera views and the mesh of its zero set.

use super::Check;
use crate::error::SceneError;
use nbv_core::surface::TsdfParams;
use serde::{Deserialize, Serialize};

/// The surface model of each object.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Model {
    /// Fuse each object's registered camera views into a mesh (`model_mesh.ply`). Default
    /// true.
    pub mesh: bool,
    /// TSDF voxel edge (m). Default 0.002.
    pub voxel: f64,
    /// TSDF truncation distance (m), at least two voxels. Default 0.016 (measured: docs/surface.md).
    pub truncation: f64,
    /// Observations a voxel needs for the mesh to pass through it. Default 1.
    pub min_observations: u32,
}

impl Default for Model {
    fn default() -> Self {
        let core = TsdfParams::default();
        Self {
            mesh: true,
            voxel: core.voxel,
            truncation: core.truncation,
            min_observations: core.min_observations.into(),
        }
    }
}

impl Model {
    /// The fusion's parameters, `None` when the mesh is off.
    pub fn params(&self) -> Option<TsdfParams> {
        self.mesh.then(|| TsdfParams {
            voxel: self.voxel,
            truncation: self.truncation,
            min_observations: self.min_observations.min(u32::from(u16::MAX)) as u16,
        })
    }

    /// Checks every value of `[model]`; the error names the key.
    pub(crate) fn check(&self, c: &Check) -> Result<(), SceneError> {
        c.within("model.voxel", self.voxel, 1e-4, 0.05, "[0.0001, 0.05] m")?;
        c.within(
            "model.truncation",
            self.truncation,
            2.0 * self.voxel,
            0.2,
            "at least two voxels (2 × model.voxel) and at most 0.2 m",
        )?;
        c.at_least("model.min_observations", self.min_observations.into(), 1)?;
        c.within(
            "model.min_observations",
            self.min_observations.into(),
            1.0,
            f64::from(u16::MAX),
            "[1, 65535]",
        )?;
        Ok(())
    }
}
