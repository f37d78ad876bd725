//! [`describe`]: a summary of a loaded scene — objects with their sizes, positions and
//! (when a [`Reachability`] is supplied) reachable viewpoints, obstacles, the grid.

use crate::error::SceneError;
use crate::mesh_distance::Surfaces;
use crate::reachability::{Reachability, count_reachable, viewing_sphere};
use crate::scene::Scene;
use nalgebra::Point3;
use nbv_core::mesh::TriMesh;
use std::fmt::Write as _;

/// One object's row.
#[derive(Debug, Clone, PartialEq)]
pub struct ObjectSummary {
    /// Object name.
    pub name: String,
    /// Size of the mesh in its own frame (x, y, z extents, m).
    pub size: [f64; 3],
    /// Pose translation (m).
    pub position: [f64; 3],
    /// Yaw (degrees).
    pub yaw_deg: f64,
    /// Centroid of the placed solid (m): the centre of its viewing sphere.
    pub centroid: [f64; 3],
    /// Number of triangles.
    pub triangles: usize,
    /// Distance to the nearest other object or obstacle (m), if within 1 m.
    pub clearance: Option<f64>,
    /// `(reachable, candidates)` viewpoints on the viewing sphere, when a reachability
    /// test was supplied.
    pub reachable_viewpoints: Option<(usize, usize)>,
}

/// One obstacle's row.
#[derive(Debug, Clone, PartialEq)]
pub struct ObstacleSummary {
    /// Obstacle name.
    pub name: String,
    /// World-frame bounds `(min, max)`.
    pub bounds: ([f64; 3], [f64; 3]),
    /// Known to the planner.
    pub known: bool,
}

/// A scene summary.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneSummary {
    /// Scene name.
    pub name: String,
    /// Grid dimensions (voxels).
    pub grid: [usize; 3],
    /// Objects.
    pub objects: Vec<ObjectSummary>,
    /// Obstacles.
    pub obstacles: Vec<ObstacleSummary>,
}

/// Centroid of the solid enclosed by a closed mesh (falls back to the vertex mean).
pub fn solid_centroid(m: &TriMesh) -> Point3<f64> {
    let mut vol = 0.0;
    let mut acc = nalgebra::Vector3::zeros();
    for i in 0..m.triangles.len() {
        let [a, b, c] = m.triangle(i);
        let v = a.coords.dot(&b.coords.cross(&c.coords)) / 6.0;
        vol += v;
        acc += (a.coords + b.coords + c.coords) * (v / 4.0);
    }
    if vol.abs() > 1e-15 {
        Point3::from(acc / vol)
    } else {
        let n = m.vertices.len().max(1) as f64;
        Point3::from(
            m.vertices
                .iter()
                .map(|p| p.coords)
                .sum::<nalgebra::Vector3<f64>>()
                / n,
        )
    }
}

/// Summarises a scene; `reach` (the lead's IK test) fills the reachable-viewpoint column.
pub fn describe(
    scene: &Scene,
    reach: Option<&dyn Reachability>,
) -> Result<SceneSummary, SceneError> {
    let objects = scene.object_meshes()?;
    let obstacles = scene.obstacle_meshes()?;
    let surfaces = Surfaces::new(objects.iter().chain(&obstacles));
    let mut rows = Vec::new();
    for (i, (o, m)) in scene.objects.iter().zip(&objects).enumerate() {
        let local = m.transformed(&o.pose.to_pose().inverse());
        let (lo, hi) = local.bounds().unwrap_or_default();
        let centroid = solid_centroid(m);
        let clearance = (0..objects.len() + obstacles.len())
            .filter(|&j| j != i)
            .filter_map(|j| surfaces.distance_below(i, j, 1.0))
            .fold(None, |acc: Option<f64>, d| {
                Some(acc.map_or(d, |a| a.min(d)))
            });
        let reachable_viewpoints = reach.map(|r| {
            let views = viewing_sphere(&centroid, &scene.nbv);
            (count_reachable(&views, r), views.len())
        });
        rows.push(ObjectSummary {
            name: o.name.clone(),
            size: [hi.x - lo.x, hi.y - lo.y, hi.z - lo.z],
            position: o.pose.xyz,
            yaw_deg: o.pose.rpy_deg[2],
            centroid: [centroid.x, centroid.y, centroid.z],
            triangles: m.triangles.len(),
            clearance,
            reachable_viewpoints,
        });
    }
    let obstacles = scene
        .obstacles
        .iter()
        .zip(&obstacles)
        .map(|(o, m)| {
            let (lo, hi) = m.bounds().unwrap_or_default();
            ObstacleSummary {
                name: o.name.clone(),
                bounds: ([lo.x, lo.y, lo.z], [hi.x, hi.y, hi.z]),
                known: o.known,
            }
        })
        .collect();
    Ok(SceneSummary {
        name: scene.name.clone(),
        grid: scene.workspace.dims(),
        objects: rows,
        obstacles,
    })
}

