//! Seeded random table-top scenes for sweeps: objects from the library at random yaw and
//! position on the table, not touching, and obstacles at the back.
//!
//! The objects come from the paper's six ([`ShapeSet::Paper`], the default) or from the
//! whole library of eleven ([`ShapeSet::All`]: also a figurine with thin legs, ears and
//! tail, a hollow pitcher, a tall bottle, a spatula lying flat and a bowl).
//!
//! Deterministic: the same seed, object count and configuration give the same scene
//! (ChaCha8 seeded with the seed). Placement is conservative — the rotated footprints'
//! bounding rectangles keep `min_gap` apart, so the meshes do too — and every candidate
//! object can be screened by a [`Reachability`] test on its viewing sphere (the lead plugs
//! inverse kinematics in; [`generate`] accepts every pose).

use crate::describe::solid_centroid;
use crate::error::SceneError;
use crate::meshgen::ObjectKind;
use crate::reachability::{Reachability, count_reachable, viewing_sphere};
use crate::scene::Scene;
use crate::schema::*;
use nalgebra::Point3;
use nbv_core::mesh::TriMesh;
use nbv_core::mesh::io::read_mesh;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::collections::HashMap;
use std::path::PathBuf;

/// The objects a generated scene draws from.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash)]
pub enum ShapeSet {
    /// The six objects of the paper's Figure 5 ([`ObjectKind::PAPER`]).
    #[default]
    Paper,
    /// Every library object ([`ObjectKind::ALL`]).
    All,
}

impl ShapeSet {
    /// Every set, in a fixed order.
    pub const ALL: [ShapeSet; 2] = [ShapeSet::Paper, ShapeSet::All];

    /// The set's name in grids and on the command line: `paper` or `all`.
    pub fn name(self) -> &'static str {
        match self {
            ShapeSet::Paper => "paper",
            ShapeSet::All => "all",
        }
    }

    /// The set with this name, if any.
    ///
    /// ```
    /// use nbv_scenes::generator::ShapeSet;
    /// assert_eq!(ShapeSet::from_name("all"), Some(ShapeSet::All));
    /// assert_eq!(ShapeSet::from_name("toys"), None);
    /// ```
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|s| s.name() == name)
    }

    /// The set's objects, in a fixed order.
    pub fn kinds(self) -> &'static [ObjectKind] {
        match self {
            ShapeSet::Paper => &ObjectKind::PAPER,
            ShapeSet::All => &ObjectKind::ALL,
        }
    }
}

impl std::fmt::Display for ShapeSet {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for ShapeSet {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Self::from_name(s).ok_or_else(|| format!("unknown shape set `{s}` (paper | all)"))
    }
}

/// Settings of the generator (not part of scene files: they shape the scenes it writes).
#[derive(Debug, Clone, PartialEq)]
pub struct GeneratorConfig {
    /// Directory holding `<object>.stl` for every library object.
    pub mesh_dir: PathBuf,
    /// The robot URDF the scenes refer to.
    pub urdf: PathBuf,
    /// Range of object positions `[x_min, x_max]` (m).
    pub region_x: [f64; 2],
    /// Range of object positions `[y_min, y_max]` (m).
    pub region_y: [f64; 2],
    /// Smallest gap between the footprint rectangles of two objects (m).
    pub min_gap: f64,
    /// Placement attempts per object before giving up.
    pub attempts: u32,
    /// Smallest number of reachable viewpoints an object's viewing sphere must offer.
    pub min_reachable_viewpoints: usize,
    /// Number of extra random boxes at the back (besides the back panel), inclusive range.
    pub extra_obstacles: [u32; 2],
    /// The objects to draw from.
    pub shapes: ShapeSet,
}

impl Default for GeneratorConfig {
    fn default() -> Self {
        let assets = crate::builtin::assets_dir();
        Self {
            mesh_dir: assets.join("meshes"),
            urdf: assets.join("urdf/comau_smart_six.urdf"),
            // The default sweep sees the table top from x = 0.645 m on (and an object's
            // upper parts a little nearer): a base nearer than 0.66 m leaves most of the
            // object out of phase 1.
            region_x: [0.66, 1.0],
            region_y: [-0.55, 0.55],
            min_gap: 0.10,
            attempts: 500,
            min_reachable_viewpoints: 1,
            extra_obstacles: [0, 2],
            shapes: ShapeSet::Paper,
        }
    }
}

