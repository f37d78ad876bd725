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
use crate::schema::PoseSpec;
use nbv_core::kinematics::Robot;
use nbv_core::mesh::TriMesh;
use nbv_core::mesh::io::read_mesh;
use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};

/// Largest grid accepted (voxels).
const MAX_VOXELS: usize = 100_000_000;

struct Check {
    file: PathBuf,
}

impl Check {
    fn err(&self, key: impl Into<String>, problem: Problem) -> SceneError {
        SceneError::Invalid {
            file: self.file.clone(),
            key: key.into(),
            problem: Box::new(problem),
        }
    }

    fn finite(&self, key: &str, values: &[f64]) -> Result<(), SceneError> {
        match values.iter().find(|v| !v.is_finite()) {
            Some(v) => Err(self.err(key, Problem::NotFinite(v.to_string()))),
            None => Ok(()),
        }
    }

    fn positive(&self, key: &str, v: f64) -> Result<(), SceneError> {
        self.finite(key, &[v])?;
        if v > 0.0 {
            Ok(())
        } else {
            Err(self.err(key, Problem::NotPositive(v.to_string())))
        }
    }

    fn within(
        &self,
        key: &str,
        v: f64,
        lo: f64,
        hi: f64,
        expected: &str,
    ) -> Result<(), SceneError> {
        self.finite(key, &[v])?;
        if v >= lo && v <= hi {
            Ok(())
        } else {
            Err(self.err(
                key,
                Problem::OutOfRange {
                    value: v.to_string(),
                    expected: expected.to_owned(),
                },
            ))
        }
    }

    fn at_least(&self, key: &str, v: u64, lo: u64) -> Result<(), SceneError> {
        if v >= lo {
            Ok(())
        } else {
            Err(self.err(
                key,
                Problem::OutOfRange {
                    value: v.to_string(),
                    expected: format!("at least {lo}"),
                },
            ))
        }
    }

    fn interval(&self, key: &str, r: [f64; 2], positive: bool) -> Result<(), SceneError> {
        self.finite(key, &r)?;
        if positive && r[0] <= 0.0 {
            return Err(self.err(format!("{key}[0]"), Problem::NotPositive(r[0].to_string())));
        }
        if r[0] < r[1] {
            Ok(())
        } else {
            Err(self.err(key, Problem::EmptyRange(format!("[{}, {}]", r[0], r[1]))))
        }
    }

    fn boxed(&self, key: &str, min: [f64; 3], max: [f64; 3]) -> Result<(), SceneError> {
        self.finite(&format!("{key}.min"), &min)?;
        self.finite(&format!("{key}.max"), &max)?;
        for a in 0..3 {
            if min[a] >= max[a] {
                return Err(self.err(
                    format!("{key}.max"),
                    Problem::EmptyRange(format!(
                        "axis {}: min {} >= max {}",
                        ['x', 'y', 'z'][a],
                        min[a],
                        max[a]
                    )),
                ));
            }
        }
        Ok(())
    }

    fn pose(&self, key: &str, p: &PoseSpec) -> Result<(), SceneError> {
        self.finite(&format!("{key}.xyz"), &p.xyz)?;
        self.finite(&format!("{key}.rpy_deg"), &p.rpy_deg)
    }

    fn name(&self, key: &str, name: &str) -> Result<(), SceneError> {
        if name.trim().is_empty() {
            Err(self.err(key, Problem::Empty))
        } else {
            Ok(())
        }
    }

    fn file_exists(&self, key: &str, path: &Path) -> Result<(), SceneError> {
        if path.is_file() {
            Ok(())
        } else {
            Err(self.err(key, Problem::MissingFile(path.to_path_buf())))
        }
    }