impl SceneSummary {
    /// A human-readable table.
    pub fn to_text(&self, scene: &Scene) -> String {
        let mut s = String::new();
        let w = &scene.workspace;
        let _ = writeln!(s, "scene {}: {}", self.name, scene.description.trim());
        let _ = writeln!(
            s,
            "workspace [{:.2}, {:.2}, {:.2}]..[{:.2}, {:.2}, {:.2}] m at {} m: {} x {} x {} = {} voxels",
            w.min[0],
            w.min[1],
            w.min[2],
            w.max[0],
            w.max[1],
            w.max[2],
            w.resolution,
            self.grid[0],
            self.grid[1],
            self.grid[2],
            w.voxel_count()
        );
        let t = &scene.table;
        let _ = writeln!(
            s,
            "table [{:.2}, {:.2}]x[{:.2}, {:.2}], top z = {:.3} m; robot {}",
            t.min[0],
            t.max[0],
            t.min[1],
            t.max[1],
            t.top(),
            scene.robot.urdf.display()
        );
        let _ = writeln!(s, "objects ({}):", self.objects.len());
        let _ = writeln!(
            s,
            "  {:<12} {:>21} {:>22} {:>7} {:>7} {:>9} {:>10}",
            "name", "size x*y*z (m)", "position (m)", "yaw", "tris", "gap (m)", "reachable"
        );
        for o in &self.objects {
            let reach = match o.reachable_viewpoints {
                Some((r, n)) => format!("{r}/{n}"),
                None => "n/a".to_owned(),
            };
            let gap = o.clearance.map_or("> 1".to_owned(), |g| format!("{g:.3}"));
            let _ = writeln!(
                s,
                "  {:<12} {:>6.3} {:>6.3} {:>6.3} {:>7.3} {:>6.3} {:>6.3} {:>7.1} {:>7} {:>9} {:>10}",
                o.name,
                o.size[0],
                o.size[1],
                o.size[2],
                o.position[0],
                o.position[1],
                o.position[2],
                o.yaw_deg,
                o.triangles,
                gap,
                reach
            );
        }
        let _ = writeln!(s, "obstacles ({}):", self.obstacles.len());
        for o in &self.obstacles {
            let (lo, hi) = o.bounds;
            let _ = writeln!(
                s,
                "  {:<12} [{:.3}, {:.3}, {:.3}]..[{:.3}, {:.3}, {:.3}] {}",
                o.name,
                lo[0],
                lo[1],
                lo[2],
                hi[0],
                hi[1],
                hi[2],
                if o.known {
                    "known"
                } else {
                    "unknown to the planner"
                }
            );
        }
        if self
            .objects
            .iter()
            .all(|o| o.reachable_viewpoints.is_none())
        {
            let _ = writeln!(
                s,
                "reachable: viewpoints of the viewing sphere (r = {} m) reachable by IK; n/a until a reachability test is plugged in",
                scene.nbv.radius
            );
        }
        s
    }
}
