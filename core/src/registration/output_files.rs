//! The files of a registration of view files (`nbv register`): the merged model, the poses
//! file and, if asked, the full report — written together or not at all
//! ([`RegistrationFiles::write`]).

use super::Registration;
use crate::cloud::PointCloud;
use crate::cloud::io::{
    CloudFormat, CloudIoError, StagedFileError, StagedFiles, WriteOptions, write_pcd, write_ply,
};
use crate::math::pose_file::poses_json;
use std::path::Path;

/// An error of [`RegistrationFiles::write`].
#[derive(Debug, thiserror::Error)]
pub enum RegistrationFileError {
    /// The model's path has no known cloud extension.
    #[error(transparent)]
    Format(Box<CloudIoError>),
    /// A file could not be written or moved into place.
    #[error(transparent)]
    Staged(#[from] StagedFileError),
    /// The report could not be serialised.
    #[error(transparent)]
    Json(#[from] serde_json::Error),
}

/// Where a registration's files go.
#[derive(Debug, Clone, Copy)]
pub struct RegistrationFiles<'a> {
    /// The merged model, PLY or PCD by its extension (binary, 32-bit floats, each point
    /// tagged with its view).
    pub model: &'a Path,
    /// The poses: each view's file name to its 4×4 view-to-world transform
    /// ([`poses_json`]).
    pub poses: &'a Path,
    /// The full registration report as pretty JSON, if asked.
    pub report: Option<&'a Path>,
}

impl RegistrationFiles<'_> {
    /// Writes `model` (the views merged by `registration`), the poses of the views `names`
    /// and the report: each under a temporary name first, then all moved into place; on
    /// any error none of them is left.
    ///
    /// ```
    /// use nbv_core::cloud::PointCloud;
    /// use nbv_core::registration::{
    ///     GpaReport, MethodReport, Registration, RegistrationFiles, StopReason,
    /// };
    /// use nalgebra::{Isometry3, Point3};
    /// let dir = std::env::temp_dir().join(format!("nbv-regfiles-doc-{}", std::process::id()));
    /// std::fs::create_dir_all(&dir).unwrap();
    /// let views = [PointCloud::from_points(vec![Point3::origin()]),
    ///              PointCloud::from_points(vec![Point3::new(1.0, 0.0, 0.0)])];
    /// let registration = Registration {
    ///     poses: vec![Isometry3::identity(), Isometry3::translation(0.0, 0.0, 2.0)],
    ///     converged: true,
    ///     rms: Some(0.0),
    ///     report: MethodReport::Gpa(GpaReport {
    ///         iterations: 0, inner_iterations: 0, stop: StopReason::Converged, rms: Some(0.0),
    ///         mse_history: vec![], independent_sets: 0, linked_points: 0, points_in_sets: 0,
    ///         correspondences_per_view: vec![0, 0], unconnected_views: vec![],
    ///     }),
    /// };
    /// let files = RegistrationFiles {
    ///     model: &dir.join("model.ply"),
    ///     poses: &dir.join("poses.json"),
    ///     report: None,
    /// };
    /// let names = ["a.ply".to_string(), "b.ply".to_string()];
    /// files.write(&names, &registration, &registration.merged(&views).unwrap()).unwrap();
    /// let poses = std::fs::read_to_string(dir.join("poses.json")).unwrap();
    /// assert!(poses.contains("\"b.ply\""));
    /// assert_eq!(nbv_core::cloud::read_cloud(dir.join("model.ply")).unwrap().len(), 2);
    /// std::fs::remove_dir_all(&dir).unwrap();
    /// ```
    pub fn write(
        &self,
        names: &[String],
        registration: &Registration,
        model: &PointCloud,
    ) -> Result<(), RegistrationFileError> {
        let mut staged = StagedFiles::default();
        let format = CloudFormat::from_path(self.model)
            .map_err(|e| RegistrationFileError::Format(Box::new(e)))?;
        staged.write(self.model, |w| match format {
            CloudFormat::Ply => write_ply(w, model, &WriteOptions::default()),
            CloudFormat::Pcd => write_pcd(w, model, &WriteOptions::default()),
        })?;
        let poses = poses_json(names, &registration.poses);
        staged.write(self.poses, |w| {
            w.write_all(&poses).map_err(CloudIoError::from)
        })?;
        if let Some(path) = self.report {
            let mut report = serde_json::to_vec_pretty(registration)?;
            report.push(b'\n');
            staged.write(path, |w| w.write_all(&report).map_err(CloudIoError::from))?;
        }
        Ok(staged.commit()?)
    }
}
