//! [`mesh_quality`]: a reconstructed surface mesh against the true one, by the protocol of
//! [`model_quality`](super::model_quality) at several tolerances — both meshes sampled
//! densely and uniformly, precision from the reconstruction's samples, completeness from
//! the truth's above the floor — plus the Chamfer distance and the mesh's topology.

use nalgebra::Point3;
use serde::Serialize;

use crate::cloud::nearest_distances;
use crate::mesh::TriMesh;

use super::{f_score, sample_surface};

/// The tolerances (m) a mesh is scored at: 2, 5 and 10 mm.
pub const MESH_TOLERANCES: [f64; 3] = [0.002, 0.005, 0.01];

/// Samples per square metre of either mesh: 0.5 mm apart (a quarter of the finest
/// tolerance).
const SAMPLES_PER_M2: f64 = 1.0 / (0.0005 * 0.0005);

/// Precision, completeness and F-score at each of [`MESH_TOLERANCES`], and the Chamfer
/// distance, of points standing for a reconstruction; shares in `[0, 1]`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ToleranceScores {
    /// The tolerances (m).
    pub tolerances: [f64; 3],
    /// Share of the reconstruction within each tolerance of the truth.
    pub precision: [f64; 3],
    /// Share of the true surface above the floor within each tolerance of the
    /// reconstruction.
    pub completeness: [f64; 3],
    /// The F-score at each tolerance.
    pub f_score: [f64; 3],
    /// Mean of the two directed mean distances (m).
    pub chamfer: f64,
}

/// The result of [`mesh_quality`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MeshQuality {
    /// The scores of the mesh's surface.
    #[serde(flatten)]
    pub scores: ToleranceScores,
    /// Triangles.
    pub triangles: usize,
    /// Edges of one triangle only (the rims of holes and of the open base).
    pub boundary_edges: usize,
    /// Edges of three or more triangles.
    pub non_manifold_edges: usize,
    /// Closed, manifold and consistently oriented ([`TriMesh::is_watertight`]).
    pub watertight: bool,
}

/// Samples of `mesh`, 0.5 mm apart.
fn dense_samples(mesh: &TriMesh, seed: u64) -> Vec<Point3<f64>> {
    let n = ((mesh.area() * SAMPLES_PER_M2).round() as usize).clamp(1_000, 2_000_000);
    sample_surface(mesh, n, seed)
}

/// `points` (a reconstruction: a point model, or a mesh's samples; world frame) against
/// the true `surface` at [`MESH_TOLERANCES`], the true surface sampled 0.5 mm apart and
/// counted above `floor` (z) for completeness. `None` without a finite point or a truth
/// above the floor.
///
/// ```
/// use nbv_core::evaluation::{sample_surface, tolerance_scores};
/// use nbv_core::mesh::TriMesh;
/// let cube = TriMesh::cuboid([0.05; 3]);
/// let s = tolerance_scores(&cube, &sample_surface(&cube, 100_000, 9), f64::MIN, 1).unwrap();
/// assert!(s.f_score[0] > 0.99);
/// ```
pub fn tolerance_scores(
    surface: &TriMesh,
    points: &[Point3<f64>],
    floor: f64,
    seed: u64,
) -> Option<ToleranceScores> {
    let truth = dense_samples(surface, seed);
    let above: Vec<Point3<f64>> = truth.iter().filter(|p| p.z > floor).copied().collect();
    let ours: Vec<Point3<f64>> = points
        .iter()
        .filter(|p| p.iter().all(|c| c.is_finite()))
        .copied()
        .collect();
    if above.is_empty() || ours.is_empty() {
        return None;
    }
    let to_truth = nearest_distances(&truth, &ours);
    let to_ours = nearest_distances(&ours, &above);
    let share = |d: &[f64], t: f64| d.iter().filter(|&&d| d <= t).count() as f64 / d.len() as f64;
    let mean = |d: &[f64]| d.iter().sum::<f64>() / d.len() as f64;
    let precision = MESH_TOLERANCES.map(|t| share(&to_truth, t));
    let completeness = MESH_TOLERANCES.map(|t| share(&to_ours, t));
    Some(ToleranceScores {
        tolerances: MESH_TOLERANCES,
        precision,
        completeness,
        f_score: [0, 1, 2].map(|k| f_score(precision[k], completeness[k])),
        chamfer: 0.5 * (mean(&to_truth) + mean(&to_ours)),
    })
}

/// `mesh` against the true `surface` (both in the world frame): the mesh sampled 0.5 mm
/// apart and scored by [`tolerance_scores`], and its topology. Seeded; `None` for an
/// empty mesh or a truth with nothing above the floor.
///
/// ```
/// use nbv_core::evaluation::mesh_quality;
/// use nbv_core::mesh::TriMesh;
/// let cube = TriMesh::cuboid([0.05; 3]);
/// let q = mesh_quality(&cube, &cube, f64::MIN, 1).unwrap();
/// assert!(q.scores.f_score.iter().all(|f| *f > 0.99));
/// assert!(q.scores.chamfer < 3e-4);
/// assert!(q.watertight);
/// ```
pub fn mesh_quality(
    surface: &TriMesh,
    mesh: &TriMesh,
    floor: f64,
    seed: u64,
) -> Option<MeshQuality> {
    if mesh.triangles.is_empty() {
        return None;
    }
    let scores = tolerance_scores(surface, &dense_samples(mesh, seed ^ 0x5eed), floor, seed)?;
    let (boundary_edges, non_manifold_edges) = mesh.edge_counts();
    Some(MeshQuality {
        scores,
        triangles: mesh.triangles.len(),
        boundary_edges,
        non_manifold_edges,
        watertight: mesh.is_watertight(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Isometry3;

    /// A 10 cm cube against itself moved 3 mm along x, by hand. At 2 mm: the four side
    /// faces slide in their planes, within but for the part of the 3 mm strip pushed past
    /// the +x edge by more than 2 mm (1/100 of each); the +x face stands 3 mm out (none
    /// within); the −x face 3 mm in, within only on its 2 mm rim (1 − 0.96² = 7.8 %):
    /// (4 · 0.99 + 0.078)/6 = 0.673. At 5 and 10 mm all is within. Chamfer: the ±x faces'
    /// 3 mm over a third of the area, the strips' little more: 1.03 mm each way, plus the
    /// samples' spacing on the faces that slide (a point on the surface is ~0.25 mm from the
    /// nearest sample 0.5 mm apart, over two thirds of the area).
    #[test]
    fn a_shifted_cube_by_hand() {
        let cube = TriMesh::cuboid([0.05; 3]);
        let moved = cube.transformed(&Isometry3::translation(0.003, 0.0, 0.0));
        let q = mesh_quality(&cube, &moved, f64::MIN, 3).unwrap().scores;
        assert!((q.precision[0] - 0.673).abs() < 0.01, "{q:?}");
        assert!((q.completeness[0] - 0.673).abs() < 0.01, "{q:?}");
        assert!(q.f_score[1] > 0.995 && q.f_score[2] > 0.995, "{q:?}");
        assert!(
            q.chamfer > 0.00103 && q.chamfer < 0.00103 + 0.0002,
            "{}",
            q.chamfer
        );
    }
}
