//! [`estimate_hand_eye`]: one correction of the depth camera's mount, estimated from every
//! object's registration — the rig calibrates itself while it explores.
//!
//! Each camera view's registration correction `ξ = (ω, t)` (world frame, about the
//! sensor) is, in the sensor frame `R` of its reported pose, `(Rᵀω, Rᵀt)`; a hand-eye error
//! `E` (true mount = nominal · `E`) gives every view the same sensor-frame correction: `E`'s
//! rotation vector and translation. The registration's estimate of a view mixes its data
//! with its prior; the data's own estimate is recovered from the information: with `H` the
//! data's and `Λ` the prior's, `H·ξ_data = (H + Λ)·ξ`. The hand-eye estimate is the
//! information-weighted mean of the data's estimates over all views, so a direction one
//! view cannot see (the turn about a bottle's axis) is taken from the views that can.

use nalgebra::{Matrix3, Matrix6, Vector6};
use serde::Serialize;

use super::ObjectExploration;
use crate::registration::MethodReport;

/// The estimated hand-eye correction (sensor frame).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct HandEyeEstimate {
    /// Rotation vector (rad) of the correction `E`.
    pub rotation: [f64; 3],
    /// Translation (m) of `E`.
    pub translation: [f64; 3],
    /// σ of the worst-determined rotation (rad) and translation (m) component.
    pub sigma: [f64; 2],
    /// Camera views that contributed.
    pub views: usize,
}

/// The hand-eye estimate from the accepted MAP registrations of `objects` (views held at
/// their prior or without correspondences do not count); `None` without any view or when
/// the views together do not determine all six components.
pub fn estimate_hand_eye(objects: &[ObjectExploration]) -> Option<HandEyeEstimate> {
    let mut info = Matrix6::zeros();
    let mut weighted = Vector6::zeros();
    let mut views = 0;
    for object in objects {
        let Some(r) = object.registration.as_ref().filter(|r| r.map_accepted) else {
            continue;
        };
        let MethodReport::Map(report) = &r.map.report else {
            continue;
        };
        // Registration view k ≥ 1 is the k-th non-empty camera view.
        let poses = object
            .views
            .iter()
            .filter(|v| !v.cloud.is_empty())
            .map(|v| v.sensor_pose);
        let entries = report.views.iter().zip(&r.models).skip(1);
        for (pose, (v, model)) in poses.zip(entries) {
            if v.held_at_prior || v.unconstrained {
                continue;
            }
            let Some(prior) = model.prior else {
                continue;
            };
            let rt: Matrix3<f64> = pose.rotation.to_rotation_matrix().matrix().transpose();
            let mut b = Matrix6::zeros();
            b.fixed_view_mut::<3, 3>(0, 0).copy_from(&rt);
            b.fixed_view_mut::<3, 3>(3, 3).copy_from(&rt);
            let xi = Vector6::from_column_slice(&v.correction);
            let h = v.data_information;
            info += b * h * b.transpose();
            weighted += b * ((h + prior.information()) * xi);
            views += 1;
        }
    }
    if views == 0 {
        return None;
    }
    let covariance = info.try_inverse()?;
    let e = covariance * weighted;
    let d = covariance.diagonal();
    if d.iter().any(|v| !v.is_finite() || *v <= 0.0) {
        return None;
    }
    Some(HandEyeEstimate {
        rotation: [e[0], e[1], e[2]],
        translation: [e[3], e[4], e[5]],
        sigma: [
            d.fixed_rows::<3>(0).max().sqrt(),
            d.fixed_rows::<3>(3).max().sqrt(),
        ],
        views,
    })
}
