//! Measures of an exploration against ground truth: how much of an object's true surface
//! a model covers ([`surface_coverage`]), how much of a model lies on it
//! ([`model_precision`]), both and their F-score and the Chamfer distance at a stated
//! tolerance — the one figure misalignment cannot raise ([`model_quality`]) — how far
//! registered points lie from the true surface points they sampled ([`point_error`]), and
//! how far registration leaves each view from its true place, free of sensor noise
//! ([`alignment_error`]).

mod alignment_error;
mod mesh_quality;
mod model_precision;
mod model_quality;
mod point_error;
mod surface_coverage;

pub use alignment_error::alignment_error;
pub use mesh_quality::{
    MESH_TOLERANCES, MeshQuality, ToleranceScores, mesh_quality, tolerance_scores,
};
pub use model_precision::model_precision;
pub use model_quality::{ModelQuality, f_score, model_quality, quality_samples};
pub use point_error::{PointError, point_error};
pub use surface_coverage::{
    Coverage, sample_surface, sample_surface_with_normals, surface_coverage, surface_coverage_curve,
};
