//! [`align_to_workcell`]: the laser sweep's pose error, estimated from the workcell the rig
//! knows — the table top and the known obstacles' boxes — before anything is segmented.
//!
//! The sweep's points are posed with the pose the robot reported; its kinematic and
//! calibration error moves the whole cloud rigidly (per sweep), so the table and the known
//! obstacles appear shifted from where the scene says they are. The shift of the known
//! surfaces is the sweep's error: point-to-plane residuals of the points near a known
//! box face (noise-weighted, Cauchy kernel, the match gate shrinking from 5 cm to 1 cm),
//! plus the rig's prior on the sweep's pose, give a maximum a posteriori correction about
//! the laser's mean position. A direction the workcell does not constrain (no face seen
//! along it) stays at the prior. The correction is accepted when it converged and lies
//! within the χ² gate (6 degrees of freedom, 0.999) of the prior.

use nalgebra::{Matrix6, Point3, Translation3, UnitQuaternion, Vector3, Vector6};

use crate::cloud::PointCloud;
use crate::math::Pose;
use crate::planning::{Obstacle, ObstacleShape};
use crate::registration::PosePrior;

/// Points used at most (evenly subsampled).
const MAX_POINTS: usize = 20_000;
/// Match gates (m), coarse to fine; the last repeats until convergence.
const GATES: [f64; 4] = [0.05, 0.03, 0.02, 0.01];
/// Cap on Gauss–Newton steps.
const MAX_STEPS: usize = 30;
/// Convergence: a step below 0.001° and 0.01 mm.
const STEP_ROTATION: f64 = 1.745e-5;
const STEP_TRANSLATION: f64 = 1e-5;
/// χ²(6) at 0.999.
const GATE_CHI2: f64 = 22.458;
/// Cauchy scale in σ.
const KERNEL: f64 = 2.385;
/// At least this many points on known surfaces.
const MIN_INLIERS: usize = 100;

/// The estimated correction of a sweep (world frame: `true = correction · reported`).
#[derive(Debug, Clone, PartialEq)]
pub struct WorkcellAlignment {
    /// The correction (identity when not accepted).
    pub correction: Pose,
    /// The estimate before acceptance.
    pub estimate: Pose,
    /// Points on known surfaces at the end.
    pub inliers: usize,
    /// RMS point-to-plane residual of the inliers (m).
    pub rms: f64,
    /// Gauss–Newton steps taken.
    pub steps: usize,
    /// χ² of the estimate under the prior.
    pub chi2: f64,
    /// Posterior σ of the worst-determined rotation (rad) and translation (m) component.
    pub sigma: (f64, f64),
    /// Converged within the gate: `correction` is applied.
    pub accepted: bool,
}

