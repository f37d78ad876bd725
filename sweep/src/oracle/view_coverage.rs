//! [`SurfaceSamples`]: an object's surface samples as the report's coverage draws them,
//! and which of them a set of points covers; [`camera_points`]: what the Dinast sees from
//! one pose in truth, without noise and without dropouts.

use crate::report::{COVERAGE_SAMPLES, COVERAGE_TOLERANCE};
use nalgebra::{Point3, Vector3};
use nbv_core::cloud::near_mask;
use nbv_core::evaluation::sample_surface_with_normals;
use nbv_core::math::Pose;
use nbv_core::mesh::TriMesh;
use nbv_sim::sensors::CameraModel;
use nbv_sim::world::TwinWorld;

/// Height (m) above the table top below which the report's coverage does not sample.
pub const FLOOR_ABOVE_TABLE: f64 = 0.005;

/// An object's surface samples above the table, with their normals and the box (grown by
/// the coverage tolerance) outside which no point can cover one.
#[derive(Debug, Clone, PartialEq)]
pub struct SurfaceSamples {
    /// The samples (world frame).
    pub points: Vec<Point3<f64>>,
    /// Their outward unit normals.
    pub normals: Vec<Vector3<f64>>,
    lo: Point3<f64>,
    hi: Point3<f64>,
}

impl SurfaceSamples {
    /// The report's samples of `mesh` (world frame) for a scene with seed `seed` and its
    /// table top at `table_top`; `None` when none lies above the table.
    pub fn of(mesh: &TriMesh, table_top: f64, seed: u64) -> Option<Self> {
        let (points, normals): (Vec<_>, Vec<_>) =
            sample_surface_with_normals(mesh, COVERAGE_SAMPLES, seed)
                .into_iter()
                .filter(|(p, _)| p.z > table_top + FLOOR_ABOVE_TABLE)
                .unzip();
        let first = points.first()?;
        let (mut lo, mut hi) = (*first, *first);
        for p in &points {
            lo = lo.inf(p);
            hi = hi.sup(p);
        }
        let grow = Vector3::repeat(COVERAGE_TOLERANCE);
        Some(Self {
            points,
            normals,
            lo: lo - grow,
            hi: hi + grow,
        })
    }

    /// The number of samples.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// Whether there is no sample.
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// Per sample, whether one of `points` lies within the coverage tolerance of it.
    pub fn covered_by(&self, points: &[Point3<f64>]) -> Vec<bool> {
        let near: Vec<Point3<f64>> = points
            .iter()
            .filter(|p| (0..3).all(|k| p[k] >= self.lo[k] && p[k] <= self.hi[k]))
            .copied()
            .collect();
        near_mask(&near, &self.points, COVERAGE_TOLERANCE)
    }

    /// Where Algorithm 2 would centre its sphere on the whole object: the samples'
    /// centroid across, the object's middle height above the table.
    pub fn centre(&self, table_top: f64) -> Point3<f64> {
        let n = self.points.len().max(1) as f64;
        let c = self
            .points
            .iter()
            .fold(Vector3::zeros(), |a, p| a + p.coords)
            / n;
        let top = self.hi.z - COVERAGE_TOLERANCE;
        Point3::new(c.x, c.y, 0.5 * (table_top + top))
    }
}

/// The points the camera sees from world pose `pose` in `world` (ignoring the colliders
/// of robot frame `ignore_frame`): every pixel whose true return lies within the range and
/// is not certain to drop out (the grazing cut-off, the range limits), at its true place.
pub fn camera_points(
    world: &TwinWorld,
    camera: &CameraModel,
    ignore_frame: Option<usize>,
    pose: &Pose,
) -> Vec<Point3<f64>> {
    let [min, max] = camera.spec.range;
    camera
        .cast(world, pose, ignore_frame)
        .pixels
        .iter()
        .flatten()
        .filter(|p| p.dropout < 1.0 && p.distance >= min && p.distance <= max)
        .map(|p| p.truth.point)
        .collect()
}