/// A random scene with `n_objects` of the paper's objects (every reachability test passes).
///
/// ```no_run
/// let scene = nbv_scenes::generator::generate(7, 4).unwrap();
/// assert_eq!(scene.objects.len(), 4);
/// ```
pub fn generate(seed: u64, n_objects: usize) -> Result<Scene, SceneError> {
    generate_from(seed, n_objects, ShapeSet::Paper)
}

/// A random scene with `n_objects` objects of the set `shapes` (every reachability test
/// passes); [`generate`] for [`ShapeSet::Paper`].
pub fn generate_from(seed: u64, n_objects: usize, shapes: ShapeSet) -> Result<Scene, SceneError> {
    let all = |_: &nbv_core::math::Pose| true;
    let config = GeneratorConfig {
        shapes,
        ..GeneratorConfig::default()
    };
    generate_with(seed, n_objects, &config, &all)
}

/// A random scene, with an explicit configuration and reachability test.
pub fn generate_with(
    seed: u64,
    n_objects: usize,
    config: &GeneratorConfig,
    reach: &dyn Reachability,
) -> Result<Scene, SceneError> {
    check_request(seed, n_objects, config)?;
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let table = Table {
        min: [0.35, -0.70, 0.0],
        max: [1.35, 0.70, 0.25],
    };
    let kinds = object_kinds(&mut rng, config.shapes, n_objects);
    let meshes =
        library_meshes(config).map_err(|message| SceneError::Generate { seed, message })?;
    let placed = place_objects(&mut rng, &kinds, &meshes, &table, config, reach)
        .map_err(|message| SceneError::Generate { seed, message })?;
    let obstacles = back_obstacles(&mut rng, &placed.rects, table.top(), config);
    Ok(generated_scene(
        seed,
        n_objects,
        config,
        table,
        placed.objects,
        obstacles,
    ))
}

/// Checks what [`generate_with`] is asked for: a seed a scene file holds, an object region
/// with min ≤ max, at least one object.
fn check_request(seed: u64, n_objects: usize, config: &GeneratorConfig) -> Result<(), SceneError> {
    let fail = |message: String| SceneError::Generate { seed, message };
    if seed > i64::MAX as u64 {
        return Err(fail(format!("the seed must be at most {}", i64::MAX)));
    }
    let ordered = |r: [f64; 2]| r[0].is_finite() && r[1].is_finite() && r[0] <= r[1];
    if !ordered(config.region_x) || !ordered(config.region_y) {
        return Err(fail(
            "the object region must be finite with min <= max".into(),
        ));
    }
    if n_objects == 0 {
        return Err(fail("at least one object is needed".into()));
    }
    Ok(())
}

/// The kinds of the `n` objects: shuffled passes over the set, repeated as needed.
fn object_kinds(rng: &mut ChaCha8Rng, shapes: ShapeSet, n: usize) -> Vec<ObjectKind> {
    let mut kinds = Vec::with_capacity(n);
    while kinds.len() < n {
        let mut pass = shapes.kinds().to_vec();
        for i in (1..pass.len()).rev() {
            pass.swap(i, rng.random_range(0..=i));
        }
        kinds.extend(pass);
    }
    kinds.truncate(n);
    kinds
}

/// The mesh of each object of the set, read from `<mesh_dir>/<object>.stl`, with its path.
fn library_meshes(
    config: &GeneratorConfig,
) -> Result<HashMap<ObjectKind, (PathBuf, TriMesh)>, String> {
    let mut meshes = HashMap::new();
    for &kind in config.shapes.kinds() {
        let path = config.mesh_dir.join(format!("{}.stl", kind.name()));
        let mesh = read_mesh(&path).map_err(|e| e.to_string())?;
        meshes.insert(kind, (path, mesh));
    }
    Ok(meshes)
}

