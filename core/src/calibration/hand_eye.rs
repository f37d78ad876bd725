//! [`estimate_hand_eye`]: the rig calibrates itself while it explores — one correction of
//! the depth camera's mount (hand-eye) and of the joint offsets but the last (folded into
//! the mount, below), estimated from every object's registration and, where the views
//! carry it, the table each view sees ([`TableEvidence`](super::TableEvidence): its height
//! and tilts, added to the view's data information).
//!
//! Each camera view's sensor-frame pose error is modelled as `E + J(q)·δq + n`: the
//! hand-eye error `E` (rotation vector and translation, shared by every camera view), the
//! joint offsets `δq` seen through the frame Jacobian at the view's joints
//! ([`Robot::frame_jacobian`]), and an independent error `n` of the standstill
//! ([`PoseUncertainty::view_noise`]). A view's registration is a MAP estimate that mixes
//! its data with its prior; the data's own estimate is recovered from the information:
//! with `H` the data's and `Λ` the prior's, `H·ξ_data = (H + Λ)·ξ − Λ·ξ₀` (`ξ₀` the
//! initial correction). Each view then counts with the information `(H⁻¹ + Σ_n)⁻¹`
//! (written `(I + H·Σ_n)⁻¹·H`, valid where `H` is singular), so a direction one view cannot
//! see (the turn about a bottle's axis) is taken from the views that can, and no single
//! view outweighs its standstill's noise. `θ = (E, δq)` is the weighted least-squares
//! solution with the rig's declared σ of `E` and of each joint offset as a prior.
//!
//! The last joint on the camera's chain turns the camera like the mount does: nothing
//! moves between that joint and the sensor, so its offset is a constant change of the
//! mount, in every view alike, and no calibration can tell the two apart. It is folded
//! into `E` (its column of `J` is dropped and its σ added to the mount's prior), so `E`
//! estimates the mount with that offset in it ([`identifiable_mount`]).
//!
//! The pipeline registers each object again with every view's prior centred on the
//! calibrated pose (`E + J·δq` applied) and only the standstill noise and the estimate's
//! own uncertainty as its σ, then estimates again, until the estimate stops moving.

use nalgebra::{Matrix3, Matrix6, Point3, SMatrix, SVector, Translation3, UnitQuaternion, Vector6};
use serde::Serialize;

use super::PoseUncertainty;
use crate::kinematics::{Joints, Robot};
use crate::math::Pose;
use crate::pipeline::ObjectExploration;
use crate::registration::{MethodReport, PosePrior};

/// Parameters of the calibration: hand-eye (6) then joint offsets (6).
const PARAMS: usize = 12;
/// Reweighting rounds of the robust estimate.
const ROBUST_ITERATIONS: usize = 10;
/// Cauchy scale of a view's χ² (6 degrees of freedom) in the robust estimate: twice the
/// expected χ.
const ROBUST_SCALE2: f64 = 24.0;

/// The estimated hand-eye correction (sensor frame) and joint offsets.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct HandEyeEstimate {
    /// Rotation vector (rad) of the correction `E` (true mount = nominal · `E`).
    pub rotation: [f64; 3],
    /// Translation (m) of `E`.
    pub translation: [f64; 3],
    /// Estimated joint offsets (rad, true minus reported); the last joint's is 0, its
    /// offset being part of the mount's correction.
    pub joint_offsets: [f64; 6],
    /// σ of the worst-determined rotation (rad) and translation (m) component of `E`.
    pub sigma: [f64; 2],
    /// Camera views that contributed.
    pub views: usize,
    /// Of those, the views whose table counted too ([`TableEvidence`](super::TableEvidence)).
    pub table_views: usize,
    /// Registration passes with a calibrated prior that followed this estimate (0: the
    /// estimate of the first pass was not used).
    pub passes: usize,
    /// Covariance of `(E, δq)`.
    #[serde(skip)]
    pub covariance: SMatrix<f64, PARAMS, PARAMS>,
}

impl HandEyeEstimate {
    /// The calibrated correction of a camera view taken at `joints` with reported sensor
    /// pose `sensor_pose`, as a world-frame `ξ = (ω, t)` about the sensor origin, and its
    /// σ per rotation and translation component (the worst of each) from the estimate's
    /// covariance.
    pub fn view_correction(
        &self,
        robot: &Robot,
        frame: &str,
        joints: &Joints,
        sensor_pose: &Pose,
    ) -> Option<(Vector6<f64>, PosePrior)> {
        let a = design(robot, frame, joints, sensor_pose)?;
        let mut theta = SVector::<f64, PARAMS>::zeros();
        theta.fixed_rows_mut::<3>(0).copy_from_slice(&self.rotation);
        theta
            .fixed_rows_mut::<3>(3)
            .copy_from_slice(&self.translation);
        theta
            .fixed_rows_mut::<6>(6)
            .copy_from_slice(&self.joint_offsets);
        let cov = a * self.covariance * a.transpose();
        let d = cov.diagonal();
        let sigma = PosePrior {
            rotation_sigma: d.fixed_rows::<3>(0).max().max(0.0).sqrt(),
            translation_sigma: d.fixed_rows::<3>(3).max().max(0.0).sqrt(),
        };
        Some((a * theta, sigma))
    }

