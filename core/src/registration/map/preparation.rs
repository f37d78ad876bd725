//! [`MapPreparation`]: an object's views prepared once for the MAP registration — each
//! view's k-d tree, viewing rays, range σ and surface elements ([`MapView`]) — and reused
//! by later runs on the same views with the same noise. The pipeline registers every
//! object again from new priors after its self-calibration; only the priors and the
//! starting poses change, so the preparation is made once per object, and a run from a
//! preparation gives exactly the result of a run that prepares afresh.
//!
//! It also keeps each pair's nearest-point cache ([`PairNearest`]) from one run to the
//! next: a later run starts near where the last one ended, so most of its first
//! evaluation's answers are proved unchanged instead of searched (a cache made within a
//! larger search radius serves a run within a smaller one). The caches answer exactly as
//! fresh searches do, so what ran before does not change a run's result.

use std::sync::Mutex;

use rayon::prelude::*;

use super::correspondences::PairNearest;
use super::view::{MapView, SeenEmpty};
use crate::cloud::PointCloud;
use crate::math::Pose;
use crate::registration::{
    DepthImageFreeSpace, FreeSpace, RangeNoise, RegistrationError, RegistrationParams, ViewModel,
};

/// Views prepared for [`register_prepared`](crate::registration::register_prepared).
///
/// ```
/// use nbv_core::cloud::PointCloud;
/// use nbv_core::registration::{
///     MapPreparation, Method, RangeNoise, RegistrationParams, ViewModel, register_prepared,
///     register_with_models,
/// };
/// use nalgebra::{Isometry3, Point3, Vector3};
/// let surface = |i: usize, j: usize| {
///     let (x, y) = (i as f64 * 0.004, j as f64 * 0.004);
///     Point3::new(x, y, 0.5 + 0.01 * (110.0 * x).sin() * (90.0 * y).cos())
/// };
/// let view = |cols: std::ops::Range<usize>| {
///     PointCloud::from_points(cols.flat_map(|i| (0..25).map(move |j| surface(i, j))).collect())
/// };
/// let views = [view(0..25), view(5..30)];
/// let initial = [Isometry3::identity(), Isometry3::translation(0.002, -0.001, 0.0)];
/// let models = [ViewModel { noise: RangeNoise::constant(0.0005), prior: None }; 2];
/// let params = RegistrationParams { method: Method::Map, max_correspondence_distance: 0.01,
///                                   ..Default::default() };
/// let prepared = MapPreparation::new(&views, &models, &params).unwrap();
/// let once = register_prepared(&prepared, &views, &initial, &models, &params).unwrap();
/// let afresh = register_with_models(&views, &initial, &models, &params).unwrap();
/// assert_eq!(once.poses, afresh.poses);
/// ```
pub struct MapPreparation {
    pub(crate) views: Vec<MapView>,
    noises: Vec<RangeNoise>,
    surface_neighbours: usize,
    /// The nearest-point caches the last run left, by pair.
    caches: Mutex<Vec<(CacheKey, PairNearest)>>,
}

/// What a nearest-point cache answers for: source view, target view, the stride of the
/// source's points, and the search radius (its bits).
pub(crate) type CacheKey = (usize, usize, usize, u64);

impl std::fmt::Debug for MapPreparation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("MapPreparation")
            .field("views", &self.views.len())
            .field("surface_neighbours", &self.surface_neighbours)
            .finish_non_exhaustive()
    }
}

