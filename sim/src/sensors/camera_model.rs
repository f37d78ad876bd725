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
//!
//! A capture is two steps: [`CameraModel::cast`] casts the rays and keeps, per pixel, the
//! noise-free return (true range `d`, `σ(d)`, the dropout probability at `d` and `a`, the
//! truth), a [`TrueFrame`]; [`CameraModel::draw`] draws one acquisition's noise and
//! dropouts from it. The rig ([`crate::rig`]) casts once per standstill of the arm and
//! draws every frame of a burst from that one [`TrueFrame`]:
//! - **shared per standstill** (until the arm next moves or teleports): the true sensor
//!   pose (with the view error, as before) and so every pixel's `d`, `a`, `σ(d)`, dropout
//!   probability and truth;
//! - **drawn per frame**: each pixel's `n` and its dropout draw, from the frame's own
//!   acquisition streams as above — independent across frames, and exactly the values an
//!   uncached capture draws, so a cached frame is bit-identical to casting it anew.

use super::AcquisitionId;
use crate::seeds::{self, Stream};
use crate::world::TwinWorld;
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
        let k = self.noise.range_sigma_exponent;
        // d¹ = d exactly: the common linear model without a `powf` per pixel.
        let scale = if k == 1.0 { d } else { d.powf(k) };
        self.noise.range_sigma_at_1m * scale
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
    /// own housing): [`Self::cast`] then [`Self::draw`].
    pub fn capture(
        &self,
        world: &TwinWorld,
        pose: &Pose,
        ignore_frame: Option<usize>,
        time: f64,
        id: AcquisitionId,
    ) -> DepthFrame {
        self.draw(&self.cast(world, pose, ignore_frame), time, id)
    }

    /// The noise-free part of a frame from the true sensor pose `pose`: every pixel's ray
    /// cast through `world` (ignoring the colliders of robot frame `ignore_frame`), with
    /// what the noise model needs per pixel. Rows are cast in parallel.
    pub fn cast(&self, world: &TwinWorld, pose: &Pose, ignore_frame: Option<usize>) -> TrueFrame {
        let (w, h) = (self.spec.width, self.spec.height);
        let reach = self.reach();
        // Below the grazing ramp's start the incidence does not matter: no `acos` there.
        let cos_start = self.noise.grazing_start_deg.to_radians().cos();
        let pixels = world.cast_pinhole_map(
            pose,
            &self.spec,
            reach,
            ignore_frame,
            |_, _, hit, norm, dir| {
                let cos = (-dir.dot(&hit.normal)).clamp(-1.0, 1.0);
                let incidence = if cos > cos_start { 0.0 } else { cos.acos() };
                TruePixel {
                    distance: hit.distance,
                    sigma: self.sigma(hit.distance),
                    dropout: self.dropout_probability(hit.distance, incidence),
                    norm,
                    truth: TruthHit {
                        label: hit.label,
                        point: hit.point,
                    },
                }
            },
        );
        TrueFrame {
            pose: *pose,
            width: w,
            height: h,
            pixels,
        }
    }

    /// Acquisition `id` at rig time `time` from the noise-free frame `truth`: each pixel's
    /// range noise and dropout drawn from the acquisition's own streams (see the module
    /// doc). Rows are drawn in parallel; the result does not depend on the thread count.
    pub fn draw(&self, truth: &TrueFrame, time: f64, id: AcquisitionId) -> DepthFrame {
        let (w, h) = (truth.width, truth.height);
        let [min, max] = self.spec.range;
        let mut depth = vec![f32::NAN; truth.pixels.len()];
        let mut hits: Vec<Option<TruthHit>> = vec![None; truth.pixels.len()];
        let row = w.max(1);
        depth
            .par_chunks_mut(row)
            .zip(hits.par_chunks_mut(row))
            .zip(truth.pixels.par_chunks(row))
            .enumerate()
            .for_each(|(v, ((depth, hits), pixels))| {
                let mut rng = seeds::rng(id.seed, Stream::CameraRow, id.index, v as u64);
                for ((d, t), pixel) in depth.iter_mut().zip(hits.iter_mut()).zip(pixels) {
                    let n: f64 = StandardNormal.sample(&mut rng);
                    let keep: f64 = rng.random();
                    let Some(p) = pixel else { continue };
                    if keep < p.dropout {
                        continue;
                    }
                    let r = p.distance + p.sigma * n;
                    if r < min || r > max {
                        continue;
                    }
                    *d = (r / p.norm) as f32;
                    *t = Some(p.truth);
                }
            });
        DepthFrame {
            time,
            width: w,
            height: h,
            depth,
            truth: Some(hits),
        }
    }

    /// How far a ray is cast: the far range limit plus six σ there (a return beyond the
    /// limit may be reported inside it).
    fn reach(&self) -> f64 {
        let max = self.spec.range[1];
        max + 6.0 * self.sigma(max)
    }
}

/// The noise-free return of one pixel: what the noise model needs to draw a frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TruePixel {
    /// True range along the ray (m).
    pub distance: f64,
    /// σ of the range noise at that range ([`CameraModel::sigma`]).
    pub sigma: f64,
    /// Dropout probability ([`CameraModel::dropout_probability`] at the range and the
    /// incidence angle).
    pub dropout: f64,
    /// Length of the pixel's unnormalised ray ([`DepthCameraSpec::pixel_ray`]): range / norm
    /// is the depth along the optical axis.
    pub norm: f64,
    /// What the ray hit, and where.
    pub truth: TruthHit,
}

/// The noise-free frame from one true sensor pose: per pixel (row-major) the return of its
/// ray, `None` where the ray meets nothing within reach.
#[derive(Debug, Clone, PartialEq)]
pub struct TrueFrame {
    /// The true sensor pose it was cast from (world frame).
    pub pose: Pose,
    /// Width, pixels.
    pub width: usize,
    /// Height, pixels.
    pub height: usize,
    /// Per pixel, row-major.
    pub pixels: Vec<Option<TruePixel>>,
}