    /// The largest change of `E` from `other`: rotation (rad) and translation (m).
    pub fn change_from(&self, other: &Self) -> (f64, f64) {
        let d =
            |a: [f64; 3], b: [f64; 3]| (0..3).map(|k| (a[k] - b[k]).powi(2)).sum::<f64>().sqrt();
        (
            d(self.rotation, other.rotation),
            d(self.translation, other.translation),
        )
    }
}

/// A world-frame correction `ξ = (ω, t)` about `origin` as a pose: `x ↦ R(ω)·(x − o) + o + t`.
pub fn correction_pose(xi: &Vector6<f64>, origin: &Point3<f64>) -> Pose {
    let r = UnitQuaternion::from_scaled_axis(xi.fixed_rows::<3>(0).into_owned());
    let t = origin.coords + xi.fixed_rows::<3>(3) - r * origin.coords;
    Pose::from_parts(Translation3::from(t), r)
}

/// `ξ = (ω, t)` of a world-frame correction pose about `origin`.
pub fn correction_of(pose: &Pose, origin: &Point3<f64>) -> Vector6<f64> {
    let w = pose.rotation.scaled_axis();
    let t = pose * origin - origin;
    Vector6::new(w.x, w.y, w.z, t.x, t.y, t.z)
}

/// The 6×12 map from `(E, δq)` to a view's world-frame correction about its sensor
/// origin: `B·[I | J(q)]` with `B` the sensor's rotation on both halves, and the mount
/// joint's column of `J` dropped (folded into `E`).
fn design(
    robot: &Robot,
    frame: &str,
    joints: &Joints,
    sensor_pose: &Pose,
) -> Option<SMatrix<f64, 6, PARAMS>> {
    let mut j = robot.frame_jacobian(joints, frame).ok()?;
    if let Some(k) = last_joint(&j) {
        j.column_mut(k).fill(0.0);
    }
    let r: Matrix3<f64> = sensor_pose.rotation.to_rotation_matrix().into_inner();
    let mut b = Matrix6::zeros();
    b.fixed_view_mut::<3, 3>(0, 0).copy_from(&r);
    b.fixed_view_mut::<3, 3>(3, 3).copy_from(&r);
    let mut a = SMatrix::<f64, 6, PARAMS>::zeros();
    a.fixed_view_mut::<6, 6>(0, 0).copy_from(&b);
    a.fixed_view_mut::<6, 6>(0, 6).copy_from(&(b * j));
    Some(a)
}

/// The last joint that moves the frame whose [frame Jacobian](Robot::frame_jacobian) is
/// `j`: its column is constant in the frame (it turns the frame like a change of the
/// mount).
fn last_joint(j: &Matrix6<f64>) -> Option<usize> {
    (0..6).rev().find(|&k| j.column(k).norm() > 0.0)
}

/// The last joint on `frame`'s chain and its (constant) column of the frame Jacobian.
fn mount_joint(robot: &Robot, frame: &str) -> Option<(usize, Vector6<f64>)> {
    let j = robot.frame_jacobian(&Joints::zeros(), frame).ok()?;
    let k = last_joint(&j)?;
    Some((k, j.column(k).into_owned()))
}