impl MapPreparation {
    /// Prepares `clouds` (each in its own frame) with their models' range noise and the
    /// surfel size of `params.map`. The clouds are checked as every registration checks
    /// its input.
    pub fn new(
        clouds: &[PointCloud],
        models: &[ViewModel],
        params: &RegistrationParams,
    ) -> Result<Self, RegistrationError> {
        let poses = vec![Pose::identity(); clouds.len()];
        crate::registration::check_input(clouds, &poses, models, params)?;
        let k = params.map.surface_neighbours;
        let views = clouds
            .par_iter()
            .zip(models)
            .enumerate()
            .map(|(v, (c, m))| MapView::new(v, c, &m.noise, k))
            .collect::<Result<_, _>>()?;
        Ok(Self {
            views,
            noises: models.iter().map(|m| m.noise).collect(),
            surface_neighbours: k,
            caches: Mutex::new(Vec::new()),
        })
    }

    /// The same views prepared with the models' noise (`models`, one per view): each view
    /// as [`MapPreparation::new`] prepares it at that noise, without searching its
    /// neighbourhoods again, without free space, and with the caches the last run left
    /// (a run at the same or a smaller search radius starts from them). `clouds` must be
    /// the ones it was prepared from, checked as [`register_prepared`] checks them.
    ///
    /// [`register_prepared`]: crate::registration::register_prepared
    pub(crate) fn with_noise(
        self,
        clouds: &[PointCloud],
        models: &[ViewModel],
        params: &RegistrationParams,
    ) -> Result<Self, RegistrationError> {
        self.check_clouds(clouds, params)?;
        crate::registration::check_input(
            clouds,
            &vec![Pose::identity(); clouds.len()],
            models,
            params,
        )?;
        Ok(Self {
            views: self
                .views
                .into_iter()
                .zip(clouds)
                .zip(models)
                .map(|((v, c), m)| v.with_noise(c, &m.noise))
                .collect(),
            noises: models.iter().map(|m| m.noise).collect(),
            surface_neighbours: self.surface_neighbours,
            caches: self.caches,
        })
    }

    /// The cache kept for `key`, if the last run left one (taken out: runs that overlap
    /// in time each get their own).
    /// A cache kept for the same pair and stride at a larger radius serves too, answering
    /// within the smaller one from then on ([`PairNearest::shrink_to`]).
    pub(crate) fn take_cache(&self, key: CacheKey) -> Option<PairNearest> {
        // A poisoned lock only means an earlier panic; the caches stay exact.
        let mut caches = self
            .caches
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        if let Some(at) = caches.iter().position(|(k, _)| *k == key) {
            return Some(caches.swap_remove(at).1);
        }
        let (source, target, stride, reach) = key;
        let radius = f64::from_bits(reach);
        let at = caches.iter().position(|&((s, t, st, r), _)| {
            (s, t, st) == (source, target, stride) && f64::from_bits(r) >= radius
        })?;
        let mut cache = caches.swap_remove(at).1;
        cache.shrink_to(radius).then_some(cache)
    }

    /// Keeps a run's caches for the next run.
    pub(crate) fn keep_caches(&self, kept: impl IntoIterator<Item = (CacheKey, PairNearest)>) {
        let mut caches = self
            .caches
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        for (key, cache) in kept {
            caches.retain(|(k, _)| *k != key);
            caches.push((key, cache));
        }
    }

    /// Attaches what view `view`'s sensor saw to be empty ([`FreeSpace`], in the view's
    /// frame): a point of another view matched into it that lies beyond the edge of its
    /// surface, or has no point of it within `d_max`, is then judged by where it lies — in
    /// that free space it contradicts the view (pulled back onto its nearest point, or
    /// costing an outlier's cap), elsewhere it is merely unseen by it and costs what a
    /// true match is expected to cost, wherever the views move. Without free space such
    /// points pull nothing beyond an edge and cost the cap out of reach. A view index out
    /// of range is an error.
    pub fn with_free_space(
        self,
        view: usize,
        free_space: FreeSpace,
    ) -> Result<Self, RegistrationError> {
        self.attach(view, SeenEmpty::Rays(free_space))
    }