    fn watertight(&self, key: &str, path: &Path, mesh: &TriMesh) -> Result<(), SceneError> {
        let detail = if !mesh.is_watertight() {
            Some("open, non-manifold or inconsistently oriented edges".to_owned())
        } else if mesh.volume().is_nan() || mesh.volume() <= 0.0 {
            Some(format!("volume {:.3e} m³", mesh.volume()))
        } else {
            None
        };
        match detail {
            Some(detail) => Err(self.err(
                key,
                Problem::NotWatertight {
                    path: path.to_path_buf(),
                    detail,
                },
            )),
            None => Ok(()),
        }
    }
}

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
    // Workspace and grid.
    let w = &s.workspace;
    c.boxed("workspace", w.min, w.max)?;
    c.positive("workspace.resolution", w.resolution)?;
    for a in 0..3 {
        let side = w.max[a] - w.min[a];
        let n = side / w.resolution;
        if (n - n.round()).abs() > 1e-6 * n.max(1.0) || n.round() < 1.0 {
            return Err(c.err(
                "workspace.resolution",
                Problem::ResolutionNotDividing {
                    resolution: w.resolution,
                    side,
                    axis: ['x', 'y', 'z'][a],
                },
            ));
        }
    }
    let voxels = w
        .dims()
        .iter()
        .try_fold(1usize, |acc, &d| acc.checked_mul(d));
    match voxels {
        Some(v) if v <= MAX_VOXELS => {}
        other => {
            return Err(c.err(
                "workspace",
                Problem::GridTooLarge(other.unwrap_or(usize::MAX)),
            ));
        }
    }
    // Robot and table.
    c.pose("robot.base", &s.robot.base)?;
    c.finite("robot.home_deg", &s.robot.home_deg)?;
    c.boxed("table", s.table.min, s.table.max)?;
    // Layout.
    c.within(
        "layout.min_object_distance",
        s.layout.min_object_distance,
        0.0,
        1.0,
        "[0, 1] m",
    )?;
    c.within(
        "layout.rest_tolerance",
        s.layout.rest_tolerance,
        0.0,
        0.05,
        "[0, 0.05] m",
    )?;
    // Objects and obstacles: names and poses.
    if s.objects.is_empty() {
        return Err(c.err("objects", Problem::Empty));
    }
    let mut names = HashSet::new();
    for (i, o) in s.objects.iter().enumerate() {
        c.name(&format!("objects[{i}].name"), &o.name)?;
        if !names.insert(o.name.as_str()) {
            return Err(c.err(
                format!("objects[{i}].name"),
                Problem::Duplicate(o.name.clone()),
            ));
        }
        c.pose(&format!("objects[{i}].pose"), &o.pose)?;
    }
    for (i, o) in s.obstacles.iter().enumerate() {
        c.name(&format!("obstacles[{i}].name"), &o.name)?;
        if !names.insert(o.name.as_str()) {
            return Err(c.err(
                format!("obstacles[{i}].name"),
                Problem::Duplicate(o.name.clone()),
            ));
        }
        c.pose(&format!("obstacles[{i}].pose"), &o.pose)?;
        match (&o.box_size, &o.mesh) {
            (Some(b), None) => {
                for (a, v) in b.iter().enumerate() {
                    c.positive(&format!("obstacles[{i}].box[{a}]"), *v)?;
                }
            }
            (None, Some(_)) => {}
            _ => return Err(c.err(format!("obstacles[{i}]"), Problem::ShapeChoice)),
        }
    }
    sensors(s, c)?;
    parameters(s, c)
}