/// The objects placed on the table so far.
#[derive(Default)]
struct PlacedObjects {
    /// Their footprint rectangles `[x0, y0, x1, y1]`.
    rects: Vec<[f64; 4]>,
    /// Their specifications.
    objects: Vec<ObjectSpec>,
    /// Objects placed per kind (the second jug is `jug-2`).
    counts: HashMap<ObjectKind, u32>,
}

/// Places one object of each of `kinds` in turn at a random yaw and position in the
/// region: on the table, `min_gap` clear of the others, with enough reachable viewpoints;
/// an error when an object finds no room in `attempts` draws.
fn place_objects(
    rng: &mut ChaCha8Rng,
    kinds: &[ObjectKind],
    meshes: &HashMap<ObjectKind, (PathBuf, TriMesh)>,
    table: &Table,
    config: &GeneratorConfig,
    reach: &dyn Reachability,
) -> Result<PlacedObjects, String> {
    // Placement asks for enough reachable viewpoints of the paper's viewing sphere (the
    // count `min_reachable_viewpoints` is of that sphere); the scene itself gets the
    // default `[nbv]`, the twin preset.
    let sphere = Nbv::preset(NbvPreset::Paper);
    let mut placed = PlacedObjects::default();
    for &kind in kinds {
        let (path, mesh) = &meshes[&kind];
        let found = (0..config.attempts)
            .find_map(|_| draw_placement(rng, mesh, &placed.rects, table, config, &sphere, reach));
        let Some((pose, rect)) = found else {
            return Err(format!(
                "no room for `{}` after {} attempts ({} objects placed)",
                kind.name(),
                config.attempts,
                placed.objects.len()
            ));
        };
        let n = placed.counts.entry(kind).or_insert(0u32);
        *n += 1;
        let name = if *n == 1 {
            kind.name().to_owned()
        } else {
            format!("{}-{}", kind.name(), n)
        };
        placed.rects.push(rect);
        placed.objects.push(ObjectSpec {
            name,
            mesh: path.clone(),
            pose,
        });
    }
    Ok(placed)
}

/// One random pose of `mesh` on the table and its footprint, if it fits: on the table
/// (2 cm from its edges), `min_gap` from the footprints `placed`, and with at least
/// `min_reachable_viewpoints` reachable viewpoints on the viewing sphere of `sphere`.
fn draw_placement(
    rng: &mut ChaCha8Rng,
    mesh: &TriMesh,
    placed: &[[f64; 4]],
    table: &Table,
    config: &GeneratorConfig,
    sphere: &Nbv,
    reach: &dyn Reachability,
) -> Option<(PoseSpec, [f64; 4])> {
    let yaw = rng.random_range(0.0..360.0f64);
    let x = rng.random_range(config.region_x[0]..=config.region_x[1]);
    let y = rng.random_range(config.region_y[0]..=config.region_y[1]);
    let pose = PoseSpec {
        xyz: [round(x), round(y), table.top()],
        rpy_deg: [0.0, 0.0, round(yaw)],
    };
    let world = mesh.transformed(&pose.to_pose());
    let rect = footprint(&world);
    let on_table = rect[0] >= table.min[0] + 0.02
        && rect[2] <= table.max[0] - 0.02
        && rect[1] >= table.min[1] + 0.02
        && rect[3] <= table.max[1] - 0.02;
    let apart = placed.iter().all(|r| rect_gap(r, &rect) >= config.min_gap);
    if !on_table || !apart {
        return None;
    }
    let views = viewing_sphere(&solid_centroid(&world), sphere);
    (count_reachable(&views, reach) >= config.min_reachable_viewpoints).then_some((pose, rect))
}

