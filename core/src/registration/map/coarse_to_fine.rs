//! [`register_coarse_to_fine`]: the MAP registration of views whose initial poses are
//! several millimetres off their noise (a user's scans: no laser anchor, no pose prior).
//!
//! A MAP stage takes part only the points matched within a few σ of the noise, so at the
//! noise of a good scanner (0.3 mm) it sees too few matches to move views a centimetre
//! off, and its nearest points find the far side of thin parts. The stages here run at a
//! coarse σ first — the correspondence distance / 8 (3.75 mm at the default 3 cm), then
//! a quarter of it, until the views' own σ — each started where the last ended, every pose
//! prior kept on the initial poses. A coarse stage works on at most [`COARSE_POINTS`]
//! points per view and stops when a step moves no view by a tenth of its σ: it has only to
//! land within the next stage's reach. Measured on rings and hand-held paths of scans 2° and
//! 5 mm off: 0.07–0.22 mm from the truth where one stage at the scans' σ ends millimetres
//! off (docs/peers.md, "Users' scans").

use super::preparation::MapPreparation;
use super::view_model::{RangeNoise, ViewModel};
use crate::cloud::PointCloud;
use crate::math::Pose;
use crate::registration::{
    Registration, RegistrationError, RegistrationParams, register_prepared_from,
};

/// Points per view in a coarse stage.
pub const COARSE_POINTS: usize = 1000;

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
    let sigma = models
        .iter()
        .map(|m| m.noise.sigma(1.0))
        .fold(0.0, f64::max);
    let coarse: Vec<PointCloud> = views.iter().map(|v| v.thinned(COARSE_POINTS)).collect();
    let mut start = initial.to_vec();
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
        let prepared = MapPreparation::new(&coarse, &staged, &p)?;
        start = register_prepared_from(&prepared, &coarse, initial, &start, &staged, &p)?.poses;
    }
    let prepared = MapPreparation::new(views, models, params)?;
    register_prepared_from(&prepared, views, initial, &start, models, params)
}
