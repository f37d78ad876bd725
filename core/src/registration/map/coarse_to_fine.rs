//! [`register_coarse_to_fine`]: the MAP registration of views whose initial poses are
//! several millimetres off their noise (a user's scans: no laser anchor, no pose prior).
//!
//! A MAP stage takes part only the points matched within a few σ of the noise, so at the
//! noise of a good scanner (0.3 mm) it sees too few matches to move views a centimetre
//! off, and its nearest points find the far side of thin parts. The stages here run at a
//! coarse σ first — the correspondence distance / 8 (3.75 mm at the default 3 cm), then
//! a quarter of it, until the views' own σ — each started where the last ended, every pose
//! prior kept on the initial poses. A coarse stage works on at most [`COARSE_POINTS`]
//! points per view, matches at most [`COARSE_PAIR_POINTS`] of them into each other view,
//! and stops when a step moves no view by a tenth of its σ: it has only to land within the
//! next stage's reach, which the views' shapes decide rather than the count of their
//! points (its objective at the initial poses is not evaluated either: nothing reads
//! it); the coarse stages share one preparation of their clouds and its nearest-point
//! caches. Each stage searches a point's nearest target point
//! only within the distance at which its kernel caps a residual between two points of its
//! σ (`outlier_sigmas · √(2σ² + σ_f²)`, at most `d_max`: 30, 11 and 5 mm on scans of 0.26 mm
//! noise at the default 3 cm), as ICP's coarse-to-fine schedules shrink the correspondence
//! distance; the freedom to slide along a plane and the overlap that pairs the views stay
//! `d_max`'s. Measured on rings and hand-held paths of scans 2° and 5 mm off: 0.07–0.23 mm
//! from the truth where one stage at the scans' σ ends millimetres off (docs/peers.md,
//! "Users' scans").

use super::preparation::MapPreparation;
use super::view_model::{RangeNoise, ViewModel};
use crate::cloud::PointCloud;
use crate::math::Pose;
use crate::registration::{
    Registration, RegistrationError, RegistrationParams, check_input, map, register_prepared_within,
};

/// Points per view in a coarse stage.
pub const COARSE_POINTS: usize = 1000;

/// Points of a view matched into each other view in a coarse stage (`map.pair_points` in
/// the fine one). Eleven other views then give a view 3300 residuals for its six unknowns.
/// Measured on 24 rings and hand-held paths of users' scans (docs/peers.md): 300 ends
/// every set where 600 does, 10–25 % sooner; 150 leaves a view of the mallet's hand-held
/// path 1.4° off.
pub const COARSE_PAIR_POINTS: usize = 300;

/// Lever (m) at which a coarse stage's rotation tolerance moves a point by its
/// translation tolerance.
const LEVER: f64 = 0.1;

/// The coarse stages' σ (m) above the views' `sigma`: the correspondence distance / 8,
/// each next a quarter of the last, while more than 1.5 σ.
///
/// ```
/// use nbv_core::registration::coarse_sigmas;
/// let s = coarse_sigmas(0.03, 0.0003);
/// assert_eq!(s, vec![0.00375, 0.0009375]);
/// assert!(coarse_sigmas(0.03, 0.005).is_empty());
/// ```
pub fn coarse_sigmas(max_distance: f64, sigma: f64) -> Vec<f64> {
    let mut stages = Vec::new();
    let mut s = max_distance / 8.0;
    while s > 1.5 * sigma {
        stages.push(s);
        s /= 4.0;
    }
    stages
}

