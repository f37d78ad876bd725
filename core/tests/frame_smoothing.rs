//! The edge-gated plane fit of an averaged depth frame (`nbv_core::rig::smooth_frame`):
//! a plane comes back as it was, the noise falls by the window's size, a depth edge keeps
//! the two sides apart, and no pixel changes validity.

use nbv_core::rig::{DepthFrame, smooth_frame};
use proptest::prelude::*;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;

const W: usize = 40;
const H: usize = 30;

/// A `W × H` frame of depth `z(u, v)`, NaN where `hole(u, v)`.
fn frame(z: impl Fn(usize, usize) -> f64, hole: impl Fn(usize, usize) -> bool) -> DepthFrame {
    let depth = (0..W * H)
        .map(|i| {
            let (u, v) = (i % W, i / W);
            if hole(u, v) { f32::NAN } else { z(u, v) as f32 }
        })
        .collect();
    DepthFrame {
        time: 0.0,
        width: W,
        height: H,
        depth,
        truth: None,
    }
}

fn rms(a: &[f64]) -> f64 {
    (a.iter().map(|x| x * x).sum::<f64>() / a.len() as f64).sqrt()
}

proptest! {
    /// A noise-free plane, any tilt, with holes: every valid pixel keeps its depth (to f32
    /// rounding), every hole stays a hole.
    #[test]
    fn a_plane_comes_back_as_it_was(
        z0 in 0.2f64..0.8,
        a in -0.004f64..0.004,
        b in -0.004f64..0.004,
        half in 1usize..4,
        holes in proptest::collection::vec((0usize..W, 0usize..H), 0..60),
    ) {
        let plane = |u: usize, v: usize| z0 + a * u as f64 + b * v as f64;
        let hole = |u: usize, v: usize| holes.contains(&(u, v));
        let f = frame(plane, hole);
        let s = smooth_frame(f.clone(), half, |_| 0.005); // gate ~2 cm
        for (i, (&before, &after)) in f.depth.iter().zip(&s.depth).enumerate() {
            prop_assert_eq!(before.is_nan(), after.is_nan(), "pixel {}", i);
            if before.is_finite() {
                prop_assert!((before - after).abs() < 2e-6, "pixel {}: {} -> {}", i, before, after);
            }
        }
    }
}

/// Gaussian noise of σ on a tilted plane: a 5 × 5 fit leaves about σ/5 (asserted below
/// σ/3.5 away from the border, at three seeds).
#[test]
fn the_noise_falls_by_the_windows_size() {
    let sigma = 0.006;
    for seed in 0..3 {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let noise: Vec<f64> = (0..W * H)
            .map(|_| rng.sample::<f64, _>(StandardNormal) * sigma)
            .collect();
        let plane = |u: usize, v: usize| 0.45 + 0.001 * u as f64 - 0.0005 * v as f64;
        let f = frame(|u, v| plane(u, v) + noise[v * W + u], |_, _| false);
        let s = smooth_frame(f.clone(), 2, |_| sigma);
        let (mut raw, mut fit) = (Vec::new(), Vec::new());
        for v in 2..H - 2 {
            for u in 2..W - 2 {
                raw.push(f64::from(f.depth[v * W + u]) - plane(u, v));
                fit.push(f64::from(s.depth[v * W + u]) - plane(u, v));
            }
        }
        let (raw, fit) = (rms(&raw), rms(&fit));
        assert!(raw > 0.8 * sigma, "seed {seed}: raw {raw}");
        assert!(fit < sigma / 3.5, "seed {seed}: {raw} -> {fit}");
    }
}

/// A 10 cm step (a silhouette against the background), both sides noisy: no pixel is
/// pulled towards the other side — every smoothed depth stays within 1 cm of its own side.
#[test]
fn a_depth_edge_keeps_its_two_sides_apart() {
    let sigma = 0.004;
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let noise: Vec<f64> = (0..W * H)
        .map(|_| rng.sample::<f64, _>(StandardNormal) * sigma)
        .collect();
    let side = |u: usize| if u < W / 2 { 0.40 } else { 0.50 };
    let f = frame(|u, v| side(u) + noise[v * W + u], |_, _| false);
    let s = smooth_frame(f.clone(), 2, |_| sigma);
    for v in 0..H {
        for u in 0..W {
            let z = f64::from(s.depth[v * W + u]);
            assert!((z - side(u)).abs() < 0.01, "({u}, {v}): {z}");
        }
    }
}

/// Half-width 0 is the identity.
#[test]
fn half_width_zero_leaves_the_frame() {
    let f = frame(
        |u, v| 0.3 + 0.01 * ((u * v) % 7) as f64,
        |u, v| (u + v) % 5 == 0,
    );
    let s = smooth_frame(f.clone(), 0, |_| 0.3);
    assert_eq!(
        f.depth.iter().map(|d| d.to_bits()).collect::<Vec<_>>(),
        s.depth.iter().map(|d| d.to_bits()).collect::<Vec<_>>()
    );
}
