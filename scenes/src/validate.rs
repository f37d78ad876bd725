//! Scene validation: every value is checked, with errors that name the file, the key path
//! and the problem ([`SceneError::Invalid`]).
//!
//! Besides ranges and finiteness, it loads every mesh (must be watertight with positive
//! volume) and checks the layout geometrically on the placed meshes:
//! - every object vertex lies inside the workspace;
//! - every object rests on the table: its lowest vertex is within `layout.rest_tolerance`
//!   of the table top, and its contact vertices (within that tolerance of the lowest) lie
//!   over the table;
//! - objects are pairwise at least `layout.min_object_distance` apart, and so are objects
//!   and obstacles — the exact triangle-to-triangle distance of the placed meshes — and
//!   none is inside another (winding number of a vertex);
//! - no obstacle vertex lies inside the table box (deeper than the rest tolerance).

use crate::error::{Problem, SceneError};
use crate::mesh_distance::Surfaces;
use crate::placed::obstacle_local_mesh;
use crate::scene::Scene;
use crate::schema::Check;
use nbv_core::kinematics::Robot;
use nbv_core::mesh::TriMesh;
use nbv_core::mesh::io::read_mesh;
use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};

fn fmt_bounds(m: &TriMesh) -> String {
    match m.bounds() {
        Some((lo, hi)) => format!(
            "[{:.3}, {:.3}, {:.3}]..[{:.3}, {:.3}, {:.3}]",
            lo.x, lo.y, lo.z, hi.x, hi.y, hi.z
        ),
        None => "empty".to_owned(),
    }
}

/// Validates a scene whose paths are already resolved. See the module doc for the rules.
pub fn validate(scene: &Scene) -> Result<(), SceneError> {
    let c = Check { file: scene.file() };
    scalars(scene, &c)?;
    geometry(scene, &c)
}

fn scalars(s: &Scene, c: &Check) -> Result<(), SceneError> {
    c.name("name", &s.name)?;
    if s.seed > i64::MAX as u64 {
        return Err(c.err("seed", Problem::SeedTooLarge(s.seed)));
    }
    s.workspace.check(c)?;
    s.robot.check(c)?;
    s.table.check(c)?;
    s.layout.check(c)?;
    if s.objects.is_empty() {
        return Err(c.err("objects", Problem::Empty));
    }
    // Names are unique across objects and obstacles.
    let mut names = HashSet::new();
    for (i, o) in s.objects.iter().enumerate() {
        o.check(i, c)?;
        if !names.insert(o.name.as_str()) {
            return Err(c.err(
                format!("objects[{i}].name"),
                Problem::Duplicate(o.name.clone()),
            ));
        }
    }
    for (i, o) in s.obstacles.iter().enumerate() {
        o.check(i, c)?;
        if !names.insert(o.name.as_str()) {
            return Err(c.err(
                format!("obstacles[{i}].name"),
                Problem::Duplicate(o.name.clone()),
            ));
        }
    }
    s.sensors.check(c)?;
    s.sweep.check(c)?;
    s.mapping.check(c)?;
    let far = s.sensors.short_range.range[1];
    let expected = format!("[0, sensors.short_range.range[1] = {far}]");
    c.within(
        "mapping.no_return_clearing",
        s.mapping.no_return_clearing,
        0.0,
        far,
        &expected,
    )?;
    s.segmentation.check(c)?;
    s.nbv.check(c)?;
    s.planner.check(c)?;
    s.registration.check(c)?;
    s.errors.check(c)?;
    s.model.check(c)
}

/// The robot's URDF loads as a kinematic model with closed-form IK, carries both sensor
/// frames, and the home configuration is within the joint limits.
fn robot_model(s: &Scene, c: &Check) -> Result<(), SceneError> {
    c.file_exists("robot.urdf", &s.robot.urdf)?;
    let robot = Robot::from_urdf_file(&s.robot.urdf)
        .map_err(|e| c.err("robot.urdf", Problem::Robot(e.to_string())))?;
    robot.ik_parameters().map_err(|e| {
        c.err(
            "robot.urdf",
            Problem::Robot(format!("no closed-form IK: {e}")),
        )
    })?;
    for (key, frame) in [
        ("sensors.mid_range.frame", &s.sensors.mid_range.frame),
        ("sensors.short_range.frame", &s.sensors.short_range.frame),
    ] {
        if robot.frame_index(frame).is_none() {
            let msg = format!("the URDF has no frame `{frame}`");
            return Err(c.err(key, Problem::Robot(msg)));
        }
    }
    for (j, (deg, limit)) in s.robot.home_deg.iter().zip(robot.limits()).enumerate() {
        if !limit.contains(deg.to_radians()) {
            let msg = format!(
                "joint {} at {deg}° is outside its limits [{:.1}°, {:.1}°]",
                j + 1,
                limit.lower.to_degrees(),
                limit.upper.to_degrees()
            );
            return Err(c.err(format!("robot.home_deg[{j}]"), Problem::Robot(msg)));
        }
    }
    Ok(())
}