/// The mount error a calibration can determine: `mount` (true mount = nominal ·
/// `mount`) with the offset of the last joint on `frame`'s chain folded in, and
/// `joint_offsets` (rad, true minus reported) with that offset zeroed. The twin compares
/// the estimate with this. `None` where `frame` is not on `robot`.
///
/// ```
/// use nbv_core::kinematics::{comau_smart_six, Joints};
/// use nbv_core::math::Pose;
/// use nbv_core::calibration::identifiable_mount;
/// let robot = comau_smart_six()?;
/// let offsets = [0.001, 0.0, 0.0, 0.0, 0.0, 0.002];
/// let (mount, rest) = identifiable_mount(&robot, "dinast", &Pose::identity(), offsets).unwrap();
/// // Joint 6 turns the camera about its optical axis (the flange axis, reversed).
/// assert!((mount.rotation.scaled_axis().z + 0.002).abs() < 1e-12);
/// assert_eq!(rest, [0.001, 0.0, 0.0, 0.0, 0.0, 0.0]);
/// // At any joints, the true sensor pose is the same either way.
/// let q = Joints::from([0.3, -0.2, 0.4, 0.1, 0.5, -0.3]);
/// let both = robot.fk(&(q + Joints::from(offsets)), "dinast")?;
/// let folded = robot.fk(&(q + Joints::from(rest)), "dinast")? * mount;
/// assert!((both.translation.vector - folded.translation.vector).norm() < 1e-12);
/// assert!(both.rotation.angle_to(&folded.rotation) < 1e-12);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn identifiable_mount(
    robot: &Robot,
    frame: &str,
    mount: &Pose,
    joint_offsets: [f64; 6],
) -> Option<(Pose, [f64; 6])> {
    let zero = Joints::zeros();
    let (k, _) = mount_joint(robot, frame)?;
    let mut turned = zero;
    turned[k] = joint_offsets[k];
    let turn = robot.fk(&zero, frame).ok()?.inverse() * robot.fk(&turned, frame).ok()?;
    let mut rest = joint_offsets;
    rest[k] = 0.0;
    Some((turn * mount, rest))
}

/// Information of the prior of `E`: the rig's declared mount σ, widened by the folded
/// joint's offset σ along its (constant) column of `frame`'s Jacobian.
fn mount_information(
    robot: &Robot,
    frame: &str,
    uncertainty: &PoseUncertainty,
) -> Option<Matrix6<f64>> {
    let (_, c) = mount_joint(robot, frame)?;
    let sigma = uncertainty.joint_offset_sigma;
    (covariance_of(&uncertainty.hand_eye) + c * c.transpose() * (sigma * sigma)).try_inverse()
}

/// Diagonal covariance of a [`PosePrior`], rotation first.
fn covariance_of(p: &PosePrior) -> Matrix6<f64> {
    let (r, t) = (p.rotation_sigma.powi(2), p.translation_sigma.powi(2));
    Matrix6::from_diagonal(&Vector6::new(r, r, r, t, t, t))
}

/// A view's data information `H` and `H·ξ_data` (world frame, about the sensor origin,
/// relative to the reported pose).
type DataEvidence = (Matrix6<f64>, Vector6<f64>);

/// What one camera view tells about the calibration: the map from `(E, δq)` to its
/// correction, the weight of its own estimate, and the estimate (world frame, about the
/// sensor origin).
#[derive(Debug, Clone)]
struct ViewEvidence {
    design: SMatrix<f64, 6, PARAMS>,
    weight: Matrix6<f64>,
    estimate: Vector6<f64>,
    /// Whether the view's table is part of it.
    table: bool,
}

/// The hand-eye correction and joint offsets from the accepted MAP registrations of
/// `objects` (views held at their prior or without correspondences do not count), with
/// `robot`'s camera `frame` and the rig's declared `uncertainty` as the prior; `None`
/// without any view or when the normal equations are singular.
pub fn estimate_hand_eye(
    objects: &[ObjectExploration],
    robot: &Robot,
    frame: &str,
    uncertainty: &PoseUncertainty,
) -> Option<HandEyeEstimate> {
    let mount = mount_information(robot, frame, uncertainty)?;
    solve(
        &evidence(objects, robot, frame, uncertainty),
        &mount,
        uncertainty,
    )
}

/// Each usable camera view's [`ViewEvidence`]: its registration's (the accepted MAP's,
/// where the view was neither held at its prior nor without correspondences) and its
/// table's ([`TableEvidence`](super::TableEvidence)), as one estimate with their summed
/// information.
fn evidence(
    objects: &[ObjectExploration],
    robot: &Robot,
    frame: &str,
    uncertainty: &PoseUncertainty,
) -> Vec<ViewEvidence> {
    let noise = covariance_of(&uncertainty.view_noise);
    let mut terms = Vec::new();
    for object in objects {
        let registered = registration_evidence(object);
        for (k, view) in object.registered_views().enumerate() {
            // `H` and `H·ξ_data` of the view's data, `ξ` about the sensor origin relative
            // to the reported pose.
            let data = registered
                .as_ref()
                .and_then(|r| r.get(k).copied().flatten());
            let table = view
                .table
                .as_ref()
                .map(|t| (t.information, t.information * t.correction));
            let (h, y) = match (data, table) {
                (None, None) => continue,
                (Some(d), None) | (None, Some(d)) => d,
                (Some(d), Some(t)) => (d.0 + t.0, d.1 + t.1),
            };
            let Some(design) = design(robot, frame, &view.joints, &view.sensor_pose) else {
                continue;
            };
            // The view's weight (I + H·Σ_n)⁻¹·H.
            let Some(m) = (Matrix6::identity() + h * noise).try_inverse() else {
                continue;
            };
            let weight = m * h;
            let weight = (weight + weight.transpose()) * 0.5;
            let Ok(pseudo) = weight.pseudo_inverse(1e-12) else {
                continue;
            };
            terms.push(ViewEvidence {
                design,
                weight,
                estimate: pseudo * (m * y),
                table: view.table.is_some(),
            });
        }
    }
    terms
}

