//! Cluster-to-object matching: which scene object (or obstacle, or the table) a phase-1
//! cluster is in truth — by the twin's truth labels, or, for the real rig, by where its
//! centroid lies.

use nalgebra::Vector3;
use nbv_core::mesh::TriMesh;
use nbv_core::pipeline::ObjectExploration;
use nbv_core::rig::TruthLabel;
use nbv_scenes::Scene;

/// The scene object an explored object is: by the truth labels of its cluster when the rig
/// gives them (the twin), else (real drivers, which know no truth) the object whose bounds,
/// grown by [`BOUNDS_SLACK`], hold the cluster's centroid — the nearest such by centre.
pub fn true_object(object: &ObjectExploration, scene: &Scene, meshes: &[TriMesh]) -> Option<usize> {
    if object.cluster.labels.is_some() {
        return true_object_of(&object.cluster, scene);
    }
    let points = &object.cluster.points;
    if points.is_empty() {
        return None;
    }
    let centroid = points.iter().fold(Vector3::zeros(), |a, p| a + p.coords) / points.len() as f64;
    meshes
        .iter()
        .enumerate()
        .filter_map(|(i, mesh)| {
            let (lo, hi) = mesh.bounds()?;
            let inside = (0..3).all(|k| {
                centroid[k] >= lo[k] - BOUNDS_SLACK && centroid[k] <= hi[k] + BOUNDS_SLACK
            });
            inside.then(|| (i, (centroid - (lo.coords + hi.coords) * 0.5).norm()))
        })
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(i, _)| i)
}

/// How far outside an object's bounds a cluster centroid may lie and still be that object
/// (metres): the centroid of a partial view of a convex object lies inside its bounds.
const BOUNDS_SLACK: f64 = 0.02;

/// The scene object most of a cluster's points hit in truth (more than half of them).
pub fn true_object_of(cluster: &nbv_core::cloud::PointCloud, scene: &Scene) -> Option<usize> {
    let labels = cluster.labels.as_ref()?;
    let mut counts = vec![0usize; scene.objects.len()];
    for &l in labels {
        if let Some(TruthLabel::Object(i)) = TruthLabel::from_code(l)
            && let Some(c) = counts.get_mut(i as usize)
        {
            *c += 1;
        }
    }
    let (best, n) = counts
        .iter()
        .enumerate()
        .max_by_key(|(i, n)| (**n, usize::MAX - i))?;
    (2 * n > labels.len()).then_some(best)
}

/// What a cluster is in truth (see [`crate::report::ObjectEntry::truth`]): the scene object it was matched
/// to, else the thing most of its points hit by the truth labels.
pub fn cluster_truth(
    cluster: &nbv_core::cloud::PointCloud,
    scene: &Scene,
    object: Option<usize>,
) -> String {
    if object.is_some() {
        return "object".into();
    }
    let Some(labels) = cluster.labels.as_ref().filter(|l| !l.is_empty()) else {
        return "unknown".into();
    };
    let mut counts = std::collections::BTreeMap::<u32, usize>::new();
    for &l in labels {
        *counts.entry(l).or_default() += 1;
    }
    let (code, n) = counts
        .iter()
        .max_by_key(|(c, n)| (**n, std::cmp::Reverse(**c)))
        .map(|(c, n)| (*c, *n))
        .unwrap_or_default();
    if 2 * n <= labels.len() {
        return "mixed".into();
    }
    match TruthLabel::from_code(code) {
        Some(TruthLabel::Obstacle(k)) => scene.obstacles.get(k as usize).map_or_else(
            || "obstacle".into(),
            |o| {
                let kind = if o.known { "known" } else { "unknown" };
                format!("{kind} obstacle {}", o.name)
            },
        ),
        Some(TruthLabel::Table) => "table".into(),
        Some(TruthLabel::Robot) => "robot".into(),
        Some(TruthLabel::Object(_)) | None => "mixed".into(),
    }
}