fn geometry(s: &Scene, c: &Check) -> Result<(), SceneError> {
    robot_model(s, c)?;
    // Load each distinct mesh once.
    let mut cache: HashMap<PathBuf, TriMesh> = HashMap::new();
    let mut load = |key: String, path: &Path| -> Result<TriMesh, SceneError> {
        if let Some(m) = cache.get(path) {
            return Ok(m.clone());
        }
        c.file_exists(&key, path)?;
        let m = read_mesh(path).map_err(|source| SceneError::Mesh {
            file: c.file.clone(),
            key: key.clone(),
            source,
        })?;
        c.watertight(&key, path, &m)?;
        cache.insert(path.to_path_buf(), m.clone());
        Ok(m)
    };
    let mut objects = Vec::with_capacity(s.objects.len());
    for (i, o) in s.objects.iter().enumerate() {
        let local = load(format!("objects[{i}].mesh"), &o.mesh)?;
        objects.push(local.transformed(&o.pose.to_pose()));
    }
    let mut obstacles = Vec::with_capacity(s.obstacles.len());
    for (i, o) in s.obstacles.iter().enumerate() {
        let local = match &o.mesh {
            Some(path) => load(format!("obstacles[{i}].mesh"), path)?,
            None => obstacle_local_mesh(o).map_err(|source| SceneError::Mesh {
                file: c.file.clone(),
                key: format!("obstacles[{i}]"),
                source,
            })?,
        };
        obstacles.push(local.transformed(&o.pose.to_pose()));
    }
    let tol = s.layout.rest_tolerance;
    let top = s.table.top();
    for (i, (o, m)) in s.objects.iter().zip(&objects).enumerate() {
        let key = format!("objects[{i}].pose.xyz");
        if m.vertices
            .iter()
            .any(|p| !s.workspace.contains(&[p.x, p.y, p.z], 1e-9))
        {
            return Err(c.err(
                key,
                Problem::OutsideWorkspace {
                    name: o.name.clone(),
                    bounds: fmt_bounds(m),
                },
            ));
        }
        let low = m.vertices.iter().map(|p| p.z).fold(f64::INFINITY, f64::min);
        if (low - top).abs() > tol {
            return Err(c.err(
                key,
                Problem::NotOnTable {
                    name: o.name.clone(),
                    detail: format!(
                        "its lowest point is at z = {low:.4}, the table top at z = {top:.4} (tolerance {tol})"
                    ),
                },
            ));
        }
        let over_table = |x: f64, y: f64| {
            x >= s.table.min[0] && x <= s.table.max[0] && y >= s.table.min[1] && y <= s.table.max[1]
        };
        if let Some(p) = m
            .vertices
            .iter()
            .find(|p| p.z <= low + tol && !over_table(p.x, p.y))
        {
            return Err(c.err(
                key,
                Problem::NotOnTable {
                    name: o.name.clone(),
                    detail: format!("contact point ({:.3}, {:.3}) is off the table", p.x, p.y),
                },
            ));
        }
    }
    let min = s.layout.min_object_distance;
    let named: Vec<(String, &str, &TriMesh)> = s
        .objects
        .iter()
        .zip(&objects)
        .enumerate()
        .map(|(i, (o, m))| (format!("objects[{i}]"), o.name.as_str(), m))
        .chain(
            s.obstacles
                .iter()
                .zip(&obstacles)
                .enumerate()
                .map(|(i, (o, m))| (format!("obstacles[{i}]"), o.name.as_str(), m)),
        )
        .collect();
    let surfaces = Surfaces::new(named.iter().map(|(_, _, m)| *m));
    for i in 0..s.objects.len() {
        for j in (i + 1)..named.len() {
            let (ka, na, ma) = &named[i];
            let (_, nb, mb) = &named[j];
            let too_close = |distance: f64, note: &str| {
                c.err(
                    format!("{ka}.pose"),
                    Problem::TooClose {
                        a: (*na).to_owned(),
                        b: (*nb).to_owned(),
                        distance,
                        min,
                        note: note.to_owned(),
                    },
                )
            };
            if let Some(d) = surfaces.distance_below(i, j, min.max(1e-9)) {
                let note = if d == 0.0 {
                    " (they touch or intersect)"
                } else {
                    ""
                };
                return Err(too_close(d, note));
            }
            let inside = ma.vertices.first().is_some_and(|p| surfaces.contains(j, p))
                || mb.vertices.first().is_some_and(|p| surfaces.contains(i, p));
            if inside {
                return Err(too_close(0.0, " (one is inside the other)"));
            }
        }
    }
    for (i, (o, m)) in s.obstacles.iter().zip(&obstacles).enumerate() {
        let inside_table = m
            .vertices
            .iter()
            .any(|p| (0..3).all(|a| p[a] > s.table.min[a] + tol && p[a] < s.table.max[a] - tol));
        if inside_table {
            return Err(c.err(
                format!("obstacles[{i}].pose"),
                Problem::IntoTable(o.name.clone()),
            ));
        }
    }
    Ok(())
}
