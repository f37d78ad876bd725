//! [`LaserModel`]: the simulated SICK LMS400 — one line of a 2-D fan cast through the twin
//! world from a given (true) sensor pose, with Gaussian range noise.
//!
//! Model: beam `i` leaves the sensor origin along
//! [`LineScannerSpec::beam_direction`]; the first surface it meets (robot links included,
//! except the sensor's own housing) is at the true range `d`; the sensor reports
//! `d + σ·n`, `n ~ N(0, 1)`, and only if that reported range lies within
//! `spec.range` (the LMS400's range gate acts on what it measures). A beam that meets
//! nothing reports NaN. The noise of line `k` of acquisition `a` comes from a ChaCha8
//! stream seeded by `(scene seed, a, k)`; beam `i` takes the `i`-th draw, whether it hits
//! or not, so the result does not depend on the thread count. A line is instantaneous (the
//! mirror's 1/190 s sweep is not modelled).

use super::AcquisitionId;
use crate::seeds::{self, Stream};
use crate::world::TwinWorld;
use nalgebra::Point3;
use nbv_core::math::Pose;
use nbv_core::rig::{LineScannerSpec, ScanLine, TruthHit};
use rand_distr::{Distribution, StandardNormal};
use rayon::prelude::*;

/// A simulated line scanner: its spec and its range noise.
#[derive(Debug, Clone, PartialEq)]
pub struct LaserModel {
    /// Geometry and timing.
    pub spec: LineScannerSpec,
    /// Standard deviation of the range noise along the beam (m).
    pub range_sigma: f64,
}

impl LaserModel {
    /// The model of a scene's `[sensors.mid_range]`.
    pub fn from_scene(sensor: &nbv_scenes::schema::MidRangeSensor) -> Self {
        Self {
            spec: sensor.spec(),
            range_sigma: sensor.noise.range_sigma,
        }
    }

    /// Casts line `line` of acquisition `id` from the true sensor pose `pose`
    /// (world frame) at rig time `time`, ignoring the colliders of robot frame
    /// `ignore_frame` (the scanner's own housing). Beams are cast in parallel.
    pub fn cast_line(
        &self,
        world: &TwinWorld,
        pose: &Pose,
        ignore_frame: Option<usize>,
        time: f64,
        id: AcquisitionId,
        line: u64,
    ) -> ScanLine {
        let beams = self.spec.beams();
        let mut rng = seeds::rng(id.seed, Stream::LaserLine, id.index, line);
        let noise: Vec<f64> = (0..beams)
            .map(|_| StandardNormal.sample(&mut rng))
            .collect();
        let [min, max] = self.spec.range;
        let reach = max + 6.0 * self.range_sigma;
        let origin = Point3::from(pose.translation.vector);
        let returns: Vec<(f32, Option<TruthHit>)> = noise
            .par_iter()
            .enumerate()
            .map_init(
                || world.ray_caster(),
                |caster, (i, n)| {
                    let dir = pose.rotation * self.spec.beam_direction(i);
                    let Some(hit) = caster.cast(&origin, &dir, reach, ignore_frame) else {
                        return (f32::NAN, None);
                    };
                    let r = hit.distance + self.range_sigma * n;
                    if r < min || r > max {
                        return (f32::NAN, None);
                    }
                    let truth = TruthHit {
                        label: hit.label,
                        point: hit.point,
                    };
                    (r as f32, Some(truth))
                },
            )
            .collect();
        let (ranges, truth) = returns.into_iter().unzip();
        ScanLine {
            time,
            start_angle: -0.5 * self.spec.fov,
            angle_step: self.spec.resolution,
            ranges,
            truth: Some(truth),
        }
    }
}