fn sensors(s: &Scene, c: &Check) -> Result<(), SceneError> {
    let m = &s.sensors.mid_range;
    c.name("sensors.mid_range.frame", &m.frame)?;
    c.interval("sensors.mid_range.range", m.range, true)?;
    c.within(
        "sensors.mid_range.fov_deg",
        m.fov_deg,
        f64::MIN_POSITIVE,
        360.0,
        "(0, 360] degrees",
    )?;
    c.within(
        "sensors.mid_range.resolution_deg",
        m.resolution_deg,
        1e-4,
        m.fov_deg,
        "[0.0001, fov_deg] degrees",
    )?;
    c.positive("sensors.mid_range.line_rate_hz", m.line_rate_hz)?;
    c.within(
        "sensors.mid_range.noise.range_sigma",
        m.noise.range_sigma,
        0.0,
        1.0,
        "[0, 1] m",
    )?;
    let sr = &s.sensors.short_range;
    c.name("sensors.short_range.frame", &sr.frame)?;
    c.interval("sensors.short_range.range", sr.range, true)?;
    c.within(
        "sensors.short_range.fov_deg",
        sr.fov_deg,
        f64::MIN_POSITIVE,
        179.0,
        "(0, 179] degrees",
    )?;
    c.within(
        "sensors.short_range.width",
        f64::from(sr.width),
        1.0,
        10_000.0,
        "1..=10000 pixels",
    )?;
    c.within(
        "sensors.short_range.height",
        f64::from(sr.height),
        1.0,
        10_000.0,
        "1..=10000 pixels",
    )?;
    c.positive("sensors.short_range.frame_rate_hz", sr.frame_rate_hz)?;
    let n = &sr.noise;
    let k = "sensors.short_range.noise";
    c.within(
        &format!("{k}.range_sigma_at_1m"),
        n.range_sigma_at_1m,
        0.0,
        1.0,
        "[0, 1] m",
    )?;
    c.within(
        &format!("{k}.range_sigma_exponent"),
        n.range_sigma_exponent,
        0.0,
        4.0,
        "[0, 4]",
    )?;
    c.within(
        &format!("{k}.dropout_probability"),
        n.dropout_probability,
        0.0,
        1.0,
        "[0, 1]",
    )?;
    c.within(
        &format!("{k}.grazing_start_deg"),
        n.grazing_start_deg,
        0.0,
        90.0,
        "[0, 90] degrees",
    )?;
    c.within(
        &format!("{k}.grazing_cutoff_deg"),
        n.grazing_cutoff_deg,
        n.grazing_start_deg,
        90.0,
        "[grazing_start_deg, 90] degrees",
    )?;
    c.within(
        &format!("{k}.range_margin"),
        n.range_margin,
        0.0,
        1.0,
        "[0, 1] m",
    )
}

