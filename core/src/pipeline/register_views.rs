//! Register (Figure 2, the last step): each object's phase-1 cluster (the reference) and
//! its views, by the MAP registration (the model's) with the rig's pose uncertainty, and
//! by the paper's p-ICP-GPA and sequential ICP beside it, from the same input.

use super::{ExploreConfig, ObjectExploration, ObjectRegistration};
use crate::cloud::PointCloud;
use crate::math::Pose;
use crate::registration::{Method, RegistrationParams, register, register_with_models};

/// Evenly keeps at most `n` points of `cloud` (all columns); 0 keeps all.
fn subsample(cloud: &PointCloud, n: usize) -> PointCloud {
    if n == 0 || cloud.len() <= n {
        return cloud.clone();
    }
    let indices: Vec<usize> = (0..n).map(|k| k * cloud.len() / n).collect();
    cloud.select(&indices)
}

/// Registers the cluster (reference) and the views with the MAP registration (the
/// model's), the paper's p-ICP-GPA and sequential ICP, from the same input.
pub(super) fn register_object(
    object: &ObjectExploration,
    config: &ExploreConfig,
    workcell: Option<&crate::perception::WorkcellAlignment>,
) -> Result<ObjectRegistration, crate::registration::RegistrationError> {
    let points = config.registration_points;
    let mut views = vec![subsample(&object.cluster, points)];
    views.extend(
        object
            .views
            .iter()
            .filter(|v| !v.cloud.is_empty())
            .map(|v| {
                let mut cloud = subsample(&v.cloud, points);
                // Every point of a frame was seen from the reported sensor position.
                let o = nalgebra::Point3::from(v.sensor_pose.translation.vector);
                cloud.origins = Some(vec![o; cloud.len()]);
                cloud
            }),
    );
    let initial = vec![Pose::identity(); views.len()];
    // A sweep aligned to the workcell is off by its posterior uncertainty only.
    let mut uncertainty = config.uncertainty;
    if let Some(a) = workcell.filter(|a| a.accepted) {
        uncertainty.laser_pose = crate::registration::PosePrior {
            rotation_sigma: a.sigma.0,
            translation_sigma: a.sigma.1,
        };
    }
    let models = uncertainty.view_models(&views, config.frames_per_view);
    let params = |method| RegistrationParams {
        method,
        reference: 0,
        ..config.registration.clone()
    };
    let map = register_with_models(&views, &initial, &models, &params(Method::Map))?;
    let gpa = register(&views, &initial, &params(Method::Gpa))?;
    let icp = register(
        &views,
        &initial,
        &params(Method::SequentialIcp {
            point_to_plane: false,
        }),
    )?;
    let accepted = |r: &crate::registration::Registration| {
        r.converged && within_correction(&views, &r.poses, config.max_correction)
    };
    let map_accepted = match &map.report {
        crate::registration::MethodReport::Map(m) => m.accepted,
        _ => false,
    };
    Ok(ObjectRegistration {
        models,
        map_accepted,
        gpa_accepted: accepted(&gpa),
        icp_accepted: accepted(&icp),
        views,
        map,
        gpa,
        icp,
    })
}

/// Whether every pose (a correction of a view given in the world frame) turns by at most
/// `max.0` rad and moves the view's centroid by at most `max.1` m.
fn within_correction(views: &[PointCloud], poses: &[Pose], max: (f64, f64)) -> bool {
    views.iter().zip(poses).all(|(v, p)| {
        let moved = v.centroid().is_none_or(|c| (p * c - c).norm() <= max.1);
        p.rotation.angle() <= max.0 && moved
    })
}
