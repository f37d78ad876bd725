//! What a registration returns: the refined poses ([`Registration`]) and a per-method
//! report of how it went ([`GpaReport`], [`SequentialIcpReport`], [`PairReport`]).

use serde::{Deserialize, Serialize};

use crate::math::Pose;

/// Why an iterative registration stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StopReason {
    /// The relative change of the mean squared residual fell to the tolerance.
    Converged,
    /// The iteration cap was reached first.
    MaxIterations,
    /// No correspondence within `d_max` (the views do not overlap at their current poses).
    NoCorrespondences,
    /// The correspondences did not determine a transform (fewer than three, collinear, or
    /// a singular point-to-plane system).
    Degenerate,
}

/// The outcome of multi-view registration.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Registration {
    /// Refined pose of each view: view frame → world frame. The reference view keeps its
    /// initial pose; every other view is placed relative to it.
    pub poses: Vec<Pose>,
    /// Whether the method converged and every view is tied to the reference view.
    pub converged: bool,
    /// Root mean squared residual of the final correspondences (metres): distance to the
    /// set centroids for p-ICP-GPA; point-to-point distance of the inlier pairs, pooled
    /// over all pairs, for sequential ICP. `None` when there is no correspondence.
    pub rms: Option<f64>,
    /// Method-specific details.
    pub report: MethodReport,
}

/// Method-specific part of a [`Registration`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MethodReport {
    /// The MAP registration.
    Map(Box<MapReport>),
    /// p-ICP-GPA.
    Gpa(GpaReport),
    /// Sequential pairwise ICP.
    SequentialIcp(SequentialIcpReport),
}

/// How the MAP registration went.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MapReport {
    /// Accepted Levenberg–Marquardt steps.
    pub iterations: usize,
    /// Evaluations of the objective (correspondence searches).
    pub evaluations: usize,
    /// Why it stopped.
    pub stop: StopReason,
    /// The objective at the reported poses.
    pub objective_initial: f64,
    /// The objective at the returned poses.
    pub objective_final: f64,
    /// Directed view pairs in the data term.
    pub pairs: usize,
    /// Inlier correspondences at the returned poses.
    pub inliers: usize,
    /// RMS distance of the inlier correspondences (m); `None` without any.
    pub rms: Option<f64>,
    /// Converged and the objective fell: the poses are the model's.
    pub accepted: bool,
    /// What was accepted and why, in words.
    pub verdict: String,
    /// Per view, in input order.
    pub views: Vec<MapViewReport>,
}

/// One view of a [`MapReport`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MapViewReport {
    /// Inlier correspondences the view takes part in.
    pub inliers: usize,
    /// Its correction `(ω, t)` about its sensor origin (rad, m; world frame).
    pub correction: [f64; 6],
    /// χ² of the correction under the prior (`None` without a prior, or the reference).
    pub chi2: Option<f64>,
    /// Beyond the χ² gate: kept at its reported pose.
    pub held_at_prior: bool,
    /// No correspondence at all: left at its prior.
    pub unconstrained: bool,
    /// The data's information about the view's pose at the returned poses (6×6 diagonal
    /// block of the Gauss–Newton Hessian, rotation first, about the sensor origin).
    pub data_information: nalgebra::Matrix6<f64>,
}

/// How p-ICP-GPA went.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GpaReport {
    /// Outer iterations (correspondence searches followed by a pose update).
    pub iterations: usize,
    /// Procrustes fits of all views, summed over the outer iterations.
    pub inner_iterations: usize,
    /// Why it stopped.
    pub stop: StopReason,
    /// Root mean squared distance of set members to their set centroid, at the returned
    /// poses (metres); `None` without any set.
    pub rms: Option<f64>,
    /// Mean squared distance to the centroids measured at the start of each iteration, the
    /// last entry at the returned poses (m²).
    pub mse_history: Vec<f64>,
    /// Independent sets found at the returned poses.
    pub independent_sets: usize,
    /// Points that have at least one mutual nearest neighbour at the returned poses.
    pub linked_points: usize,
    /// Points that belong to an independent set at the returned poses.
    pub points_in_sets: usize,
    /// Independent-set members per view at the returned poses.
    pub correspondences_per_view: Vec<usize>,
    /// Views that share no independent set, directly or through other views, with the
    /// reference view at the returned poses: their pose is not tied to it.
    pub unconnected_views: Vec<usize>,
}

/// How sequential ICP went: one entry per registered pair, in the order they were run
/// (outward from the reference view).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SequentialIcpReport {
    /// Per-pair reports.
    pub pairs: Vec<PairReport>,
}

/// One registered pair of sequential ICP.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PairReport {
    /// Index of the view that moves.
    pub source: usize,
    /// Index of the view it is registered onto.
    pub target: usize,
    /// How the pairwise ICP went.
    #[serde(flatten)]
    pub icp: IcpReport,
}

/// How one pairwise ICP went.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct IcpReport {
    /// Pose updates performed.
    pub iterations: usize,
    /// Why it stopped.
    pub stop: StopReason,
    /// Share of source points with a correspondence within `d_max` at the returned pose.
    pub fitness: f64,
    /// Root mean squared point-to-point distance of those inliers (metres); `None` without
    /// any inlier.
    pub rms: Option<f64>,
    /// Number of inlier pairs at the returned pose.
    pub inliers: usize,
}

impl IcpReport {
    /// Whether the pair converged.
    pub fn converged(&self) -> bool {
        self.stop == StopReason::Converged
    }
}
