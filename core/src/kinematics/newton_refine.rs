//! Verifies a closed-form IK solution on the exact chain and, if it misses the target (a URDF
//! that is ortho-parallel only within [`STRUCTURE_TOLERANCE`](super::STRUCTURE_TOLERANCE)),
//! polishes it with damped Newton steps on the geometric Jacobian.

use super::joints::{DOF, Joints};
use super::serial_chain::SerialChain;
use crate::math::Pose;
use nalgebra::{Matrix6, Vector6};

/// Iterations of the polishing loop.
const MAX_ITERATIONS: usize = 12;

/// Damping (squared) of the least-squares step; keeps steps finite at singularities.
const DAMPING: f64 = 1e-12;

/// Position error (m) and rotation error (Frobenius norm of the rotation-matrix difference,
/// about √2 × the angle) between two poses.
pub(crate) fn pose_error(a: &Pose, b: &Pose) -> (f64, f64) {
    let dp = (a.translation.vector - b.translation.vector).norm();
    let ra = a.rotation.to_rotation_matrix();
    let rb = b.rotation.to_rotation_matrix();
    (dp, (ra.matrix() - rb.matrix()).norm())
}

/// `q` moved (if needed) so that the tip reaches `target` within `tol` in position and
/// rotation; `None` if the iteration does not get there.
pub(crate) fn refine(
    chain: &SerialChain,
    mut q: Joints,
    target: &Pose,
    tol: f64,
) -> Option<Joints> {
    for _ in 0..MAX_ITERATIONS {
        let tip = chain.tip_pose(&q);
        let (ep, er) = pose_error(&tip, target);
        if ep <= tol && er <= tol {
            return Some(q);
        }
        let dp = target.translation.vector - tip.translation.vector;
        let dr = (target.rotation * tip.rotation.inverse()).scaled_axis();
        let error = Vector6::new(dp.x, dp.y, dp.z, dr.x, dr.y, dr.z);
        let mut jacobian = Matrix6::zeros();
        for (k, (axis, point)) in chain.joint_axes(&q).iter().enumerate().take(DOF) {
            let linear = axis.cross(&(tip.translation.vector - point));
            jacobian.fixed_view_mut::<3, 1>(0, k).copy_from(&linear);
            jacobian.fixed_view_mut::<3, 1>(3, k).copy_from(axis);
        }
        let jt = jacobian.transpose();
        let normal = jt * jacobian + Matrix6::identity() * DAMPING;
        let step = normal.cholesky()?.solve(&(jt * error));
        if step.iter().any(|v| !v.is_finite()) {
            return None;
        }
        q += step;
    }
    let (ep, er) = pose_error(&chain.tip_pose(&q), target);
    (ep <= tol && er <= tol).then_some(q)
}