/// Per registered view of `object` (in [`ObjectExploration::registered_views`]' order),
/// the data information `H` of its accepted MAP registration and `H·ξ_data`, the data's
/// own correction recovered from the MAP optimum; `None` for a view held at its prior or
/// without correspondences, and for an object without an accepted MAP registration.
fn registration_evidence(object: &ObjectExploration) -> Option<Vec<Option<DataEvidence>>> {
    let r = object.registration.as_ref().filter(|r| r.map_accepted)?;
    let MethodReport::Map(report) = &r.map.report else {
        return None;
    };
    let entries = report
        .views
        .iter()
        .zip(&r.models)
        .zip(&r.map_initial)
        .skip(1);
    Some(
        object
            .registered_views()
            .zip(entries)
            .map(|(view, ((v, model), initial))| {
                if v.held_at_prior || v.unconstrained {
                    return None;
                }
                let prior = model.prior?;
                let origin = Point3::from(view.sensor_pose.translation.vector);
                let xi0 = correction_of(initial, &origin);
                // The run's correction, relative to its initial pose.
                let xi = Vector6::from_column_slice(&v.correction);
                let h = v.data_information;
                // H·ξ_data at the MAP optimum.
                Some((h, (h + prior.information()) * xi + h * xi0))
            })
            .collect(),
    )
}

/// The robust weighted least-squares `(E, δq)` of `terms` with the information `mount`
/// of `E`'s prior and the rig's declared joint σ as the prior.
fn solve(
    terms: &[ViewEvidence],
    mount: &Matrix6<f64>,
    uncertainty: &PoseUncertainty,
) -> Option<HandEyeEstimate> {
    if terms.is_empty() {
        return None;
    }
    let q = 1.0 / uncertainty.joint_offset_sigma.powi(2);
    let normal_of = |robust: &[f64]| {
        let mut normal = SMatrix::<f64, PARAMS, PARAMS>::zeros();
        let mut rhs = SVector::<f64, PARAMS>::zeros();
        for (t, k) in terms.iter().zip(robust) {
            normal += t.design.transpose() * t.weight * t.design * *k;
            rhs += t.design.transpose() * (t.weight * t.estimate) * *k;
        }
        let mut block = normal.fixed_view_mut::<6, 6>(0, 0);
        block += mount;
        for k in 0..6 {
            normal[(6 + k, 6 + k)] += q;
        }
        (normal, rhs)
    };
    // Iteratively reweighted: a view whose own estimate disagrees with the rest beyond its
    // weight (a registration pulled by a wrong match) counts less (Cauchy on its χ²).
    let mut robust = vec![1.0; terms.len()];
    for _ in 0..ROBUST_ITERATIONS {
        let (normal, rhs) = normal_of(&robust);
        let theta = normal.try_inverse()? * rhs;
        for (t, k) in terms.iter().zip(robust.iter_mut()) {
            let r = t.estimate - t.design * theta;
            *k = 1.0 / (1.0 + r.dot(&(t.weight * r)) / ROBUST_SCALE2);
        }
    }
    let (normal, rhs) = normal_of(&robust);
    let covariance = normal.try_inverse()?;
    let theta = covariance * rhs;
    let d = covariance.diagonal();
    if d.iter().any(|v| !v.is_finite() || *v <= 0.0) || theta.iter().any(|v| !v.is_finite()) {
        return None;
    }
    Some(HandEyeEstimate {
        rotation: [theta[0], theta[1], theta[2]],
        translation: [theta[3], theta[4], theta[5]],
        joint_offsets: std::array::from_fn(|k| theta[6 + k]),
        sigma: [
            d.fixed_rows::<3>(0).max().sqrt(),
            d.fixed_rows::<3>(3).max().sqrt(),
        ],
        views: terms.len(),
        table_views: terms.iter().filter(|t| t.table).count(),
        passes: 0,
        covariance,
    })
}

#[cfg(test)]
mod tests;