/// Estimates the correction of `cloud` (a sweep, world frame through the reported poses,
/// with sensor origins) from the known boxes of `workcell` (cuboids; other shapes are
/// ignored), with range noise `sigma` (m) and the sweep's pose prior.
///
/// ```
/// use nbv_core::cloud::PointCloud;
/// use nbv_core::perception::align_to_workcell;
/// use nbv_core::planning::Obstacle;
/// use nbv_core::registration::PosePrior;
/// use nalgebra::{Isometry3, Point3, Vector3};
/// // A table top at z = 0 and a wall facing -x at x = 1, a side wall facing +y at y = -0.5.
/// let workcell = [
///     Obstacle::cuboid("table", [0.5, 0.0, -0.05], [1.0, 1.0, 0.05]),
///     Obstacle::cuboid("wall", [1.05, 0.0, 0.5], [0.05, 1.0, 0.5]),
///     Obstacle::cuboid("side", [0.5, -0.55, 0.5], [0.5, 0.05, 0.5]),
/// ];
/// let mut pts = Vec::new();
/// for i in 0..40 {
///     for j in 0..40 {
///         let (a, b) = (i as f64 / 40.0, j as f64 / 40.0);
///         pts.push(Point3::new(0.1 + 0.8 * a, -0.4 + 0.8 * b, 0.0));
///         pts.push(Point3::new(1.0, -0.4 + 0.8 * a, 0.1 + 0.6 * b));
///         pts.push(Point3::new(0.1 + 0.8 * a, -0.5, 0.1 + 0.6 * b));
///     }
/// }
/// // The robot reported the sweep 4 mm and 0.3° off.
/// let error = Isometry3::new(Vector3::new(0.004, -0.003, 0.002), Vector3::new(0.0, 0.003, 0.004));
/// let mut cloud = PointCloud::from_points(pts.iter().map(|p| error * p).collect());
/// cloud.origins = Some(vec![Point3::new(0.0, 0.0, 1.0); pts.len()]);
/// let prior = PosePrior { rotation_sigma: 0.005, translation_sigma: 0.005 };
/// let a = align_to_workcell(&cloud, &workcell, 0.001, &prior);
/// assert!(a.accepted);
/// let left = a.correction * error;
/// assert!(left.translation.vector.norm() < 1e-4 && left.rotation.angle() < 1e-4);
/// ```
pub fn align_to_workcell(
    cloud: &PointCloud,
    workcell: &[Obstacle],
    sigma: f64,
    prior: &PosePrior,
) -> WorkcellAlignment {
    let boxes: Vec<(Pose, Vector3<f64>)> = workcell
        .iter()
        .filter_map(|o| match &o.shape {
            ObstacleShape::Cuboid { half_extents: h } => {
                Some((o.pose, Vector3::new(h[0], h[1], h[2])))
            }
            ObstacleShape::TriMesh(_) => None,
        })
        .collect();
    let stride = cloud.len().div_ceil(MAX_POINTS).max(1);
    let points: Vec<Point3<f64>> = cloud.points.iter().step_by(stride).copied().collect();
    let centre = cloud
        .origin_centroid()
        .or_else(|| cloud.centroid())
        .unwrap_or_else(Point3::origin);
    let info_prior = prior.information();
    let var = sigma * sigma;
    let mut correction = Pose::identity();
    let (mut steps, mut converged) = (0, false);
    let mut last = (0usize, 0.0f64, Matrix6::zeros());
    for step in 0..MAX_STEPS {
        let gate = GATES[step.min(GATES.len() - 1)];
        let c = correction * centre;
        let (mut h, mut g) = (Matrix6::zeros(), Vector6::zeros());
        let (mut inliers, mut sum_sq) = (0usize, 0.0);
        for p in &points {
            let x = correction * p;
            let Some((d, n)) = nearest_face(&boxes, &x, gate) else {
                continue;
            };
            let m2 = d * d / var;
            let w = 1.0 / (1.0 + m2 / (KERNEL * KERNEL));
            let r = x - c;
            let j = Vector6::new(
                r.y * n.z - r.z * n.y,
                r.z * n.x - r.x * n.z,
                r.x * n.y - r.y * n.x,
                n.x,
                n.y,
                n.z,
            );
            h += j * j.transpose() * (w / var);
            g += j * (w * d / var);
            inliers += 1;
            sum_sq += d * d;
        }
        let xi = correction_vector(&correction, &centre);
        let a = h + info_prior;
        let b = g + info_prior * xi;
        last = (inliers, sum_sq, h);
        let Some(delta) = a.cholesky().map(|ch| -ch.solve(&b)) else {
            break;
        };
        let rotation = UnitQuaternion::from_scaled_axis(delta.fixed_rows::<3>(0).into_owned());
        let move_by = Translation3::from(c.coords + delta.fixed_rows::<3>(3).into_owned())
            * rotation
            * Translation3::from(-c.coords);
        correction = move_by * correction;
        steps = step + 1;
        let small = delta.fixed_rows::<3>(0).norm() < STEP_ROTATION
            && delta.fixed_rows::<3>(3).norm() < STEP_TRANSLATION;
        if small && step + 1 >= GATES.len() {
            converged = true;
            break;
        }
    }
    let (inliers, sum_sq, h) = last;
    let chi2 = prior.chi2(&correction_vector(&correction, &centre));
    let covariance = (h + info_prior)
        .try_inverse()
        .unwrap_or_else(Matrix6::zeros);
    let diag = covariance.diagonal();
    let sigma_out = (
        diag.fixed_rows::<3>(0).max().max(0.0).sqrt(),
        diag.fixed_rows::<3>(3).max().max(0.0).sqrt(),
    );
    let accepted = converged && inliers >= MIN_INLIERS && chi2 <= GATE_CHI2;
    WorkcellAlignment {
        correction: if accepted {
            correction
        } else {
            Pose::identity()
        },
        estimate: correction,
        inliers,
        rms: if inliers > 0 {
            (sum_sq / inliers as f64).sqrt()
        } else {
            0.0
        },
        steps,
        chi2,
        sigma: sigma_out,
        accepted,
    }
}

