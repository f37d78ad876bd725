//! Merging registered views into one model cloud, each point tagged with its view.

use super::{Registration, RegistrationError};
use crate::cloud::PointCloud;

impl Registration {
    /// All `views` moved by their refined poses into the world frame and concatenated, in
    /// view order, with the `views` column set to each point's view index. Columns that
    /// not every view has are dropped (see [`PointCloud::extend`]).
    ///
    /// ```
    /// use nbv_core::cloud::PointCloud;
    /// use nbv_core::registration::{GpaReport, MethodReport, Registration, StopReason};
    /// use nalgebra::{Isometry3, Point3};
    /// let views = [PointCloud::from_points(vec![Point3::origin()]),
    ///              PointCloud::from_points(vec![Point3::origin(), Point3::new(1.0, 0.0, 0.0)])];
    /// let reg = Registration {
    ///     poses: vec![Isometry3::identity(), Isometry3::translation(0.0, 0.0, 2.0)],
    ///     converged: true,
    ///     rms: Some(0.0),
    ///     report: MethodReport::Gpa(GpaReport {
    ///         iterations: 0, inner_iterations: 0, stop: StopReason::Converged, rms: Some(0.0),
    ///         mse_history: vec![], independent_sets: 0, linked_points: 0, points_in_sets: 0,
    ///         correspondences_per_view: vec![0, 0], unconnected_views: vec![],
    ///     }),
    /// };
    /// let model = reg.merged(&views).unwrap();
    /// assert_eq!(model.points[2], Point3::new(1.0, 0.0, 2.0));
    /// assert_eq!(model.views.as_deref(), Some(&[0, 1, 1][..]));
    /// ```
    pub fn merged(&self, views: &[PointCloud]) -> Result<PointCloud, RegistrationError> {
        if views.len() != self.poses.len() {
            return Err(RegistrationError::PoseCountMismatch {
                views: views.len(),
                poses: self.poses.len(),
            });
        }
        let mut model = PointCloud::default();
        for (v, (view, pose)) in views.iter().zip(&self.poses).enumerate() {
            let mut moved = view.clone();
            moved.transform(pose);
            moved.views = Some(vec![v as u32; moved.len()]);
            model.extend(&moved);
        }
        Ok(model)
    }
}
