//! [`RegistrationError`]: what can be wrong with the input of a registration.
//!
//! Poor data that is nevertheless well formed (views that do not overlap, a solve that
//! stays degenerate) is not an error: it comes back as a result whose report says it did
//! not converge and why.

use thiserror::Error;

use crate::cloud::CloudError;

/// Errors of registration input: views, initial poses and parameters.
#[derive(Debug, Error, PartialEq)]
pub enum RegistrationError {
    /// Multi-view registration needs at least two views.
    #[error("registration needs at least 2 views, got {0}")]
    TooFewViews(usize),
    /// There must be exactly one initial pose per view.
    #[error("{views} views but {poses} initial poses")]
    PoseCountMismatch {
        /// Number of views.
        views: usize,
        /// Number of initial poses.
        poses: usize,
    },
    /// A view has no point.
    #[error("view {0} has no point")]
    EmptyView(usize),
    /// A view's columns are inconsistent or hold a NaN / infinite value.
    #[error("view {view}: {source}")]
    InvalidView {
        /// Index of the view.
        view: usize,
        /// What is wrong with the cloud.
        source: CloudError,
    },
    /// A point is finite but absurdly far away (beyond ±1e9 m), which no sensor measures.
    #[error("view {view}: point {index} lies beyond ±1e9 m")]
    PointOutOfRange {
        /// Index of the view.
        view: usize,
        /// Index of the point in the view.
        index: usize,
    },
    /// A view holds more points than the k-d tree can index (u32).
    #[error("view {view} has {points} points, more than a k-d tree can index")]
    TooManyPoints {
        /// Index of the view.
        view: usize,
        /// Number of points in the view.
        points: usize,
    },
    /// All views together hold more points than can be numbered (u32).
    #[error("the views hold {0} points in all, more than can be numbered")]
    TooManyPointsInAll(usize),
    /// The k-d tree over a view could not be built.
    #[error("view {view}: k-d tree construction failed: {message}")]
    KdTree {
        /// Index of the view.
        view: usize,
        /// The k-d tree library's message.
        message: String,
    },
    /// An initial pose has a NaN or infinite component.
    #[error("initial pose of view {0} is not finite")]
    NonFinitePose(usize),
    /// The reference view index does not name a view.
    #[error("reference view {reference} is out of range for {views} views")]
    ReferenceOutOfRange {
        /// Requested reference index.
        reference: usize,
        /// Number of views.
        views: usize,
    },
    /// A parameter is outside its valid range.
    #[error("parameter `{name}` = {value} is invalid: {reason}")]
    InvalidParameter {
        /// Parameter name.
        name: &'static str,
        /// Value given.
        value: f64,
        /// The valid range.
        reason: &'static str,
    },
    /// The two sides of a set of correspondences have different lengths.
    #[error("{sources} source points but {targets} target points")]
    CorrespondenceMismatch {
        /// Number of source points.
        sources: usize,
        /// Number of target points.
        targets: usize,
    },
    /// A rigid transform needs at least three correspondences.
    #[error("a rigid fit needs at least 3 correspondences, got {0}")]
    TooFewCorrespondences(usize),
    /// The correspondences are (nearly) collinear or coincident, so the rotation is not
    /// determined.
    #[error("the correspondences are collinear or coincident: the rotation is not determined")]
    DegenerateCorrespondences,
    /// The number of view models differs from the number of views.
    #[error("{views} views but {models} view models")]
    ModelCountMismatch {
        /// Views given.
        views: usize,
        /// Models given.
        models: usize,
    },
    /// A [`MapPreparation`](super::MapPreparation) was made from other views, other
    /// noise or other surfel parameters than those it is used with.
    #[error("the MAP preparation does not match the views: {0}")]
    PreparationMismatch(String),
    /// A view model has a non-positive or non-finite σ.
    #[error("view {0}: the noise σ and the prior σ must be finite and > 0 (exponent >= 0)")]
    InvalidViewModel(usize),
}
