//! [`RenderScene`]: everything one picture shows, as plain data in world coordinates.

use super::{Color, Lighting, LineSet, MeshItem, PointSet, VoxelSet};
use nalgebra::Point3;

/// The drawables of one picture, its background and its lights.
///
/// Opaque meshes, voxels, points and lines are depth-tested against each other; meshes
/// whose colour has alpha below 1 are blended in last.
///
/// ```
/// use nbv_sim::render::{Color, LineSet, RenderScene};
/// use nalgebra::Point3;
/// let mut scene = RenderScene::new();
/// scene.add_lines(LineSet::aabb(Point3::origin(), Point3::new(1.0, 2.0, 3.0), Color::BLACK, 2.0));
/// let (lo, hi) = scene.bounds().unwrap();
/// assert_eq!((lo, hi), (Point3::origin(), Point3::new(1.0, 2.0, 3.0)));
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct RenderScene {
    /// Triangle meshes.
    pub meshes: Vec<MeshItem>,
    /// Point sprites.
    pub points: Vec<PointSet>,
    /// Voxel cubes.
    pub voxels: Vec<VoxelSet>,
    /// Line segments.
    pub lines: Vec<LineSet>,
    /// Background colour (alpha is ignored: pictures are opaque).
    pub background: Color,
    /// Light rig.
    pub lighting: Lighting,
}

impl Default for RenderScene {
    fn default() -> Self {
        Self::new()
    }
}

impl RenderScene {
    /// An empty scene on the default light-grey background.
    pub fn new() -> Self {
        Self {
            meshes: Vec::new(),
            points: Vec::new(),
            voxels: Vec::new(),
            lines: Vec::new(),
            background: Color::BACKGROUND,
            lighting: Lighting::default(),
        }
    }

    /// Adds a mesh.
    pub fn add_mesh(&mut self, mesh: MeshItem) -> &mut Self {
        self.meshes.push(mesh);
        self
    }

    /// Adds a set of points.
    pub fn add_points(&mut self, points: PointSet) -> &mut Self {
        self.points.push(points);
        self
    }

    /// Adds a set of voxels.
    pub fn add_voxels(&mut self, voxels: VoxelSet) -> &mut Self {
        self.voxels.push(voxels);
        self
    }

    /// Adds a set of lines.
    pub fn add_lines(&mut self, lines: LineSet) -> &mut Self {
        self.lines.push(lines);
        self
    }

    /// Whether nothing would be drawn.
    pub fn is_empty(&self) -> bool {
        self.meshes.iter().all(|m| m.mesh.triangles.is_empty())
            && self.points.iter().all(|p| p.points.is_empty())
            && self.voxels.iter().all(|v| v.centers.is_empty())
            && self.lines.iter().all(|l| l.segments.is_empty())
    }

    /// Every point that outlines what is drawn, in world coordinates: mesh vertices
    /// (placed), points, voxel cube corners and line end points — for framing cameras.
    pub fn outline_points(&self) -> Vec<Point3<f64>> {
        let mut out = Vec::new();
        for m in &self.meshes {
            out.extend(m.mesh.vertices.iter().map(|v| m.pose * v));
        }
        for p in &self.points {
            out.extend_from_slice(&p.points);
        }
        for v in &self.voxels {
            let h = v.size.abs() / 2.0;
            for c in &v.centers {
                for i in 0..8 {
                    let s = |bit: usize| if i & bit == 0 { -h } else { h };
                    out.push(c + nalgebra::Vector3::new(s(1), s(2), s(4)));
                }
            }
        }
        for l in &self.lines {
            for [a, b] in &l.segments {
                out.push(*a);
                out.push(*b);
            }
        }
        out
    }

    /// Axis-aligned bounds `(min, max)` of everything drawn (finite coordinates only), or
    /// `None` for an empty scene.
    pub fn bounds(&self) -> Option<(Point3<f64>, Point3<f64>)> {
        self.outline_points()
            .into_iter()
            .filter(|p| p.coords.iter().all(|v| v.is_finite()))
            .fold(None, |acc, p| {
                Some(match acc {
                    None => (p, p),
                    Some((lo, hi)) => (lo.inf(&p), hi.sup(&p)),
                })
            })
    }
}