/// The obstacles at the back: a known back panel and a few boxes (each known with
/// probability 0.8) between x = 1.08 m and the panel, half `min_gap` clear of the objects'
/// footprints `placed` and of each other (a box finding no room in `attempts` draws is
/// left out).
fn back_obstacles(
    rng: &mut ChaCha8Rng,
    placed: &[[f64; 4]],
    top: f64,
    config: &GeneratorConfig,
) -> Vec<ObstacleSpec> {
    let mut obstacles = vec![ObstacleSpec {
        name: "back-panel".into(),
        box_size: Some([
            0.04,
            round(rng.random_range(0.8..1.2)),
            round(rng.random_range(0.30..0.45)),
        ]),
        mesh: None,
        pose: PoseSpec {
            xyz: [
                round(rng.random_range(1.24..1.30)),
                round(rng.random_range(-0.15..0.15)),
                top,
            ],
            rpy_deg: [0.0; 3],
        },
        known: true,
    }];
    let extra = rng.random_range(
        config.extra_obstacles[0]..=config.extra_obstacles[1].max(config.extra_obstacles[0]),
    );
    let mut boxes: Vec<[f64; 4]> = Vec::new();
    for k in 0..extra {
        for _ in 0..config.attempts {
            // Between x = 1.08 and the panel's front face (≥ 1.22).
            let sx = round(rng.random_range(0.08..=0.12));
            let sy = round(rng.random_range(0.10..=0.30));
            let sz = round(rng.random_range(0.30..=0.45));
            let x = round(rng.random_range(1.08 + 0.5 * sx..=1.21 - 0.5 * sx));
            let y = round(rng.random_range(-0.68 + 0.5 * sy..0.68 - 0.5 * sy));
            let rect = [x - 0.5 * sx, y - 0.5 * sy, x + 0.5 * sx, y + 0.5 * sy];
            if placed
                .iter()
                .chain(&boxes)
                .all(|r| rect_gap(r, &rect) >= config.min_gap * 0.5)
            {
                boxes.push(rect);
                obstacles.push(ObstacleSpec {
                    name: format!("box-{}", k + 1),
                    box_size: Some([sx, sy, sz]),
                    mesh: None,
                    pose: PoseSpec {
                        xyz: [x, y, top],
                        rpy_deg: [0.0; 3],
                    },
                    known: rng.random_bool(0.8),
                });
                break;
            }
        }
    }
    obstacles
}

/// The generated scene: its name and description, the paper's workspace, the robot at
/// its home, the objects and obstacles, and every other section at its default.
fn generated_scene(
    seed: u64,
    n_objects: usize,
    config: &GeneratorConfig,
    table: Table,
    objects: Vec<ObjectSpec>,
    obstacles: Vec<ObstacleSpec>,
) -> Scene {
    let (name, from) = match config.shapes {
        ShapeSet::Paper => (format!("random-{seed}"), "the library"),
        ShapeSet::All => (format!("random-{seed}-all"), "the whole library"),
    };
    Scene {
        name,
        description: format!(
            "Random table-top scene: seed {seed}, {n_objects} objects from {from}, obstacles at the back."
        ),
        seed,
        workspace: Workspace {
            min: [0.30, -0.70, 0.23],
            max: [1.50, 0.70, 0.83],
            resolution: 0.02,
        },
        robot: RobotSpec {
            urdf: config.urdf.clone(),
            base: PoseSpec::default(),
            home_deg: [0.0, 0.0, -90.0, 0.0, 90.0, 0.0],
        },
        table,
        objects,
        obstacles,
        layout: Layout::default(),
        sensors: Sensors::default(),
        sweep: Sweep::default(),
        mapping: Mapping::default(),
        segmentation: Segmentation::default(),
        nbv: Nbv::default(),
        planner: Planner::default(),
        registration: Registration::default(),
        errors: ErrorModel::default(),
        model: Model::default(),
        source: None,
    }
}

/// Rounds to 0.1 mm / 0.01° so written scenes read cleanly (and round-trip exactly).
fn round(v: f64) -> f64 {
    (v * 1e4).round() / 1e4
}

/// xy bounding rectangle `[x0, y0, x1, y1]` of a placed mesh.
fn footprint(m: &TriMesh) -> [f64; 4] {
    let (lo, hi) = m.bounds().unwrap_or((Point3::origin(), Point3::origin()));
    [lo.x, lo.y, hi.x, hi.y]
}

/// Gap between two rectangles (0 when they overlap).
fn rect_gap(a: &[f64; 4], b: &[f64; 4]) -> f64 {
    let dx = (b[0] - a[2]).max(a[0] - b[2]).max(0.0);
    let dy = (b[1] - a[3]).max(a[1] - b[3]).max(0.0);
    (dx * dx + dy * dy).sqrt()
}
