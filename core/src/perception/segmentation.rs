//! [`segment_objects`]: phase-1 segmentation of the mid-range cloud into object clusters —
//! crop, voxel filter, statistical outlier removal, table plane (RANSAC + least squares),
//! Euclidean clustering of what stands on the table — and its [`ObjectSegmentation`].

use crate::cloud::{
    Cluster, EuclideanClustering, PlaneFit, PlaneRansac, PointCloud, ProcessingError,
    StatisticalOutlierFilter, VoxelFilter,
};

use nalgebra::{Point3, Vector3};

use super::{
    ObstacleSliver, OrientedBox, PerceptionError, SegmentationParams, merge_bridged_parts,
    merge_fragments, merge_stacked_parts, obstacle_sliver,
};

/// Share of the smaller footprint that must lie under the other for two components to be
/// parts of one object: half, so that touching neighbours never qualify.
const STACKED_SHARE: f64 = 0.5;
/// Widest gap (in clustering tolerances) across which a piece too small to be an object
/// joins its nearest neighbour: the sweep leaves 2.4–2.6 cm between a 15 cm figurine's
/// head, body and legs at the 2 cm tolerance; generated objects stand 10 cm apart.
const FRAGMENT_GAP: f64 = 2.0;
/// Thickest flat layer (4σ, m) taken for a known obstacle's face: the LMS400's range noise
/// (σ 2–4 mm at the workcell's ranges) spread over a few sweep lines.
const SLIVER_THICKNESS: f64 = 0.012;
/// Furthest in front of a known face (m, beyond its exclusion box) a sliver lies.
const SLIVER_REACH: f64 = 0.05;

/// Point counts after each step of [`segment_objects`].
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct SegmentationCounts {
    /// Points in the input cloud.
    pub input: usize,
    /// Inside the region and outside every excluded box.
    pub in_region: usize,
    /// After the voxel filter (equal to `in_region` when it is disabled).
    pub after_voxel: usize,
    /// After outlier removal: the points of [`ObjectSegmentation::filtered`].
    pub after_outliers: usize,
    /// Inliers of the table plane (0 without a plane).
    pub table_inliers: usize,
    /// Points above the table by more than the plane distance: the ones clustered.
    pub above_table: usize,
    /// Points in the kept clusters.
    pub clustered: usize,
    /// Connected components joined to another one: linked by points the outlier filter
    /// removed from a thin part ([`merge_bridged_parts`](super::merge_bridged_parts)),
    /// standing over the same patch of the table
    /// ([`merge_stacked_parts`](super::merge_stacked_parts)), or too small alone and near
    /// another ([`merge_fragments`](super::merge_fragments)).
    pub merged_parts: usize,
    /// Connected components dropped for having fewer than `min_cluster_points` points.
    pub small_components: usize,
    /// Connected components dropped for having more than `max_cluster_points` points.
    pub large_components: usize,
    /// Clusters dropped as a flat sliver of a known obstacle's face
    /// ([`ObjectSegmentation::slivers`]).
    pub slivers: usize,
}

/// What segmentation found. Every index refers to [`ObjectSegmentation::filtered`].
#[derive(Debug, Clone, PartialEq)]
pub struct ObjectSegmentation {
    /// The cropped, downsampled, outlier-free cloud (columns kept in step).
    pub filtered: PointCloud,
    /// The table plane, if a near-horizontal plane was found.
    pub table: Option<PlaneFit>,
    /// The object clusters P_j^0, in the order of their smallest point index.
    pub clusters: Vec<Cluster>,
    /// Clusters that are only a known obstacle's face moved by the pose error
    /// ([`obstacle_sliver`](super::obstacle_sliver)): not objects.
    pub slivers: Vec<(Cluster, ObstacleSliver)>,
    /// Point counts per step.
    pub counts: SegmentationCounts,
}

impl ObjectSegmentation {
    /// The points of cluster `j` (all columns), or `None` if there is no such cluster.
    pub fn cluster_cloud(&self, j: usize) -> Option<PointCloud> {
        self.clusters.get(j).map(|c| c.cloud(&self.filtered))
    }

