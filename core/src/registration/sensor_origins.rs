//! [`assign_sensor_origins`]: where each of a user's views was taken from, when its file
//! does not say (no per-point origins) — what the MAP registration's noise along the rays
//! and its test of which way a surface faces need.
//!
//! Scanners' files, PCL's default VIEWPOINT and a ROS sensor frame put the sensor at the
//! frame's origin. A turntable's frame or an object frame a scanner's software exported
//! does not (the Stanford scans: the origin under the object). Under
//! [`SensorOrigin::Auto`] a view whose frame's origin stands behind the surface it saw
//! ([`estimate_view_direction`]) and among its points (within [`ORIGIN_AMONG_POINTS`]
//! times its radius about its centroid) is seen along its estimated direction instead.
//! The views are one layout: where one frame is found not to be a sensor's, none is taken
//! for one, and the views without a usable estimate get no sensor (isotropic noise). A
//! frame farther off is kept whatever the estimate says: the sign of a concave view's
//! estimate can be wrong (one view in four of the six generated users' sets).

use nalgebra::{Point3, Vector3};
use rayon::prelude::*;

use super::view_direction_estimate::estimate_view_direction;
use crate::cloud::PointCloud;

/// A frame's origin within this multiple of the view's radius about its centroid stands
/// among its points (the Stanford bunny's turntable frames: 0.98–1.18).
pub const ORIGIN_AMONG_POINTS: f64 = 1.5;

/// Where a view without per-point sensor origins was taken from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SensorOrigin {
    /// Its frame's origin, unless that stands behind its surface among its points (see
    /// the module doc).
    Auto,
    /// Its frame's origin.
    Frame,
    /// Unknown: no origins (isotropic noise, no test of which way a surface faces).
    Unknown,
}

/// Gives every view of `views` (each in its own frame) without per-point origins its
/// sensor by `rule`; returns the indices of the views seen along their estimated
/// direction (each point's origin 1 m along it).
///
/// ```
/// use nbv_core::cloud::PointCloud;
/// use nbv_core::registration::{SensorOrigin, assign_sensor_origins};
/// use nalgebra::Point3;
/// // The half of a 5 cm sphere that faces +z, in a frame at the sphere's centre.
/// let mut pts = Vec::new();
/// for i in -50..=50 {
///     for j in -50..=50 {
///         let (x, y) = (i as f64 * 0.001, j as f64 * 0.001);
///         if x * x + y * y < 0.05 * 0.05 {
///             pts.push(Point3::new(x, y, (0.05f64 * 0.05 - x * x - y * y).sqrt()));
///         }
///     }
/// }
/// let mut views = vec![PointCloud::from_points(pts)];
/// let mut framed = views.clone();
/// assert_eq!(assign_sensor_origins(&mut views, SensorOrigin::Auto), vec![0]);
/// let o = views[0].origins.as_ref().unwrap()[0] - views[0].points[0];
/// assert!(o.z > 0.99);
/// // Forced: the frame's origin.
/// assert!(assign_sensor_origins(&mut framed, SensorOrigin::Frame).is_empty());
/// assert_eq!(framed[0].origins.as_ref().unwrap()[0], Point3::origin());
/// ```
pub fn assign_sensor_origins(views: &mut [PointCloud], rule: SensorOrigin) -> Vec<usize> {
    let along: Vec<Option<Vector3<f64>>> = views
        .par_iter()
        .map(|view| {
            if view.origins.is_some() || rule != SensorOrigin::Auto || view.is_empty() {
                return None;
            }
            let centroid =
                view.points.iter().map(|p| p.coords).sum::<Vector3<f64>>() / view.len() as f64;
            let radius = view
                .points
                .iter()
                .map(|p| (p.coords - centroid).norm())
                .fold(0.0, f64::max);
            // A frame's origin away from the points is kept whatever the estimate says:
            // the estimate is made only for the others.
            if centroid.norm() >= ORIGIN_AMONG_POINTS * radius {
                return None;
            }
            let direction = estimate_view_direction(view)?;
            let behind = -centroid.dot(&direction) < 0.0;
            behind.then_some(direction.into_inner())
        })
        .collect();
    let frames_are_sensors = along.iter().all(Option::is_none);
    let mut seen_along = Vec::new();
    for (k, (view, along)) in views.iter_mut().zip(along).enumerate() {
        if view.origins.is_some() || rule == SensorOrigin::Unknown {
            continue;
        }
        view.origins = match along {
            Some(d) => {
                seen_along.push(k);
                Some(view.points.iter().map(|p| p + d).collect())
            }
            None if frames_are_sensors => Some(vec![Point3::origin(); view.len()]),
            None => None,
        };
    }
    seen_along
}
