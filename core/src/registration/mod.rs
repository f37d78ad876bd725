//! Registration of an object's views (the paper's §III-B, Figure 4): every view's pose
//! refined so that the views agree with each other and with the reference view.
//!
//! Input: the views as [`PointCloud`]s, each in its own (sensor) frame, and an initial
//! pose per view (view frame → world frame: the sensor poses the robot reported). Output: a
//! [`Registration`] with the refined pose of each view, the reference view keeping its
//! initial pose, and a report; [`Registration::merged`] builds the model cloud. One call,
//! [`register`] (or [`register_with_models`] with each view's noise and pose prior), runs
//! any of three methods on the same input ([`Method`]):
//!
//! 1. **The MAP registration** ([`Method::Map`], `map/`), which makes the pipeline's
//!    models: a maximum a posteriori estimate of every view's pose, the reference (the
//!    laser cluster) fixed. Each camera point is matched into the reference, its residual
//!    weighted by both sensors' range noise along their rays ([`RangeNoise`]), point-to-
//!    plane where the target's plane is well determined, under a truncated Cauchy kernel;
//!    a point beyond the reference's edge is judged by where the laser saw empty space
//!    ([`FreeSpace`]), and a reference point beyond a camera view's edge by where the
//!    camera did ([`DepthImageFreeSpace`]). Each view's correction has a prior from the
//!    robot's pose uncertainty ([`PosePrior`]); Levenberg–Marquardt solves all views at
//!    once, and a view whose correction fails its prior's χ² gate keeps its reported pose.
//!    Points are matched to their nearest target points, or where the camera's rays cross
//!    the target ([`MapParams::along_rays`]): the pipeline registers by nearest points and
//!    refines each object's final registration along the rays. A [`MapPreparation`] keeps
//!    the views' trees and surface elements for later runs on the same views.
//!    [`register_coarse_to_fine`] runs it in stages of decreasing σ for views far off
//!    their noise (a user's scans, `nbv register`).
//! 2. **p-ICP-GPA** ([`Method::Gpa`], `gpa/`), the paper's method: mutual nearest
//!    neighbours between every pair of views, independent sets ([`SetRule`]), and
//!    generalised Procrustes of every view onto the sets' centroids.
//! 3. **Sequential ICP** ([`Method::SequentialIcp`], `icp/`), the baseline the paper
//!    compares with: pairwise ICP chained outward from the reference; [`align`] registers
//!    a single pair.
//!
//! What they share sits here: the parameters ([`RegistrationParams`]), the report, the
//! errors, the views' k-d trees and nearest-neighbour caches, normals, Procrustes, the
//! merge, the files of a registration of view files ([`RegistrationFiles`]) and the range
//! noise, viewing direction and sensor of views that come without a sensor model
//! ([`estimate_range_sigma`], [`estimate_view_direction`], [`assign_sensor_origins`]). The
//! pipeline builds each object's model with the MAP registration; it runs p-ICP-GPA and
//! sequential ICP beside it for comparison (`[registration] baselines`).
//!
//! Everything that runs in parallel (rayon: over points, sets and views) collects in
//! index order and reduces sequentially, so results are bit-identical at any thread
//! count.

mod error;
mod gpa;
mod icp;
mod local_planes;
mod map;
mod merge;
mod nearest_cache;
mod neighbour_graph;
mod normals;
mod outcome;
mod output_files;
mod params;
mod procrustes;
mod range_noise_estimate;
mod sensor_origins;
mod view_direction_estimate;
mod view_tree;

pub use error::RegistrationError;
pub use icp::align;
pub use local_planes::NOISE_NEIGHBOURS;
pub use map::coarse_to_fine::{
    COARSE_PAIR_POINTS, COARSE_POINTS, coarse_sigmas, register_coarse_to_fine,
};
pub use map::depth_image_free_space::DepthImageFreeSpace;
pub use map::free_space::FreeSpace;
pub use map::preparation::MapPreparation;
pub use map::view_model::{PosePrior, RangeNoise, ViewModel};
pub use normals::estimate_normals;
pub use outcome::{
    GpaReport, IcpReport, MapReport, MapViewReport, MethodReport, PairReport, Registration,
    SequentialIcpReport, StopReason,
};
pub use output_files::{RegistrationFileError, RegistrationFiles};
pub use params::{IcpParams, MapParams, Method, RegistrationParams, SetRule};
pub use procrustes::rigid_procrustes;
pub use range_noise_estimate::estimate_range_sigma;
pub use sensor_origins::{ORIGIN_AMONG_POINTS, SensorOrigin, assign_sensor_origins};
pub use view_direction_estimate::estimate_view_direction;

use crate::cloud::PointCloud;
use crate::math::Pose;

