//! Pairwise ICP: a source view moved onto a target view. Each iteration takes every source
//! point's nearest target point (k-d tree over the target, built once; answers kept
//! between iterations by a [`NearestCache`] and searched again only where the pose change
//! could alter them), rejects pairs
//! farther than `d_max`, and solves for the pose either point-to-point (closed-form
//! Procrustes by SVD) or point-to-plane (the error linearised about the current pose,
//! a 6×6 normal-equation solve). Target normals come from the cloud, or are estimated by
//! PCA of `normal_neighbours` neighbours when it has none.
//!
//! Convergence: the relative change of the minimised mean squared error (point-to-point
//! distance², or point-to-plane residual²) from the previous iteration (or the one before,
//! which catches a two-state cycle) is at most `tolerance`; the report always describes
//! the returned pose.

pub(crate) mod sequential;

use std::num::NonZeroUsize;

use nalgebra::{Matrix6, Point3, Vector3, Vector6};

use crate::cloud::PointCloud;
use crate::math::Pose;
use crate::registration::nearest_cache::NearestCache;
use crate::registration::normals::normals_of;
use crate::registration::procrustes::fit_pairs;
use crate::registration::view_tree::{ViewTree, check_pose, check_view};
use crate::registration::{IcpParams, IcpReport, RegistrationError, StopReason, settled};

/// A registration target: its k-d tree and, for point-to-plane, its normals.
pub(crate) struct IcpTarget {
    tree: ViewTree,
    normals: Option<Vec<Vector3<f64>>>,
}

impl IcpTarget {
    /// Builds the target of view `view` (already checked).
    pub(crate) fn new(
        view: usize,
        cloud: &PointCloud,
        params: &IcpParams,
    ) -> Result<Self, RegistrationError> {
        let tree = ViewTree::build_with_graph(view, &cloud.points)?;
        let normals = if params.point_to_plane {
            Some(match &cloud.normals {
                // Unit length; a zero normal stays zero and its pairs weigh nothing.
                Some(n) => n
                    .iter()
                    .map(|v| v.try_normalize(0.0).unwrap_or_else(Vector3::zeros))
                    .collect(),
                None => {
                    let k = NonZeroUsize::new(params.normal_neighbours).ok_or(
                        RegistrationError::InvalidParameter {
                            name: "normal_neighbours",
                            value: 0.0,
                            reason: "must be at least 3",
                        },
                    )?;
                    normals_of(view, &cloud.points, cloud.origins.as_deref(), k)?
                }
            })
        } else {
            None
        };
        Ok(Self { tree, normals })
    }
}

/// The pose moving `source` onto `target`, starting from `initial` (source frame → target
/// frame), by ICP. In errors, the source is view 0 and the target view 1.
///
/// ```
/// use nbv_core::cloud::PointCloud;
/// use nbv_core::registration::{align, IcpParams};
/// use nalgebra::{Isometry3, Point3, Vector3};
/// // A bumpy grid, and the same grid moved by a small known transform.
/// let target: Vec<_> = (0..400)
///     .map(|i| {
///         let (x, y) = ((i % 20) as f64 * 0.01, (i / 20) as f64 * 0.01);
///         Point3::new(x, y, 0.02 * (20.0 * x).sin() * (15.0 * y).cos())
///     })
///     .collect();
/// let truth = Isometry3::new(Vector3::new(0.004, -0.003, 0.002), Vector3::new(0.0, 0.0, 0.03));
/// let source: Vec<_> = target.iter().map(|p| truth.inverse() * p).collect();
/// let params = IcpParams { max_correspondence_distance: 0.02, ..IcpParams::default() };
/// let (pose, report) = align(&PointCloud::from_points(source), &PointCloud::from_points(target),
///                            &Isometry3::identity(), &params).unwrap();
/// assert!(report.converged());
/// assert!((pose.translation.vector - truth.translation.vector).norm() < 1e-6);
/// ```
pub fn align(
    source: &PointCloud,
    target: &PointCloud,
    initial: &Pose,
    params: &IcpParams,
) -> Result<(Pose, IcpReport), RegistrationError> {
    params.validate()?;
    check_view(0, source)?;
    check_view(1, target)?;
    check_pose(0, initial)?;
    let target = IcpTarget::new(1, target, params)?;
    Ok(icp(&source.points, &target, initial, params))
}

/// Smallest/largest eigenvalue ratio of the point-to-plane normal matrix below which it
/// counts as singular.
const SINGULAR_RATIO: f64 = 1e-12;

/// One correspondence: source index, target index, squared distance.
type Pair = (u32, u32, f64);

/// ICP on checked input.
pub(crate) fn icp(
    source: &[Point3<f64>],
    target: &IcpTarget,
    initial: &Pose,
    params: &IcpParams,
) -> (Pose, IcpReport) {
    let mut pose = *initial;
    let mut iterations = 0;
    let mut history = Vec::new();
    let d_max = params.max_correspondence_distance;
    let mut cache = NearestCache::new(source.len(), d_max);
    let (pairs, stop) = loop {
        let pairs = correspondences(source, target, &pose, &mut cache, d_max);
        if pairs.is_empty() {
            break (pairs, StopReason::NoCorrespondences);
        }
        let objective = match &target.normals {
            Some(normals) => plane_mse(source, target, normals, &pose, &pairs),
            None => point_mse(&pairs),
        };
        history.push(objective);
        if settled(&history, params.tolerance) {
            break (pairs, StopReason::Converged);
        }
        if iterations == params.max_iterations {
            break (pairs, StopReason::MaxIterations);
        }
        let next = match &target.normals {
            Some(normals) => plane_step(source, target, normals, &pose, &pairs),
            None => {
                let points = target.tree.points();
                fit_pairs(pairs.len(), |k| {
                    let (i, j, _) = pairs[k];
                    (source[i as usize], points[j as usize])
                })
                .ok()
            }
        };
        let Some(next) = next else {
            break (pairs, StopReason::Degenerate);
        };
        pose = next;
        iterations += 1;
    };
    let report = IcpReport {
        iterations,
        stop,
        fitness: pairs.len() as f64 / source.len() as f64,
        rms: (!pairs.is_empty()).then(|| point_mse(&pairs).sqrt()),
        inliers: pairs.len(),
    };
    (pose, report)
}

