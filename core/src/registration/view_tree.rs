//! [`ViewTree`]: one view's points in its own frame with a k-d tree built once over them,
//! and the input checks every registration runs before touching the data.
//!
//! Trees are never rebuilt while registering: query points are moved into the view's
//! frame instead (distances are invariant under rigid transforms).

use std::num::NonZeroUsize;

use kiddo::{ImmutableKdTree, SquaredEuclidean};
use nalgebra::Point3;

use super::RegistrationError;
use super::neighbour_graph::NeighbourGraph;
use crate::cloud::PointCloud;
use crate::math::Pose;

/// Coordinates beyond this magnitude (metres) are rejected: no sensor measures them, and
/// the k-d tree reserves `f64::MAX`.
const MAX_COORDINATE: f64 = 1e9;

/// Two, for two-nearest searches.
const TWO: NonZeroUsize = NonZeroUsize::new(2).unwrap();

/// A view's points (own frame) and a k-d tree over them.
pub(crate) struct ViewTree {
    points: Vec<Point3<f64>>,
    tree: ImmutableKdTree<f64, 3>,
    /// Axis-aligned bounds of the points.
    lo: Point3<f64>,
    hi: Point3<f64>,
    /// Each point's nearest neighbours in the view, when built (for repeated searches).
    graph: Option<NeighbourGraph>,
}

impl ViewTree {
    /// Builds the tree (serially, so the tree is the same at any thread count). The cloud
    /// must have passed [`check_view`].
    pub(crate) fn build(view: usize, points: &[Point3<f64>]) -> Result<Self, RegistrationError> {
        let coords: Vec<[f64; 3]> = points.iter().map(|p| [p.x, p.y, p.z]).collect();
        let tree = ImmutableKdTree::<f64, 3>::builder()
            .build_from_slice(&coords)
            .map_err(|e| RegistrationError::KdTree {
                view,
                message: e.to_string(),
            })?;
        let first = points.first().copied().unwrap_or_else(Point3::origin);
        let (lo, hi) = points
            .iter()
            .fold((first, first), |(lo, hi), p| (lo.inf(p), hi.sup(p)));
        Ok(Self {
            points: points.to_vec(),
            tree,
            lo,
            hi,
            graph: None,
        })
    }

    /// [`build`](Self::build), plus the [`NeighbourGraph`] that lets a [`NearestCache`]
    /// (super::nearest_cache::NearestCache) repair answers without searching the tree.
    pub(crate) fn build_with_graph(
        view: usize,
        points: &[Point3<f64>],
    ) -> Result<Self, RegistrationError> {
        let mut tree = Self::build(view, points)?;
        let nearest =
            NeighbourGraph::nearest(&tree.points).map_err(|e| RegistrationError::KdTree {
                view,
                message: e.to_string(),
            })?;
        tree.graph = Some(NeighbourGraph::from_nearest(&nearest));
        Ok(tree)
    }

    /// Attaches a [`NeighbourGraph`] of the view's points made elsewhere (from the
    /// neighbours its surfels were fitted to).
    pub(crate) fn set_graph(&mut self, graph: NeighbourGraph) {
        self.graph = Some(graph);
    }

    /// The neighbour graph, if built.
    pub(crate) fn graph(&self) -> Option<&NeighbourGraph> {
        self.graph.as_ref()
    }

    /// The view's points in its own frame.
    pub(crate) fn points(&self) -> &[Point3<f64>] {
        &self.points
    }

    /// Centroid of the points (view frame).
    pub(crate) fn centroid(&self) -> Point3<f64> {
        let sum = self
            .points
            .iter()
            .fold(nalgebra::Vector3::zeros(), |s, p| s + p.coords);
        Point3::from(sum / self.points.len().max(1) as f64)
    }

    /// Largest coordinate magnitude of the points (view frame), for rounding margins.
    pub(crate) fn scale(&self) -> f64 {
        self.lo.coords.amax().max(self.hi.coords.amax())
    }