fn parameters(s: &Scene, c: &Check) -> Result<(), SceneError> {
    // Sweep.
    if s.sweep.waypoints_deg.len() < 2 {
        return Err(c.err(
            "sweep.waypoints_deg",
            Problem::OutOfRange {
                value: format!("{} waypoints", s.sweep.waypoints_deg.len()),
                expected: "at least 2".into(),
            },
        ));
    }
    for (i, w) in s.sweep.waypoints_deg.iter().enumerate() {
        c.finite(&format!("sweep.waypoints_deg[{i}]"), w)?;
    }
    c.within(
        "sweep.joint_speed_fraction",
        s.sweep.joint_speed_fraction,
        1e-6,
        1.0,
        "(0, 1]",
    )?;
    // Mapping.
    let m = &s.mapping;
    c.within("mapping.p_hit", m.p_hit, 0.5 + 1e-9, 1.0 - 1e-9, "(0.5, 1)")?;
    let u = m.log_odds_hit();
    c.within(
        "mapping.epsilon_o",
        m.epsilon_o,
        0.0,
        u - 1e-9,
        &format!("[0, u) with u = ln(p_hit/(1-p_hit)) = {u:.4}"),
    )?;
    c.finite("mapping.clamp", &m.clamp)?;
    if !(m.clamp[0] < -m.epsilon_o && m.clamp[1] > m.epsilon_o) {
        return Err(c.err(
            "mapping.clamp",
            Problem::OutOfRange {
                value: format!("[{}, {}]", m.clamp[0], m.clamp[1]),
                expected: "min < -epsilon_o and max > epsilon_o".into(),
            },
        ));
    }
    // Segmentation.
    let g = &s.segmentation;
    c.within("segmentation.voxel", g.voxel, 0.0, 1.0, "[0, 1] m")?;
    c.at_least("segmentation.outlier_k", g.outlier_k.into(), 1)?;
    c.positive("segmentation.outlier_std", g.outlier_std)?;
    c.positive("segmentation.plane_distance", g.plane_distance)?;
    c.at_least(
        "segmentation.plane_iterations",
        g.plane_iterations.into(),
        1,
    )?;
    c.positive("segmentation.cluster_tolerance", g.cluster_tolerance)?;
    c.at_least(
        "segmentation.min_cluster_points",
        g.min_cluster_points.into(),
        1,
    )?;
    c.at_least(
        "segmentation.max_cluster_points",
        g.max_cluster_points.into(),
        g.min_cluster_points.into(),
    )?;
    // NBV.
    let v = &s.nbv;
    c.positive("nbv.radius", v.radius)?;
    c.within(
        "nbv.dtheta_deg",
        v.dtheta_deg,
        0.1,
        180.0,
        "[0.1, 180] degrees",
    )?;
    c.within(
        "nbv.theta_max_deg",
        v.theta_max_deg,
        0.0,
        180.0,
        "[0, 180] degrees",
    )?;
    c.within("nbv.dphi_deg", v.dphi_deg, 0.1, 360.0, "[0.1, 360] degrees")?;
    c.within("nbv.alpha_u", v.alpha_u, 0.0, f64::MAX, "≥ 0")?;
    c.within("nbv.alpha_o", v.alpha_o, 0.0, f64::MAX, "≥ 0")?;
    if v.alpha_u + v.alpha_o <= 0.0 {
        return Err(c.err(
            "nbv.alpha_u",
            Problem::NotPositive("alpha_u + alpha_o = 0".into()),
        ));
    }
    c.within("nbv.gain_threshold", v.gain_threshold, 0.0, f64::MAX, "≥ 0")?;
    c.at_least("nbv.ray_subsample", v.ray_subsample.into(), 1)?;
    c.at_least("nbv.rolls", v.rolls.into(), 1)?;
    c.within(
        "nbv.visited_min_distance",
        v.visited_min_distance,
        0.0,
        10.0,
        "[0, 10] m",
    )?;
    c.at_least("nbv.max_views_per_object", v.max_views_per_object.into(), 1)?;
    c.at_least("nbv.frames_per_view", v.frames_per_view.into(), 1)?;
    c.within("nbv.cost_weight", v.cost_weight, 0.0, f64::MAX, "≥ 0")?;
    c.within(
        "nbv.relative_gain",
        v.relative_gain,
        0.0,
        1.0 - f64::EPSILON,
        "[0, 1)",
    )?;
    // Planner.
    let p = &s.planner;
    c.at_least("planner.max_iterations", p.max_iterations.into(), 1)?;
    c.within("planner.step_rad", p.step_rad, 1e-6, 3.15, "(0, π] rad")?;
    c.within(
        "planner.edge_check_rad",
        p.edge_check_rad,
        1e-6,
        3.15,
        "(0, π] rad",
    )?;
    c.within("planner.goal_bias", p.goal_bias, 0.0, 1.0, "[0, 1]")?;
    c.at_least("planner.tries", p.tries.into(), 1)?;
    // Registration.
    let r = &s.registration;
    c.positive("registration.d_max", r.d_max)?;
    c.at_least("registration.max_iterations", r.max_iterations.into(), 1)?;
    c.positive("registration.tolerance", r.tolerance)?;
    c.at_least("registration.points_per_view", r.points_per_view.into(), 3)?;
    c.positive("registration.max_correction_deg", r.max_correction_deg)?;
    c.positive("registration.max_correction_m", r.max_correction_m)?;
    // Error model.
    let e = &s.errors;
    c.pose("errors.hand_eye", &e.hand_eye)?;
    c.finite("errors.joint_offset_deg", &e.joint_offset_deg)?;
    c.within(
        "errors.pose_noise.translation_sigma",
        e.pose_noise.translation_sigma,
        0.0,
        1.0,
        "[0, 1] m",
    )?;
    c.within(
        "errors.pose_noise.rotation_sigma_deg",
        e.pose_noise.rotation_sigma_deg,
        0.0,
        90.0,
        "[0, 90] degrees",
    )?;
    c.within("errors.scale", e.scale, 0.0, 100.0, "[0, 100]")
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
