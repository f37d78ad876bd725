//! Register (Figure 2, the last step): each object's phase-1 cluster (the reference) and
//! its views, by the MAP registration (the model's) with
//! the rig's pose uncertainty, and (unless turned off) by the paper's p-ICP-GPA and
//! sequential ICP beside it, from the same input; and again, MAP only, with every view's
//! prior centred on the rig's self-calibration.

use super::{AcquiredView, ExploreConfig, ObjectExploration, ObjectRegistration};
use crate::calibration::{HandEyeEstimate, PoseUncertainty};
use crate::cloud::PointCloud;
use crate::kinematics::Robot;
use crate::math::Pose;
use crate::perception::WorkcellAlignment;
use crate::registration::{
    FreeSpace, MapPreparation, Method, MethodReport, PosePrior, Registration, RegistrationError,
    RegistrationParams, ViewModel, register, register_prepared, register_prepared_from,
};

/// The registration's input: `reference` (view 0) and the non-empty views, subsampled,
/// each camera point with its sensor position — each view's points smoothed for the
/// registration where it has them (`smoothed`), else its points as acquired.
fn registration_views(
    object: &ObjectExploration,
    reference: &PointCloud,
    config: &ExploreConfig,
    smoothed: bool,
) -> Vec<PointCloud> {
    let points = config.registration_points;
    let mut views = vec![reference.thinned(points)];
    views.extend(object.registered_views().map(|v| {
        let source = v
            .registration_cloud
            .as_ref()
            .filter(|c| smoothed && !c.is_empty())
            .unwrap_or(&v.cloud);
        with_origin(source.thinned(points), v)
    }));
    views
}

/// `cloud` with the reported sensor position of `view` as every point's origin: every
/// point of a frame was seen from there.
fn with_origin(mut cloud: PointCloud, view: &AcquiredView) -> PointCloud {
    let o = nalgebra::Point3::from(view.sensor_pose.translation.vector);
    cloud.origins = Some(vec![o; cloud.len()]);
    cloud
}

/// The model's points, one cloud per registration view: the cluster and every point of
/// the exploration's views as acquired; the calibration's views (after them) empty, since
/// they serve the calibration's evidence on their poses, not the model. Not subsampled as
/// the registration's input is: a subsample by index keeps a surface's points in
/// proportion to its pixels, and so drops most of what a view saw at a grazing angle,
/// sparse there, that no other view saw.
fn model_points(object: &ObjectExploration) -> Vec<PointCloud> {
    let explored = object.explored_views().count();
    let mut points = vec![object.cluster.clone()];
    points.extend(object.registered_views().enumerate().map(|(k, v)| {
        if k < explored {
            with_origin(v.cloud.clone(), v)
        } else {
            PointCloud::default()
        }
    }));
    points
}

/// Where the laser sweep saw empty space around `cluster` (within the correspondence
/// distance of its bounding box), its rays ending three of the laser's σ short of their
/// hits: the free space the pipeline gives the MAP registration of `cluster`'s views
/// ([`MapPreparation::with_free_space`]).
pub fn sweep_free_space(
    sweep: &PointCloud,
    cluster: &PointCloud,
    config: &ExploreConfig,
) -> Result<Option<FreeSpace>, RegistrationError> {
    let Some((lo, hi)) = cluster.bounds() else {
        return Ok(None);
    };
    let reach = nalgebra::Vector3::repeat(config.registration.max_correspondence_distance);
    let range = cluster
        .origin_centroid()
        .zip(cluster.centroid())
        .map_or(1.0, |(o, c)| (c - o).norm());
    let margin = 3.0 * config.uncertainty.laser_noise.sigma(range);
    FreeSpace::of_scan(sweep, lo - reach, hi + reach, margin)
}

/// The rig's uncertainty, the laser's pose prior replaced by the workcell alignment's
/// posterior where the sweep was aligned.
fn uncertainty_of(config: &ExploreConfig, workcell: Option<&WorkcellAlignment>) -> PoseUncertainty {
    let mut uncertainty = config.uncertainty;
    if let Some(a) = workcell.filter(|a| a.accepted) {
        uncertainty.laser_pose = PosePrior {
            rotation_sigma: a.sigma.0,
            translation_sigma: a.sigma.1,
        };
    }
    uncertainty
}

fn params(config: &ExploreConfig, method: Method) -> RegistrationParams {
    RegistrationParams {
        method,
        reference: 0,
        ..config.registration.clone()
    }
}

fn map_accepted(map: &Registration) -> bool {
    matches!(&map.report, MethodReport::Map(m) if m.accepted)
}