/// Registers `views` (each in its own frame) starting from `initial_poses` (view → world)
/// with the method and parameters of `params`.
///
/// ```
/// use nbv_core::cloud::PointCloud;
/// use nbv_core::registration::{register, Method, MethodReport, RegistrationParams};
/// use nalgebra::{Isometry3, Point3, Vector3};
/// // A bumpy surface sampled on a 5 mm grid; view 0 sees columns 0..30 (its frame is the
/// // world), view 1 columns 10..40 from a sensor at `truth` (view 1 frame → world).
/// let surface = |i: usize, j: usize| {
///     let (x, y) = (i as f64 * 0.005, j as f64 * 0.005);
///     Point3::new(x, y, 0.02 * (30.0 * x).sin() * (25.0 * y).cos())
/// };
/// let truth = Isometry3::new(Vector3::new(0.05, 0.0, 0.0), Vector3::new(0.0, 0.0, 0.1));
/// let view0: Vec<_> = (0..30).flat_map(|i| (0..30).map(move |j| surface(i, j))).collect();
/// let view1: Vec<_> = (10..40)
///     .flat_map(|i| (0..30).map(move |j| truth.inverse() * surface(i, j)))
///     .collect();
/// let views = [PointCloud::from_points(view0), PointCloud::from_points(view1)];
/// // The robot reported view 1's pose with an error of 2 mm and 0.5°.
/// let error = Isometry3::new(Vector3::new(0.002, -0.001, 0.0), Vector3::new(0.0, 0.0, 0.009));
/// let initial = [Isometry3::identity(), truth * error];
/// let params = RegistrationParams { max_correspondence_distance: 0.01, ..Default::default() };
///
/// let gpa = register(&views, &initial, &params).unwrap();
/// assert!(gpa.converged);
/// assert_eq!(gpa.poses[0], initial[0]); // the reference view keeps its pose
/// assert!((gpa.poses[1].to_homogeneous() - truth.to_homogeneous()).norm() < 1e-9);
/// let MethodReport::Gpa(report) = &gpa.report else { unreachable!() };
/// assert_eq!(report.independent_sets, 600); // the 20 shared columns
///
/// // The same call runs the sequential baseline.
/// let icp_params = RegistrationParams {
///     method: Method::SequentialIcp { point_to_plane: true },
///     ..params
/// };
/// let icp = register(&views, &initial, &icp_params).unwrap();
/// assert!((icp.poses[1].translation.vector - truth.translation.vector).norm() < 2e-3);
/// ```
pub fn register(
    views: &[PointCloud],
    initial_poses: &[Pose],
    params: &RegistrationParams,
) -> Result<Registration, RegistrationError> {
    let models = vec![ViewModel::default(); views.len()];
    register_with_models(views, initial_poses, &models, params)
}

/// [`register`] with what is known of each view: its sensor's noise and the prior on its
/// pose ([`ViewModel`]). Only [`Method::Map`] uses them; the other methods ignore them.
///
/// ```
/// use nbv_core::cloud::PointCloud;
/// use nbv_core::registration::{
///     register_with_models, Method, MethodReport, PosePrior, RangeNoise, RegistrationParams,
///     ViewModel,
/// };
/// use nalgebra::{Isometry3, Point3, Vector3};
/// // Two views of a wavy surface; the robot reported view 1 2 mm and 0.5° off.
/// let surface = |i: usize, j: usize| {
///     let (x, y) = (i as f64 * 0.004, j as f64 * 0.004);
///     Point3::new(x, y, 0.5 + 0.01 * (110.0 * x).sin() * (90.0 * y).cos())
/// };
/// let view0: Vec<_> = (0..25).flat_map(|i| (0..25).map(move |j| surface(i, j))).collect();
/// let view1: Vec<_> = (5..30).flat_map(|i| (0..25).map(move |j| surface(i, j))).collect();
/// // Both seen from a sensor 0.5 m above the surface (the `origins` column).
/// let seen = |points: Vec<Point3<f64>>| {
///     let mut c = PointCloud::from_points(points);
///     c.origins = Some(vec![Point3::new(0.06, 0.05, 0.0); c.len()]);
///     c
/// };
/// let views = [seen(view0), seen(view1)];
/// let error = Isometry3::new(Vector3::new(0.002, -0.001, 0.0), Vector3::new(0.0, 0.0, 0.009));
/// let initial = [Isometry3::identity(), error];
/// let model = ViewModel {
///     noise: RangeNoise::constant(0.0005),
///     prior: Some(PosePrior { rotation_sigma: 0.01, translation_sigma: 0.003 }),
/// };
/// let params = RegistrationParams { method: Method::Map, max_correspondence_distance: 0.01,
///                                   ..Default::default() };
/// let r = register_with_models(&views, &initial, &[model; 2], &params).unwrap();
/// assert!(r.converged);
/// let MethodReport::Map(report) = &r.report else { unreachable!() };
/// assert!(report.accepted && report.objective_final < report.objective_initial);
/// // Closer to the truth (the identity) than the reported 2.2 mm and 0.5°.
/// assert!(r.poses[1].translation.vector.norm() < 0.0022);
/// assert!(r.poses[1].rotation.angle() < 0.5f64.to_radians());
/// ```
pub fn register_with_models(
    views: &[PointCloud],
    initial_poses: &[Pose],
    models: &[ViewModel],
    params: &RegistrationParams,
) -> Result<Registration, RegistrationError> {
    check_input(views, initial_poses, models, params)?;
    match params.method {
        Method::Map => {
            let prepared = MapPreparation::new(views, models, params)?;
            map::run(
                &prepared,
                initial_poses,
                initial_poses,
                models,
                params,
                params.max_correspondence_distance,
            )
        }
        Method::Gpa => gpa::run(views, initial_poses, params),
        Method::SequentialIcp { point_to_plane } => {
            icp::sequential::run(views, initial_poses, params, point_to_plane)
        }
    }
}