    /// The points of every cluster, cluster after cluster, with `labels` set to the
    /// cluster's index `j` (0-based).
    pub fn labelled_clusters(&self) -> PointCloud {
        let indices: Vec<usize> = self
            .clusters
            .iter()
            .flat_map(|c| c.indices.iter().copied())
            .collect();
        let mut out = self.filtered.select(&indices);
        out.labels = Some(
            self.clusters
                .iter()
                .enumerate()
                .flat_map(|(j, c)| std::iter::repeat_n(j as u32, c.len()))
                .collect(),
        );
        out
    }
}

fn step(name: &'static str) -> impl Fn(ProcessingError) -> PerceptionError {
    move |source| PerceptionError::Processing { step: name, source }
}

/// Segments `cloud` into object clusters (paper, line 3 of Figure 2):
/// 1. keep the points inside `region` (if given) and outside every `exclude` box (the
///    known obstacles);
/// 2. voxel-grid downsampling ([`VoxelFilter`], if `voxel > 0`);
/// 3. statistical outlier removal ([`StatisticalOutlierFilter`], if `outlier_neighbours > 0`);
/// 4. the dominant near-horizontal plane, the table ([`PlaneRansac`] with the tilt limit);
///    without one every point goes on;
/// 5. the points more than `plane_distance` above the plane are clustered by flood fill
///    ([`EuclideanClustering`]);
/// 6. components standing over the same patch of the table (most of the smaller one's
///    footprint, on a grid of the clustering tolerance) are parts of one object the sweep
///    saw apart, and are merged ([`merge_stacked_parts`](super::merge_stacked_parts)); so
///    are components that the points the outlier filter removed above the table link
///    within the tolerance (a rim, a leg, a tail: thin parts the filter takes for
///    outliers; [`merge_bridged_parts`](super::merge_bridged_parts)); a component too
///    small to be an object joins its nearest neighbour within twice the tolerance (the
///    pieces of a small object; [`merge_fragments`](super::merge_fragments));
///    then clusters outside `[min_cluster_points, max_cluster_points]` (the lower bound
///    counting the removed points a cluster's component holds: its thin parts) are dropped
///    and counted;
/// 7. a cluster that is a flat layer (thinner than 12 mm) parallel to the face of an
///    `exclude` box and at most 5 cm in front of it is that known obstacle's face, moved
///    out of its box by the pose error: it goes to [`ObjectSegmentation::slivers`].
///
/// Deterministic: the result depends on the inputs and the seed only.
///
/// ```
/// use nbv_core::cloud::PointCloud;
/// use nbv_core::perception::{SegmentationParams, segment_objects};
/// use nalgebra::Point3;
/// // A 1 m table at z = 0.25 sampled every 2 cm, and a 10 cm cube standing on it.
/// let mut pts = Vec::new();
/// for i in 0..50 {
///     for j in 0..50 {
///         pts.push(Point3::new(0.5 + i as f64 * 0.02, -0.5 + j as f64 * 0.02, 0.25));
///     }
/// }
/// for i in 0..10 {
///     for j in 0..10 {
///         for k in 0..10 {
///             pts.push(Point3::new(0.9 + i as f64 * 0.01, j as f64 * 0.01, 0.255 + k as f64 * 0.01));
///         }
///     }
/// }
/// let params = SegmentationParams { voxel: 0.0, outlier_neighbours: 0, ..Default::default() };
/// let seg = segment_objects(&PointCloud::from_points(pts), &params, None, &[]).unwrap();
/// assert_eq!(seg.clusters.len(), 1);
/// assert_eq!(seg.clusters[0].len(), 900); // the bottom layer is within 1 cm of the table
/// assert_eq!(seg.counts.table_inliers, 2500 + 100);
/// assert!((seg.table.unwrap().offset + 0.25).abs() < 1e-3);
/// ```
pub fn segment_objects(
    cloud: &PointCloud,
    params: &SegmentationParams,
    region: Option<&OrientedBox>,
    exclude: &[OrientedBox],
) -> Result<ObjectSegmentation, PerceptionError> {
    params.validate()?;
    cloud
        .validate()
        .map_err(|e| step("input cloud")(ProcessingError::Cloud(e)))?;
    let mut counts = SegmentationCounts {
        input: cloud.len(),
        ..SegmentationCounts::default()
    };
    let kept = cloud.retain_indices(|i| {
        let p = &cloud.points[i];
        region.is_none_or(|r| r.contains(p)) && !exclude.iter().any(|b| b.contains(p))
    });
    counts.in_region = kept.len();
    if kept.is_empty() {
        return Err(PerceptionError::NothingInRegion {
            points: cloud.len(),
        });
    }
    let voxels = (params.voxel > 0.0).then_some(VoxelFilter {
        leaf_size: params.voxel,
    });
    let down = match &voxels {
        Some(f) => f.filter(&kept).map_err(step("voxel filter"))?,
        None => kept,
    };
    counts.after_voxel = down.len();
    // The removed points stay at hand: the thin parts of objects are among them.
    let (filtered, removed) = if params.outlier_neighbours > 0 {
        let inliers = StatisticalOutlierFilter {
            neighbours: params.outlier_neighbours,
            std_mul: params.outlier_std,
        }
        .inliers(&down)
        .map_err(step("outlier removal"))?;
        let mut keep = vec![false; down.len()];
        inliers.iter().for_each(|&i| keep[i] = true);
        let removed: Vec<Point3<f64>> = (0..down.len())
            .filter(|&i| !keep[i])
            .map(|i| down.points[i])
            .collect();
        (down.select(&inliers), removed)
    } else {
        (down, Vec::new())
    };
    counts.after_outliers = filtered.len();
    let ransac = PlaneRansac {
        distance_threshold: params.plane_distance,
        iterations: params.plane_iterations,
        max_tilt: Some(params.plane_max_tilt),
        seed: params.seed,
    };
    let table = match ransac.fit(&filtered) {
        Ok(fit) => Some(fit),
        Err(ProcessingError::NoPlaneFound { .. } | ProcessingError::TooFewPoints { .. }) => None,
        Err(e) => return Err(step("table plane")(e)),
    };
    counts.table_inliers = table.as_ref().map_or(0, |t| t.inliers.len());
    let candidates: Vec<usize> = (0..filtered.len())
        .filter(|&i| {
            table
                .as_ref()
                .is_none_or(|t| t.signed_distance(&filtered.points[i]) > params.plane_distance)
        })
        .collect();
    counts.above_table = candidates.len();
    let mut clusters = Vec::new();
    let mut slivers = Vec::new();
    if !candidates.is_empty() {
        let above = filtered.select(&candidates);
        let components = EuclideanClustering {
            tolerance: params.cluster_tolerance,
            min_size: 1,
            max_size: usize::MAX,
        }
        .clusters(&above)
        .map_err(step("clustering"))?;
        let up = table.as_ref().map_or_else(Vector3::z_axis, |t| t.normal);
        let (components, stacked) = merge_stacked_parts(
            &above.points,
            components,
            &up,
            params.cluster_tolerance,
            STACKED_SHARE,
        );
        let removed_above: Vec<Point3<f64>> = removed
            .into_iter()
            .filter(|p| {
                table
                    .as_ref()
                    .is_none_or(|t| t.signed_distance(p) > params.plane_distance)
            })
            .collect();
        let (components, thin, bridged) = merge_bridged_parts(
            &above.points,
            components,
            &removed_above,
            params.cluster_tolerance,
        )
        .map_err(step("clustering"))?;
        // A small object the sweep saw in pieces is judged by its size, not each piece's.
        let (components, thin, fragments) = merge_fragments(
            &above.points,
            components,
            &thin,
            params.min_cluster_points,
            FRAGMENT_GAP * params.cluster_tolerance,
        );
        counts.merged_parts = bridged + stacked + fragments;
        for (mut c, thin) in components.into_iter().zip(thin) {
            // An object's thin parts count towards its size, though not among its points.
            if c.len() + thin < params.min_cluster_points {
                counts.small_components += 1;
            } else if c.len() > params.max_cluster_points {
                counts.large_components += 1;
            } else {
                // Back to indices of `filtered` (candidates ascend, so these still do).
                for i in &mut c.indices {
                    *i = candidates[*i];
                }
                if let Some(s) = obstacle_sliver(
                    &filtered.points,
                    &c,
                    exclude,
                    SLIVER_THICKNESS,
                    SLIVER_REACH,
                ) {
                    counts.slivers += 1;
                    slivers.push((c, s));
                    continue;
                }
                counts.clustered += c.len();
                clusters.push(c);
            }
        }
    }
    Ok(ObjectSegmentation {
        filtered,
        table,
        clusters,
        slivers,
        counts,
    })
}
