//! [`estimate_range_sigma`]: the range noise of views that come without a sensor model (a
//! user's scans), read from the views themselves.
//!
//! On a surface that is smooth at the scale of a few point spacings, the spread of a
//! point's `k` nearest neighbours across their best-fit plane is the noise: the smallest
//! eigenvalue of the neighbourhood's covariance is `σ²·(k − 3)/k` for Gaussian noise of σ
//! along the normal (the plane's three parameters absorb three of the k samples). The
//! estimate is the median over a sample of each view's points, scaled back by `k/(k − 3)`,
//! then the median over the views (each view's on its own thread). The surface's curvature adds to it (a neighbourhood of
//! radius r on a surface of radius R bends by r²/2R): it is an upper estimate on curved
//! or sparsely sampled objects, which is the safe side for a registration's noise model.

use rayon::prelude::*;

use super::local_planes::{NOISE_NEIGHBOURS, sampled_local_planes};
use crate::cloud::PointCloud;

/// Points sampled per view.
const SAMPLES: usize = 1000;

/// The range noise σ (m) of `views`, `None` when no view has enough finite points.
///
/// ```
/// use nbv_core::cloud::PointCloud;
/// use nbv_core::registration::estimate_range_sigma;
/// use nalgebra::Point3;
/// // A 10 cm square sampled every 2 mm with ±0.5 mm of alternating noise along its normal.
/// let pts = (0..2500)
///     .map(|i| {
///         let (u, v) = ((i % 50) as f64 * 0.002, (i / 50) as f64 * 0.002);
///         Point3::new(u, v, if (i % 50 + i / 50) % 2 == 0 { 0.0005 } else { -0.0005 })
///     })
///     .collect();
/// let sigma = estimate_range_sigma(&[PointCloud::from_points(pts)]).unwrap();
/// assert!((sigma - 0.0005).abs() < 0.0001, "{sigma}");
/// ```
pub fn estimate_range_sigma(views: &[PointCloud]) -> Option<f64> {
    let mut per_view: Vec<f64> = views.par_iter().filter_map(view_sigma).collect();
    median(&mut per_view)
}

/// One view's estimate.
fn view_sigma(view: &PointCloud) -> Option<f64> {
    let mut spreads: Vec<f64> = sampled_local_planes(view, SAMPLES)?
        .iter()
        .map(|p| p.spread)
        .collect();
    let k = NOISE_NEIGHBOURS as f64;
    median(&mut spreads).map(|v| (v * k / (k - 3.0)).sqrt())
}

/// The median of `values` (the upper of the two middle ones), `None` for none.
fn median(values: &mut [f64]) -> Option<f64> {
    if values.is_empty() {
        return None;
    }
    values.sort_by(f64::total_cmp);
    Some(values[values.len() / 2])
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Point3, Vector3};
    use proptest::prelude::*;
    use rand::SeedableRng;
    use rand_distr::{Distribution, Normal};

    /// A sphere of radius `r` sampled on a latitude-longitude grid, with Gaussian noise
    /// of `sigma` along the radius.
    fn noisy_sphere(r: f64, sigma: f64, seed: u64) -> PointCloud {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let noise = Normal::new(0.0, sigma).unwrap();
        let mut pts = Vec::new();
        for i in 1..60 {
            for j in 0..120 {
                let (t, f) = (
                    i as f64 / 60.0 * std::f64::consts::PI,
                    j as f64 / 120.0 * std::f64::consts::TAU,
                );
                let u = Vector3::new(t.sin() * f.cos(), t.sin() * f.sin(), t.cos());
                pts.push(Point3::from(u * (r + noise.sample(&mut rng))));
            }
        }
        PointCloud::from_points(pts)
    }

    #[test]
    fn too_few_points_give_none() {
        let few = PointCloud::from_points(vec![Point3::origin(); 10]);
        assert_eq!(estimate_range_sigma(&[few]), None);
        assert_eq!(estimate_range_sigma(&[]), None);
    }

    proptest! {
        /// On a sphere of 10 cm sampled every ~5 mm, the estimate is the noise within a
        /// third (plus the sampled curvature's share, under 0.1 mm).
        #[test]
        fn reads_the_noise_of_a_curved_surface(sigma in 0.0003f64..0.003, seed in 0u64..100) {
            let est = estimate_range_sigma(&[noisy_sphere(0.1, sigma, seed)]).unwrap();
            prop_assert!(est > 0.67 * sigma && est < 1.33 * sigma + 0.0001, "σ {sigma}, estimate {est}");
        }
    }
}