    /// Attaches what view `view`'s depth camera saw to be empty ([`DepthImageFreeSpace`],
    /// in the view's frame), as [`with_free_space`](Self::with_free_space) does a
    /// scanner's. A camera view's free space also lets the reference's points judge it:
    /// a reference point beyond the edge of the view's surface, where the camera saw
    /// through, contradicts the view and is pulled back onto its edge point (the view
    /// slid past a rim the reference saw); no other reference point is matched into the
    /// view. A view index out of range is an error.
    pub fn with_depth_image(
        self,
        view: usize,
        free_space: DepthImageFreeSpace,
    ) -> Result<Self, RegistrationError> {
        self.attach(view, SeenEmpty::DepthImage(free_space))
    }

    fn attach(mut self, view: usize, seen: SeenEmpty) -> Result<Self, RegistrationError> {
        let views = self.views.len();
        let Some(v) = self.views.get_mut(view) else {
            return Err(RegistrationError::ReferenceOutOfRange {
                reference: view,
                views,
            });
        };
        v.free_space = Some(seen);
        Ok(self)
    }

    /// Checks that the preparation was made from `clouds` (their points and sensor
    /// origins), the models' noise and `params`' surfel size.
    pub(crate) fn check_matches(
        &self,
        clouds: &[PointCloud],
        models: &[ViewModel],
        params: &RegistrationParams,
    ) -> Result<(), RegistrationError> {
        self.check_clouds(clouds, params)?;
        match self
            .noises
            .iter()
            .zip(models)
            .position(|(n, m)| *n != m.noise)
        {
            Some(v) => Err(RegistrationError::PreparationMismatch(format!(
                "view {v} has another range noise"
            ))),
            None => Ok(()),
        }
    }

