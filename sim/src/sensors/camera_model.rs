//! [`CameraModel`]: the simulated Dinast IPA-1110 — an organised depth frame cast through
//! the twin world from a given (true) sensor pose, with range-dependent noise and dropouts.
//!
//! Model (parameters from the scene's `[sensors.short_range]`, see
//! [`CameraNoise`](nbv_scenes::schema::CameraNoise)): pixel `(u, v)` looks along
//! [`DepthCameraSpec::pixel_ray`] (pinhole, square pixels; the 80° field of view is the
//! *horizontal* one across 320 pixels, so the vertical one is 2·atan(120/f) ≈ 64.4°). The
//! first surface on the ray is at the true range `d` (along the ray) with incidence angle
//! `a` between the ray and the surface normal. The pixel
//! - drops out with probability `max(p₀, grazing(a), near_limit(d))`;
//! - otherwise reports the range `d + σ(d)·n`, `σ(d) = σ₁·d^k`, `n ~ N(0, 1)`, valid only
//!   within `spec.range` (gated on the reported range);
//! - stores it as depth `z` (optical axis), NaN when invalid or when the ray meets nothing.
//!
//! Row `v` of acquisition `a` draws from a ChaCha8 stream seeded by `(scene seed, a, v)`:
//! two draws per pixel (noise, then dropout), in column order, hit or not. Rows are cast in
//! parallel; the result does not depend on the thread count.

use super::AcquisitionId;
use crate::seeds::{self, Stream};
use crate::world::TwinWorld;
use nalgebra::Point3;
use nbv_core::math::Pose;
use nbv_core::rig::{DepthCameraSpec, DepthFrame, TruthHit};
use nbv_scenes::schema::CameraNoise;
use rand::Rng;
use rand_distr::{Distribution, StandardNormal};
use rayon::prelude::*;

/// A simulated depth camera: its spec and its noise model.
#[derive(Debug, Clone, PartialEq)]
pub struct CameraModel {
    /// Geometry and range.
    pub spec: DepthCameraSpec,
    /// Noise and dropouts.
    pub noise: CameraNoise,
    /// Frames per second (the rig clock advances one period per capture).
    pub frame_rate_hz: f64,
}

impl CameraModel {
    /// The model of a scene's `[sensors.short_range]`.
    pub fn from_scene(sensor: &nbv_scenes::schema::ShortRangeSensor) -> Self {
        Self {
            spec: sensor.spec(),
            noise: sensor.noise.clone(),
            frame_rate_hz: sensor.frame_rate_hz,
        }
    }

    /// σ of the range noise at true range `d` (m).
    pub fn sigma(&self, d: f64) -> f64 {
        self.noise.range_sigma_at_1m * d.powf(self.noise.range_sigma_exponent)
    }

    /// Probability that a return at true range `d` and incidence angle `incidence` (rad,
    /// between the ray and the surface normal) drops out.
    pub fn dropout_probability(&self, d: f64, incidence: f64) -> f64 {
        let n = &self.noise;
        let a = incidence.to_degrees();
        let grazing = if a >= n.grazing_cutoff_deg {
            1.0
        } else if a <= n.grazing_start_deg {
            0.0
        } else {
            (a - n.grazing_start_deg) / (n.grazing_cutoff_deg - n.grazing_start_deg)
        };
        let [min, max] = self.spec.range;
        let near = if n.range_margin > 0.0 {
            let to_limit = (d - min).min(max - d);
            (1.0 - to_limit / n.range_margin).clamp(0.0, 1.0)
        } else {
            0.0
        };
        n.dropout_probability.max(grazing).max(near)
    }

    /// Captures acquisition `id` from the true sensor pose `pose` (world frame) at
    /// rig time `time`, ignoring the colliders of robot frame `ignore_frame` (the camera's
    /// own housing).
    pub fn capture(
        &self,
        world: &TwinWorld,
        pose: &Pose,
        ignore_frame: Option<usize>,
        time: f64,
        id: AcquisitionId,
    ) -> DepthFrame {
        let (w, h) = (self.spec.width, self.spec.height);
        let [min, max] = self.spec.range;
        let reach = max + 6.0 * self.sigma(max);
        let origin = Point3::from(pose.translation.vector);
        let rows: Vec<Vec<(f32, Option<TruthHit>)>> = (0..h)
            .into_par_iter()
            .map_init(
                || world.ray_caster(),
                |caster, v| {
                    let mut rng = seeds::rng(id.seed, Stream::CameraRow, id.index, v as u64);
                    (0..w)
                        .map(|u| {
                            let n: f64 = StandardNormal.sample(&mut rng);
                            let keep: f64 = rng.random();
                            let ray = self.spec.pixel_ray(u, v);
                            let norm = ray.norm();
                            let dir = pose.rotation * (ray / norm);
                            let Some(hit) = caster.cast(&origin, &dir, reach, ignore_frame) else {
                                return (f32::NAN, None);
                            };
                            let incidence = (-dir.dot(&hit.normal)).clamp(-1.0, 1.0).acos();
                            if keep < self.dropout_probability(hit.distance, incidence) {
                                return (f32::NAN, None);
                            }
                            let r = hit.distance + self.sigma(hit.distance) * n;
                            if r < min || r > max {
                                return (f32::NAN, None);
                            }
                            let truth = TruthHit {
                                label: hit.label,
                                point: hit.point,
                            };
                            ((r / norm) as f32, Some(truth))
                        })
                        .collect()
                },
            )
            .collect();
        let (depth, truth) = rows.into_iter().flatten().unzip();
        DepthFrame {
            time,
            width: w,
            height: h,
            depth,
            truth: Some(truth),
        }
    }
}