/// Nearest target point of every source point at `pose` (brought up to date in `cache`),
/// kept if closer than `d_max`; in source order.
fn correspondences(
    source: &[Point3<f64>],
    target: &IcpTarget,
    pose: &Pose,
    cache: &mut NearestCache,
    d_max: f64,
) -> Vec<Pair> {
    cache.update(source, &target.tree, *pose);
    cache
        .entries()
        .iter()
        .enumerate()
        .filter_map(|(i, e)| e.within(d_max).map(|(j, sq)| (i as u32, j as u32, sq)))
        .collect()
}

/// Mean squared point-to-point distance of the pairs.
fn point_mse(pairs: &[Pair]) -> f64 {
    pairs.iter().map(|p| p.2).sum::<f64>() / pairs.len() as f64
}

/// Mean squared point-to-plane residual of the pairs.
fn plane_mse(
    source: &[Point3<f64>],
    target: &IcpTarget,
    normals: &[Vector3<f64>],
    pose: &Pose,
    pairs: &[Pair],
) -> f64 {
    let points = target.tree.points();
    pairs
        .iter()
        .map(|&(i, j, _)| {
            let r = (pose * source[i as usize] - points[j as usize]).dot(&normals[j as usize]);
            r * r
        })
        .sum::<f64>()
        / pairs.len() as f64
}

/// One Gauss–Newton step of point-to-plane ICP: with p = pose·x, minimise
/// Σ ((R(ω) p + t − q)·n)² linearised as R(ω) p ≈ p + ω × p, i.e. J = [p × n, n].
fn plane_step(
    source: &[Point3<f64>],
    target: &IcpTarget,
    normals: &[Vector3<f64>],
    pose: &Pose,
    pairs: &[Pair],
) -> Option<Pose> {
    let points = target.tree.points();
    let mut a = Matrix6::zeros();
    let mut g = Vector6::zeros();
    for &(i, j, _) in pairs {
        let p = pose * source[i as usize];
        let n = normals[j as usize];
        let r = (p - points[j as usize]).dot(&n);
        let c = p.coords.cross(&n);
        let jac = Vector6::new(c.x, c.y, c.z, n.x, n.y, n.z);
        a += jac * jac.transpose();
        g += jac * r;
    }
    // Refuse a (numerically) singular system: the pairs do not fix all six freedoms.
    let eigenvalues = a.symmetric_eigenvalues();
    let floor = SINGULAR_RATIO * eigenvalues.max();
    if eigenvalues.min().partial_cmp(&floor) != Some(std::cmp::Ordering::Greater) {
        return None;
    }
    let xi = a.cholesky()?.solve(&(-g));
    if !xi.iter().all(|v| v.is_finite()) {
        return None;
    }
    let step = Pose::new(
        Vector3::new(xi[3], xi[4], xi[5]),
        Vector3::new(xi[0], xi[1], xi[2]),
    );
    Some(step * pose)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rejects_bad_input_and_reports_no_overlap() {
        let pts: Vec<_> = (0..50)
            .map(|i| Point3::new((i % 10) as f64 * 0.01, (i / 10) as f64 * 0.01, 0.0))
            .collect();
        let cloud = PointCloud::from_points(pts);
        let p = IcpParams::default();
        assert_eq!(
            align(&PointCloud::default(), &cloud, &Pose::identity(), &p),
            Err(RegistrationError::EmptyView(0))
        );
        let bad = IcpParams {
            max_correspondence_distance: -1.0,
            ..IcpParams::default()
        };
        assert!(matches!(
            align(&cloud, &cloud, &Pose::identity(), &bad),
            Err(RegistrationError::InvalidParameter { .. })
        ));
        let far = Pose::translation(10.0, 0.0, 0.0);
        let (pose, report) = align(&cloud, &cloud, &far, &p).unwrap();
        assert_eq!(report.stop, StopReason::NoCorrespondences);
        assert_eq!((report.inliers, report.fitness, report.rms), (0, 0.0, None));
        assert_eq!(pose, far);
    }

    #[test]
    fn planar_target_is_degenerate_for_point_to_plane() {
        // Point-to-plane on a plane cannot fix in-plane motion: the 6×6 system is singular.
        let pts: Vec<_> = (0..100)
            .map(|i| Point3::new((i % 10) as f64 * 0.01, (i / 10) as f64 * 0.01, 0.0))
            .collect();
        let cloud = PointCloud::from_points(pts);
        let p = IcpParams {
            point_to_plane: true,
            ..IcpParams::default()
        };
        let start = Pose::translation(0.0, 0.0, 0.003);
        let (_, report) = align(&cloud, &cloud, &start, &p).unwrap();
        assert_eq!(report.stop, StopReason::Degenerate);
    }
}