/// The MAP registration ([`Method::Map`]) of `views` from a [`MapPreparation`] of them:
/// the result of [`register_with_models`] without preparing the views again. Errors with
/// [`RegistrationError::PreparationMismatch`] when `prepared` was made from other views,
/// noise or surfel size, or `params.method` is not [`Method::Map`]; otherwise checks its
/// input as [`register_with_models`] does.
pub fn register_prepared(
    prepared: &MapPreparation,
    views: &[PointCloud],
    initial_poses: &[Pose],
    models: &[ViewModel],
    params: &RegistrationParams,
) -> Result<Registration, RegistrationError> {
    register_prepared_from(
        prepared,
        views,
        initial_poses,
        initial_poses,
        models,
        params,
    )
}

/// [`register_prepared`] started from `start_poses` rather than from `initial_poses`: the
/// priors stay centred on `initial_poses` (the reported or calibrated poses), the solver
/// starts where another run ended. The report's initial objective is still the one at
/// `initial_poses`. Errors as [`register_prepared`] does, and with
/// [`RegistrationError::PoseCountMismatch`] when `start_poses` is not one pose per view.
pub fn register_prepared_from(
    prepared: &MapPreparation,
    views: &[PointCloud],
    initial_poses: &[Pose],
    start_poses: &[Pose],
    models: &[ViewModel],
    params: &RegistrationParams,
) -> Result<Registration, RegistrationError> {
    register_prepared_within(
        prepared,
        views,
        initial_poses,
        start_poses,
        models,
        params,
        params.max_correspondence_distance,
    )
}

/// [`register_prepared_from`] with each point's nearest target point searched within
/// `reach` (≤ `d_max`) only: a coarse-to-fine stage's.
pub(crate) fn register_prepared_within(
    prepared: &MapPreparation,
    views: &[PointCloud],
    initial_poses: &[Pose],
    start_poses: &[Pose],
    models: &[ViewModel],
    params: &RegistrationParams,
    reach: f64,
) -> Result<Registration, RegistrationError> {
    check_input(views, initial_poses, models, params)?;
    if start_poses.len() != views.len() {
        return Err(RegistrationError::PoseCountMismatch {
            views: views.len(),
            poses: start_poses.len(),
        });
    }
    if params.method != Method::Map {
        return Err(RegistrationError::PreparationMismatch(
            "a MAP preparation registers with method map only".into(),
        ));
    }
    prepared.check_matches(views, models, params)?;
    map::run(
        prepared,
        initial_poses,
        start_poses,
        models,
        params,
        reach.min(params.max_correspondence_distance),
    )
}

/// The checks every registration runs on its input: valid parameters, the views
/// ([`view_tree::check_views`]) and one valid [`ViewModel`] per view.
fn check_input(
    views: &[PointCloud],
    initial_poses: &[Pose],
    models: &[ViewModel],
    params: &RegistrationParams,
) -> Result<(), RegistrationError> {
    params.validate()?;
    view_tree::check_views(views, initial_poses, params.reference)?;
    check_models(views, models)
}

/// One valid [`ViewModel`] per view.
fn check_models(views: &[PointCloud], models: &[ViewModel]) -> Result<(), RegistrationError> {
    if models.len() != views.len() {
        return Err(RegistrationError::ModelCountMismatch {
            views: views.len(),
            models: models.len(),
        });
    }
    if let Some(view) = models
        .iter()
        .position(|m| !m.noise.is_valid() || m.prior.is_some_and(|p| !p.is_valid()))
    {
        return Err(RegistrationError::InvalidViewModel(view));
    }
    Ok(())
}

/// Mean squared residual (m²) below which a registration counts as exact: relative
/// changes of rounding noise are meaningless (1e-26 m² is an RMS of 0.1 pm).
const EXACT_MSE: f64 = 1e-26;

/// Whether the last mean squared error of `history` has settled: its relative change
/// from the previous value, or from the one before (a two-state cycle of
/// correspondences), is at most `tolerance`, or it is at rounding level.
pub(crate) fn settled(history: &[f64], tolerance: f64) -> bool {
    let close = |prev: f64, cur: f64| (prev - cur).abs() <= tolerance * prev;
    match history {
        [.., cur] if *cur <= EXACT_MSE => true,
        [.., before, prev, cur] => close(*prev, *cur) || close(*before, *cur),
        [.., prev, cur] => close(*prev, *cur),
        _ => false,
    }
}