    /// Distance from `q` (view frame) to the points' bounding box (0 inside): no point is
    /// closer than this.
    pub(crate) fn distance_to_bounds(&self, q: &Point3<f64>) -> f64 {
        let outside = (self.lo - q)
            .sup(&(q - self.hi))
            .sup(&nalgebra::Vector3::zeros());
        outside.norm()
    }

    /// The nearest point to `q` (view frame) within `radius`, if any, and the distance of
    /// the second nearest within `radius`, if any.
    pub(crate) fn nearest_two_within(
        &self,
        q: &Point3<f64>,
        radius: f64,
    ) -> (Option<usize>, Option<f64>) {
        let mut found = self
            .tree
            .query(&[q.x, q.y, q.z])
            .nearest_n::<SquaredEuclidean<f64>>(TWO)
            .within(radius * radius)
            .execute();
        found.sort_by(|a, b| a.distance.total_cmp(&b.distance).then(a.item.cmp(&b.item)));
        let mut found = found.into_iter();
        (
            found.next().map(|r| r.item as usize),
            found.next().map(|r| r.distance.sqrt()),
        )
    }

    /// The nearest point to `q` (view frame) within `radius`, if any (ties: the lower
    /// index, as the tree returns it).
    pub(crate) fn nearest_within(&self, q: &Point3<f64>, radius: f64) -> Option<usize> {
        if self.distance_to_bounds(q) > radius {
            return None;
        }
        let found = self
            .tree
            .query(&[q.x, q.y, q.z])
            .nearest_one::<SquaredEuclidean<f64>>()
            .execute();
        (found.distance <= radius * radius).then_some(found.item as usize)
    }
}

/// Checks one view: not empty, consistent columns, finite and sane coordinates, and
/// indexable by a u32 k-d tree.
pub(crate) fn check_view(view: usize, cloud: &PointCloud) -> Result<(), RegistrationError> {
    if cloud.is_empty() {
        return Err(RegistrationError::EmptyView(view));
    }
    cloud
        .validate()
        .map_err(|source| RegistrationError::InvalidView { view, source })?;
    if let Some(index) = cloud
        .points
        .iter()
        .position(|p| p.coords.iter().any(|c| c.abs() > MAX_COORDINATE))
    {
        return Err(RegistrationError::PointOutOfRange { view, index });
    }
    if u32::try_from(cloud.len()).is_err() {
        return Err(RegistrationError::TooManyPoints {
            view,
            points: cloud.len(),
        });
    }
    Ok(())
}

/// Checks a multi-view input: at least two views, one finite pose per view, every view
/// valid, the reference index in range.
pub(crate) fn check_views(
    views: &[PointCloud],
    poses: &[Pose],
    reference: usize,
) -> Result<(), RegistrationError> {
    if views.len() < 2 {
        return Err(RegistrationError::TooFewViews(views.len()));
    }
    if poses.len() != views.len() {
        return Err(RegistrationError::PoseCountMismatch {
            views: views.len(),
            poses: poses.len(),
        });
    }
    if reference >= views.len() {
        return Err(RegistrationError::ReferenceOutOfRange {
            reference,
            views: views.len(),
        });
    }
    for (view, cloud) in views.iter().enumerate() {
        check_view(view, cloud)?;
    }
    // Points are numbered globally with u32, u32::MAX being reserved.
    let total: usize = views.iter().map(PointCloud::len).sum();
    if total >= u32::MAX as usize {
        return Err(RegistrationError::TooManyPointsInAll(total));
    }
    for (view, pose) in poses.iter().enumerate() {
        check_pose(view, pose)?;
    }
    Ok(())
}

/// Checks that a pose is finite.
pub(crate) fn check_pose(view: usize, pose: &Pose) -> Result<(), RegistrationError> {
    if pose.to_homogeneous().iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err(RegistrationError::NonFinitePose(view))
    }
}