/// Registers the cluster and the views with the MAP registration (the model's) and, when the configuration asks for
/// the baselines, the paper's p-ICP-GPA and sequential ICP, from the same input. Also
/// returns the views as prepared for the MAP registration, for [`register_calibrated`].
pub(super) fn register_object(
    object: &ObjectExploration,
    config: &ExploreConfig,
    workcell: Option<&WorkcellAlignment>,
    sweep: Option<&PointCloud>,
) -> Result<(ObjectRegistration, MapPreparation), RegistrationError> {
    let views = registration_views(object, &object.cluster, config, true);
    let initial = vec![Pose::identity(); views.len()];
    let models = uncertainty_of(config, workcell).view_models(&views, config.frames_per_view);
    let map_params = params(config, Method::Map);
    let mut prepared = MapPreparation::new(&views, &models, &map_params)?;
    let free = match sweep {
        Some(sweep) => sweep_free_space(sweep, &object.cluster, config)?,
        None => None,
    };
    if let Some(free) = free {
        prepared = prepared.with_free_space(0, free)?;
    }
    for (k, view) in object.registered_views().enumerate() {
        prepared = prepared.with_depth_image(k + 1, view.free_space.clone())?;
    }
    let map = register_prepared(&prepared, &views, &initial, &models, &map_params)?;
    let (gpa, icp) = if config.registration_baselines {
        let icp_params = params(
            config,
            Method::SequentialIcp {
                point_to_plane: false,
            },
        );
        (
            Some(register(&views, &initial, &params(config, Method::Gpa))?),
            Some(register(&views, &initial, &icp_params)?),
        )
    } else {
        (None, None)
    };
    let accepted = |r: &Option<Registration>| {
        r.as_ref().is_some_and(|r| {
            r.converged && within_correction(&views, &r.poses, config.max_correction)
        })
    };
    let registration = ObjectRegistration {
        models,
        map_accepted: map_accepted(&map),
        map_initial: initial,
        calibrated: false,
        gpa_accepted: accepted(&gpa),
        icp_accepted: accepted(&icp),
        // The model's points: the cluster and the exploration's views as acquired (the
        // registration's reference and smoothed views stand for them).
        points: model_points(object),
        views,
        map,
        gpa,
        icp,
    };
    Ok((registration, prepared))
}

/// The MAP registration of `object` again, every camera view starting from and held
/// towards its self-calibrated pose (`calibration` applied at the view's joints), its
/// prior σ only the standstill's noise, the laser anchor's and the calibration's own. It
/// replaces the object's MAP registration when it is accepted; `Ok(false)` leaves it.
/// `prepared` is the views' preparation that [`register_object`] returned (the views and
/// their noise are the same; only the priors and the starting poses change).
pub(super) fn register_calibrated(
    object: &mut ObjectExploration,
    prepared: &MapPreparation,
    config: &ExploreConfig,
    workcell: Option<&WorkcellAlignment>,
    calibration: &HandEyeEstimate,
    robot: &Robot,
    frame: &str,
) -> Result<bool, RegistrationError> {
    let Some(first) = object.registration.as_ref() else {
        return Ok(false);
    };
    let views = &first.views;
    let uncertainty = uncertainty_of(config, workcell);
    let mut initial = vec![Pose::identity(); views.len()];
    let mut own = vec![uncertainty.camera_pose; views.len()];
    for (k, view) in object
        .registered_views()
        .enumerate()
        .map(|(k, v)| (k + 1, v))
    {
        let Some((xi, sigma)) =
            calibration.view_correction(robot, frame, &view.joints, &view.sensor_pose)
        else {
            return Ok(false);
        };
        let origin = nalgebra::Point3::from(view.sensor_pose.translation.vector);
        initial[k] = crate::calibration::correction_pose(&xi, &origin);
        let noise = uncertainty.view_noise;
        own[k] = PosePrior {
            rotation_sigma: noise.rotation_sigma.hypot(sigma.rotation_sigma),
            translation_sigma: noise.translation_sigma.hypot(sigma.translation_sigma),
        };
    }
    let models: Vec<ViewModel> =
        uncertainty.view_models_with(views, config.frames_per_view, |k| own[k]);
    let map = register_prepared(
        prepared,
        views,
        &initial,
        &models,
        &params(config, Method::Map),
    )?;
    if !map_accepted(&map) {
        return Ok(false);
    }
    let Some(r) = object.registration.as_mut() else {
        return Ok(false);
    };
    r.map = map;
    r.models = models;
    r.map_initial = initial;
    r.map_accepted = true;
    r.calibrated = true;
    Ok(true)
}

/// The object's accepted MAP registration refined along the camera's rays: started where
/// it ended, with the same initial poses and priors, every camera point matched where its
/// viewing ray crosses the laser cluster ([`MapParams::along_rays`]). It replaces the
/// registration when accepted; `Ok(false)` leaves it (not accepted).
///
/// [`MapParams::along_rays`]: crate::registration::MapParams::along_rays
pub(super) fn refine_along_rays(
    object: &mut ObjectExploration,
    prepared: &MapPreparation,
    config: &ExploreConfig,
) -> Result<bool, RegistrationError> {
    let Some(r) = object.registration.as_mut().filter(|r| r.map_accepted) else {
        return Ok(false);
    };
    let mut map_params = params(config, Method::Map);
    map_params.map.along_rays = true;
    let mut map = register_prepared_from(
        prepared,
        &r.views,
        &r.map_initial,
        &r.map.poses,
        &r.models,
        &map_params,
    )?;
    if !map_accepted(&map) {
        return Ok(false);
    }
    if let MethodReport::Map(report) = &mut map.report {
        report.verdict = format!(
            "refined along the camera's rays from the {} registration: {}",
            if r.calibrated { "calibrated" } else { "first" },
            report.verdict
        );
    }
    r.map = map;
    Ok(true)
}

/// Whether every pose (a correction of a view given in the world frame) turns by at most
/// `max.0` rad and moves the view's centroid by at most `max.1` m.
fn within_correction(views: &[PointCloud], poses: &[Pose], max: (f64, f64)) -> bool {
    views.iter().zip(poses).all(|(v, p)| {
        let moved = v.centroid().is_none_or(|c| (p * c - c).norm() <= max.1);
        p.rotation.angle() <= max.0 && moved
    })
}
