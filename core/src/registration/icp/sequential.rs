//! The sequential baseline the paper compares against: pairwise ICP chained outward from
//! the reference view. Views after the reference are registered each onto the previous
//! one (h onto h−1), views before it each onto the next one (h onto h+1); each pair starts
//! from the relative pose of the initial poses, and the refined relative poses are
//! composed along the chain, so every pairwise error propagates to all views farther out.

use rayon::prelude::*;

use super::{IcpTarget, icp};
use crate::cloud::PointCloud;
use crate::math::Pose;
use crate::registration::{
    MethodReport, PairReport, Registration, RegistrationError, RegistrationParams,
    SequentialIcpReport,
};

/// Runs sequential ICP on checked input.
pub(crate) fn run(
    views: &[PointCloud],
    initial: &[Pose],
    params: &RegistrationParams,
    point_to_plane: bool,
) -> Result<Registration, RegistrationError> {
    let w = views.len();
    let r = params.reference;
    let icp_params = params.icp_params(point_to_plane);
    // (source, target) in chain order.
    let chain: Vec<(usize, usize)> = (r + 1..w)
        .map(|h| (h, h - 1))
        .chain((0..r).rev().map(|h| (h, h + 1)))
        .collect();
    let targets: Vec<Option<IcpTarget>> = (0..w)
        .into_par_iter()
        .map(|v| {
            chain
                .iter()
                .any(|&(_, t)| t == v)
                .then(|| IcpTarget::new(v, &views[v], &icp_params))
                .transpose()
        })
        .collect::<Result<_, _>>()?;
    let mut poses = initial.to_vec();
    let mut pairs = Vec::with_capacity(chain.len());
    for &(s, t) in &chain {
        let Some(target) = &targets[t] else {
            continue;
        };
        let guess = initial[t].inverse() * initial[s];
        let (relative, report) = icp(&views[s].points, target, &guess, &icp_params);
        poses[s] = poses[t] * relative;
        pairs.push(PairReport {
            source: s,
            target: t,
            icp: report,
        });
    }
    let inliers: usize = pairs.iter().map(|p| p.icp.inliers).sum();
    let sum_sq: f64 = pairs
        .iter()
        .filter_map(|p| p.icp.rms.map(|rms| rms * rms * p.icp.inliers as f64))
        .sum();
    Ok(Registration {
        poses,
        converged: pairs.iter().all(|p| p.icp.converged()),
        rms: (inliers > 0).then(|| (sum_sq / inliers as f64).sqrt()),
        report: MethodReport::SequentialIcp(SequentialIcpReport { pairs }),
    })
}