/// `(ω, t)` of a correction about `centre`.
fn correction_vector(correction: &Pose, centre: &Point3<f64>) -> Vector6<f64> {
    let w = correction.rotation.scaled_axis();
    let t = correction * centre - centre;
    Vector6::new(w.x, w.y, w.z, t.x, t.y, t.z)
}

/// The signed distance of `x` to the nearest face of the nearest box within `gate`, and
/// that face's outward normal (world); `None` near an edge (no single face) or when no
/// face is that close.
fn nearest_face(
    boxes: &[(Pose, Vector3<f64>)],
    x: &Point3<f64>,
    gate: f64,
) -> Option<(f64, Vector3<f64>)> {
    let mut best: Option<(f64, Vector3<f64>)> = None;
    for (pose, half) in boxes {
        let q = pose.inverse_transform_point(x);
        let excess = q.coords.abs() - half;
        let outside: Vec<usize> = (0..3).filter(|&k| excess[k] > 0.0).collect();
        let (axis, d) = match outside[..] {
            [] => {
                // Inside: the nearest face.
                let k = excess.imax();
                (k, excess[k])
            }
            [k] => (k, excess[k]),
            _ => continue,
        };
        if d.abs() > gate || best.is_some_and(|(b, _)| b.abs() <= d.abs()) {
            continue;
        }
        let mut n = Vector3::zeros();
        n[axis] = q[axis].signum();
        best = Some((d, pose.rotation * n));
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn faces_are_found_outside_and_inside_and_edges_are_skipped() {
        let boxes = [(Pose::identity(), Vector3::new(0.5, 0.5, 0.5))];
        let (d, n) = nearest_face(&boxes, &Point3::new(0.0, 0.0, 0.503), 0.01).unwrap();
        assert!((d - 0.003).abs() < 1e-12 && (n - Vector3::z()).norm() < 1e-12);
        let (d, n) = nearest_face(&boxes, &Point3::new(-0.498, 0.1, 0.0), 0.01).unwrap();
        assert!((d + 0.002).abs() < 1e-12 && (n + Vector3::x()).norm() < 1e-12);
        assert!(nearest_face(&boxes, &Point3::new(0.502, 0.502, 0.0), 0.01).is_none());
        assert!(nearest_face(&boxes, &Point3::new(0.0, 0.0, 0.6), 0.01).is_none());
    }

    #[test]
    fn an_unconstrained_direction_stays_at_the_prior() {
        // Only a table: x, y and the rotation about z are not observable.
        let workcell = [Obstacle::cuboid(
            "table",
            [0.0, 0.0, -0.05],
            [2.0, 2.0, 0.05],
        )];
        let pts: Vec<_> = (0..2500)
            .map(|k| {
                Point3::new(
                    (k % 50) as f64 * 0.02 - 0.5,
                    (k / 50) as f64 * 0.02 - 0.5,
                    0.0,
                )
            })
            .collect();
        let error = Pose::new(
            Vector3::new(0.003, 0.003, 0.002),
            Vector3::new(0.0, 0.0, 0.0),
        );
        let mut cloud = PointCloud::from_points(pts.iter().map(|p| error * p).collect());
        cloud.origins = Some(vec![Point3::new(0.0, 0.0, 1.0); pts.len()]);
        let prior = PosePrior {
            rotation_sigma: 0.005,
            translation_sigma: 0.005,
        };
        let a = align_to_workcell(&cloud, &workcell, 0.001, &prior);
        assert!(a.accepted);
        let t = (a.correction * Point3::new(0.0, 0.0, 1.0)) - Point3::new(0.0, 0.0, 1.0);
        assert!((t.z + 0.002).abs() < 1e-4, "{t}");
        assert!(t.x.abs() < 1e-6 && t.y.abs() < 1e-6, "{t}");
        // The prior bounds what the data do not tell: x, y stay uncertain at ~5 mm.
        assert!(a.sigma.1 > 0.004);
    }
}