    /// Checks that the preparation was made from `clouds` (their points and sensor
    /// origins) and `params`' surfel size, whatever the noise.
    fn check_clouds(
        &self,
        clouds: &[PointCloud],
        params: &RegistrationParams,
    ) -> Result<(), RegistrationError> {
        let mismatch = |what: String| Err(RegistrationError::PreparationMismatch(what));
        if self.views.len() != clouds.len() {
            return mismatch(format!(
                "{} views prepared, {} given",
                self.views.len(),
                clouds.len()
            ));
        }
        if self.surface_neighbours != params.map.surface_neighbours {
            return mismatch("another map.surface_neighbours".into());
        }
        for (v, (view, cloud)) in self.views.iter().zip(clouds).enumerate() {
            let centre = cloud
                .origin_centroid()
                .unwrap_or_else(|| view.tree.centroid());
            if view.tree.points() != cloud.points.as_slice() || view.centre != centre {
                return mismatch(format!("view {v} has other points or sensor origins"));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::registration::{Method, register_prepared};
    use nalgebra::Point3;

    fn views() -> Vec<PointCloud> {
        let sheet = |dx: f64| {
            PointCloud::from_points(
                (0..400)
                    .map(|i| {
                        let (x, y) = ((i % 20) as f64 * 0.004 + dx, (i / 20) as f64 * 0.004);
                        Point3::new(x, y, 0.01 * (60.0 * x).sin())
                    })
                    .collect(),
            )
        };
        vec![sheet(0.0), sheet(0.02)]
    }

    /// The two views, their models, the MAP's parameters and their preparation.
    fn problem() -> (
        Vec<PointCloud>,
        [ViewModel; 2],
        RegistrationParams,
        MapPreparation,
    ) {
        let views = views();
        let models = [ViewModel {
            noise: RangeNoise::constant(0.0005),
            prior: None,
        }; 2];
        let params = RegistrationParams {
            method: Method::Map,
            max_correspondence_distance: 0.01,
            ..Default::default()
        };
        let prepared = MapPreparation::new(&views, &models, &params).unwrap();
        (views, models, params, prepared)
    }

    #[test]
    fn a_run_after_others_on_the_same_preparation_gives_a_fresh_runs_result() {
        // The runs' nearest-point caches are kept in the preparation; each answers exactly
        // as a fresh search, so the poses do not depend on what ran before.
        let (views, models, params, prepared) = problem();
        let start = |dx: f64, dz: f64| {
            [
                Pose::identity(),
                Pose::new(
                    nalgebra::Vector3::new(dx, 0.0, dz),
                    nalgebra::Vector3::new(0.0, 0.004, 0.0),
                ),
            ]
        };
        for (dx, dz) in [(0.002, -0.001), (-0.003, 0.0015), (0.0005, 0.002)] {
            let initial = start(dx, dz);
            let kept = register_prepared(&prepared, &views, &initial, &models, &params).unwrap();
            let fresh = MapPreparation::new(&views, &models, &params).unwrap();
            let afresh = register_prepared(&fresh, &views, &initial, &models, &params).unwrap();
            assert_eq!(kept.poses, afresh.poses);
            assert_ne!(kept.poses[1], initial[1]);
        }
        assert!(!prepared.caches.lock().unwrap().is_empty());
    }

    #[test]
    fn the_same_views_at_another_noise_register_as_a_fresh_preparation_does() {
        // A first run leaves its caches at the full radius; the run at the other noise
        // and half the radius starts from them and ends where a fresh preparation does.
        let (views, models, params, prepared) = problem();
        let noisier = [ViewModel {
            noise: RangeNoise::constant(0.002),
            prior: None,
        }; 2];
        let initial = [
            Pose::identity(),
            Pose::new(
                nalgebra::Vector3::new(0.002, 0.0, -0.001),
                nalgebra::Vector3::new(0.0, 0.004, 0.0),
            ),
        ];
        register_prepared(&prepared, &views, &initial, &models, &params).unwrap();
        let shared = prepared.with_noise(&views, &noisier, &params).unwrap();
        assert!(!shared.caches.lock().unwrap().is_empty());
        let fresh = MapPreparation::new(&views, &noisier, &params).unwrap();
        let half = params.max_correspondence_distance / 2.0;
        let run = |p: &MapPreparation| {
            crate::registration::register_prepared_within(
                p, &views, &initial, &initial, &noisier, &params, half,
            )
            .unwrap()
        };
        let (a, b) = (run(&shared), run(&fresh));
        assert_eq!(a.poses, b.poses);
        assert_eq!(a.report, b.report);
        // The noise the preparation was made for no longer matches it.
        assert!(register_prepared(&shared, &views, &initial, &models, &params).is_err());
        // Other clouds are refused.
        let mut moved = views.clone();
        moved[0].points[3].y += 1e-4;
        assert!(matches!(
            fresh.with_noise(&moved, &models, &params),
            Err(RegistrationError::PreparationMismatch(_))
        ));
    }

    #[test]
    fn refuses_other_views_noise_or_method() {
        let (views, models, params, prepared) = problem();
        let initial = [Pose::identity(); 2];
        assert!(register_prepared(&prepared, &views, &initial, &models, &params).is_ok());
        let mismatch = |r: Result<_, RegistrationError>| {
            matches!(r, Err(RegistrationError::PreparationMismatch(_)))
        };
        // Other points.
        let mut moved = views.clone();
        moved[1].points[7].x += 1e-4;
        assert!(mismatch(register_prepared(
            &prepared, &moved, &initial, &models, &params
        )));
        // Other noise.
        let mut noisier = models;
        noisier[1].noise = RangeNoise::constant(0.001);
        assert!(mismatch(register_prepared(
            &prepared, &views, &initial, &noisier, &params
        )));
        // Another surfel size, another method.
        let mut other = params.clone();
        other.map.surface_neighbours += 1;
        assert!(mismatch(register_prepared(
            &prepared, &views, &initial, &models, &other
        )));
        other = RegistrationParams {
            method: Method::Gpa,
            ..params
        };
        assert!(mismatch(register_prepared(
            &prepared, &views, &initial, &models, &other
        )));
    }
}
