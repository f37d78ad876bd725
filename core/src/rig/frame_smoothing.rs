//! [`smooth_frame`]: an averaged depth frame's range noise taken down further by a local
//! plane fit in image space, as range-image pipelines do before ICP (KinectFusion's
//! bilateral filter; here an edge-gated least-squares plane).
//!
//! Why: the camera's noise lies along its rays and is an order of magnitude above the
//! laser's (σ ≈ 4 % of range, 6 mm at 0.45 m after eight frames). Matched to the laser's
//! surface of a curved object, a point displaced by `δ` along a ray at incidence `θ` sits
//! `−δ·cos θ + δ²·sin²θ / 2R` off a surface of radius `R`: the noisy view looks inflated by
//! `σ²·sin²θ / 2R` and the registration pushes it into the object to compensate (on the
//! paper scenes, 1–3 mm along the optical axis). The bias grows with σ², so a fit over
//! a `(2h+1)²` window (σ/5 for `h = 2`) removes nearly all of it, while the fit's own
//! bias on a curved surface is of the window's size squared over `2R` (≈ 0.2 mm there).
//!
//! Per valid pixel: the neighbours in the window whose depth is within [`GATE_SIGMAS`] σ of
//! the centre's, σ the noise of a depth difference (`√2·σ(z)` for the frame's per-pixel
//! `σ(z)`; other surfaces across a depth edge stay out), a plane `z = a + b·du + c·dv`
//! fitted to them, and the centre's depth replaced by `a` — when at least
//! [`MIN_NEIGHBOURS`] took part and the fit is well conditioned; otherwise the pixel keeps
//! its depth. Invalid pixels stay invalid; the truth is unchanged. Rows run in parallel;
//! the result does not depend on the thread count.

use nalgebra::{Matrix3, Vector3};
use rayon::prelude::*;

use super::DepthFrame;

/// Valid pixels (the centre included) a fit needs.
pub const MIN_NEIGHBOURS: usize = 6;

/// How many σ of a depth difference a neighbour may be off the centre's depth.
pub const GATE_SIGMAS: f64 = 3.0;

/// `frame` with every valid depth replaced by the edge-gated plane fit over the
/// `(2·half + 1)²` window around it; `sigma(z)` is the frame's range noise (m) at depth `z`,
/// and a neighbour takes part within [`GATE_SIGMAS`]·√2·`sigma(z)` of the centre's depth
/// `z`. `half = 0` returns the frame unchanged.
///
/// ```
/// use nbv_core::rig::{DepthFrame, smooth_frame};
/// // A tilted plane with alternating ±2 mm noise; a 5-pixel step at column 4 (an edge).
/// let (w, h) = (8, 6);
/// let depth: Vec<f32> = (0..w * h)
///     .map(|i| {
///         let (u, v) = (i % w, i / w);
///         let plane = 0.5 + 0.001 * u as f32 + 0.002 * v as f32;
///         let noise = if (u + v) % 2 == 0 { 0.002 } else { -0.002 };
///         plane + noise + if u >= 4 { 0.1 } else { 0.0 }
///     })
///     .collect();
/// let frame = DepthFrame { time: 0.0, width: w, height: h, depth, truth: None };
/// let smooth = smooth_frame(frame, 2, |_| 0.0025); // a neighbour within ~1 cm
/// // Pixel (1, 2): the plane's 0.505 with the noise mostly gone, the edge left out.
/// let z = smooth.depth[2 * w + 1];
/// assert!((z - 0.505).abs() < 0.0006, "{z}");
/// ```
pub fn smooth_frame(
    mut frame: DepthFrame,
    half: usize,
    sigma: impl Fn(f64) -> f64 + Sync,
) -> DepthFrame {
    let (w, h) = (frame.width, frame.height);
    if half == 0 || w == 0 || h == 0 {
        return frame;
    }
    let source = frame.depth.clone();
    let at = |u: usize, v: usize| f64::from(source[v * w + u]);
    frame
        .depth
        .par_chunks_mut(w)
        .enumerate()
        .for_each(|(v, row)| {
            for (u, out) in row.iter_mut().enumerate() {
                let z0 = at(u, v);
                if !z0.is_finite() {
                    continue;
                }
                let g = GATE_SIGMAS * std::f64::consts::SQRT_2 * sigma(z0);
                // Normal equations of dz = a + b·du + c·dv (dz from the centre's depth):
                // n, Σdu, Σdv, Σdu², Σdu·dv, Σdv², Σdz, Σdz·du, Σdz·dv.
                let mut s = [0.0f64; 9];
                for y in v.saturating_sub(half)..(v + half + 1).min(h) {
                    for x in u.saturating_sub(half)..(u + half + 1).min(w) {
                        let dz = at(x, y) - z0;
                        if !dz.is_finite() || dz.abs() > g {
                            continue;
                        }
                        let (du, dv) = (x as f64 - u as f64, y as f64 - v as f64);
                        s[0] += 1.0;
                        s[1] += du;
                        s[2] += dv;
                        s[3] += du * du;
                        s[4] += du * dv;
                        s[5] += dv * dv;
                        s[6] += dz;
                        s[7] += dz * du;
                        s[8] += dz * dv;
                    }
                }
                if (s[0] as usize) < MIN_NEIGHBOURS {
                    continue;
                }
                let m = Matrix3::new(s[0], s[1], s[2], s[1], s[3], s[4], s[2], s[4], s[5]);
                // A window that degenerates to a line (a one-pixel-wide strip) keeps its depth.
                if m.determinant() < 1e-6 * s[0].powi(3) {
                    continue;
                }
                if let Some(fit) = m.try_inverse().map(|i| i * Vector3::new(s[6], s[7], s[8])) {
                    *out = (z0 + fit[0]) as f32;
                }
            }
        });
    frame
}