/// The MAP registration ([`register_with_models`](crate::registration::register_with_models)
/// with `params.method` the MAP) from coarse to fine: the coarse stages of
/// [`coarse_sigmas`] below the correspondence distance and above the largest of the
/// models' σ at 1 m, then the models as given on every point. Errors as
/// [`register_prepared_from`] does.
pub fn register_coarse_to_fine(
    views: &[PointCloud],
    initial: &[Pose],
    models: &[ViewModel],
    params: &RegistrationParams,
) -> Result<Registration, RegistrationError> {
    check_input(views, initial, models, params)?;
    let sigma = models
        .iter()
        .map(|m| m.noise.sigma(1.0))
        .fold(0.0, f64::max);
    // The fine stage's preparation does not depend on the coarse stages' poses: it is
    // made beside them, on the threads their serial steps leave idle.
    let (start, prepared) = rayon::join(
        || coarse_stages(views, initial, models, params, sigma),
        || MapPreparation::new(views, models, params),
    );
    let (start, prepared) = (start?, prepared?);
    let reach = stage_distance(params, sigma);
    register_prepared_within(&prepared, views, initial, &start, models, params, reach)
}

/// The poses the coarse stages of [`register_coarse_to_fine`] end at, from `initial`, for
/// views whose largest σ at 1 m is `sigma`.
fn coarse_stages(
    views: &[PointCloud],
    initial: &[Pose],
    models: &[ViewModel],
    params: &RegistrationParams,
    sigma: f64,
) -> Result<Vec<Pose>, RegistrationError> {
    let coarse: Vec<PointCloud> = views.iter().map(|v| v.thinned(COARSE_POINTS)).collect();
    let mut start = initial.to_vec();
    // The coarse stages share their clouds: each stage's preparation is the last one's at
    // its own noise, with the nearest-point caches the last run left.
    let mut last: Option<MapPreparation> = None;
    for s in coarse_sigmas(params.max_correspondence_distance, sigma) {
        let staged: Vec<ViewModel> = models
            .iter()
            .map(|m| ViewModel {
                noise: RangeNoise::constant(s),
                prior: m.prior,
            })
            .collect();
        let mut p = params.clone();
        p.map.translation_tolerance = p.map.translation_tolerance.max(s / 10.0);
        p.map.rotation_tolerance = p.map.rotation_tolerance.max(s / 10.0 / LEVER);
        p.map.pair_points = p.map.pair_points.min(COARSE_PAIR_POINTS);
        let reach = stage_distance(params, s);
        let prepared = match last.take() {
            Some(prepared) => prepared.with_noise(&coarse, &staged, &p)?,
            None => MapPreparation::new(&coarse, &staged, &p)?,
        };
        start = map::solve(&prepared, initial, &start, &staged, &p, reach);
        last = Some(prepared);
    }
    Ok(start)
}

/// A stage's correspondence distance: where its kernel caps a residual between two
/// points of noise `sigma` each (and the floor), at most the one asked for.
fn stage_distance(params: &RegistrationParams, sigma: f64) -> f64 {
    let residual = (2.0 * sigma * sigma + params.map.floor_sigma * params.map.floor_sigma).sqrt();
    params
        .max_correspondence_distance
        .min(params.map.outlier_sigmas * residual)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn the_stages_of_a_good_scanner_search_within_their_cap() {
        // The default 3 cm and 0.5 mm floor, scans of 0.26 mm noise: the stages at 3.75
        // and 0.94 mm, then the scans' σ.
        let params = RegistrationParams::default();
        let reach: Vec<f64> = [0.00375, 0.0009375, 0.00026]
            .iter()
            .map(|&s| stage_distance(&params, s))
            .collect();
        assert_eq!(reach[0], 0.03);
        assert!((reach[1] - 0.011336).abs() < 1e-5, "{reach:?}");
        assert!((reach[2] - 0.00497).abs() < 1e-5, "{reach:?}");
    }

    proptest! {
        /// A stage never searches farther than asked, and a noisier stage never nearer.
        #[test]
        fn a_stage_searches_within_d_max_and_farther_as_its_noise_grows(
            d_max in 0.001f64..0.1,
            s in 1e-5f64..0.02,
            more in 1.0f64..10.0,
        ) {
            let params = RegistrationParams {
                max_correspondence_distance: d_max,
                ..RegistrationParams::default()
            };
            let reach = stage_distance(&params, s);
            prop_assert!(reach > 0.0 && reach <= d_max);
            prop_assert!(stage_distance(&params, s * more) >= reach);
        }
    }
}
