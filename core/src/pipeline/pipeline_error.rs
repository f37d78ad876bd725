//! [`PipelineError`]: why an exploration could not run to its end.

use crate::nbv::NbvError;
use crate::occupancy::OccupancyError;
use crate::perception::PerceptionError;
use crate::planning::PlanningError;
use crate::registration::RegistrationError;
use crate::rig::{RigError, SensorCloudError};
use thiserror::Error;

/// A failure that ends the exploration (failures of single viewpoints do not: they are
/// recorded and the next viewpoint is tried).
#[derive(Debug, Error)]
pub enum PipelineError {
    /// The configuration is unusable.
    #[error("invalid configuration: {0}")]
    Config(String),
    /// The rig failed outside a viewpoint attempt (sweep, capture, reading joints).
    #[error("rig: {0}")]
    Rig(#[from] RigError),
    /// Sensor data could not become a cloud.
    #[error("sensor data: {0}")]
    SensorCloud(#[from] SensorCloudError),
    /// A view's points could not be processed (the object region's growth).
    #[error("point cloud: {0}")]
    Cloud(#[from] crate::cloud::ProcessingError),
    /// Phase 1 failed.
    #[error("phase 1: {0}")]
    Perception(#[from] PerceptionError),
    /// The grid update failed.
    #[error("occupancy grid: {0}")]
    Occupancy(#[from] OccupancyError),
    /// Next-best-view computation failed.
    #[error("next best view: {0}")]
    Nbv(#[from] NbvError),
    /// The planner could not be set up.
    #[error("planner: {0}")]
    Planning(#[from] PlanningError),
    /// A view's data could not be prepared for the registration.
    #[error("registration input: {0}")]
    Registration(#[from] RegistrationError),
    /// The views could not be fused into a surface.
    #[error("surface: {0}")]
    Surface(#[from] crate::surface::SurfaceError),
}
