//! [`CollisionWorld`]: the robot against the known obstacles, the reduced map's voxels and
//! itself, at a joint configuration.

use std::fmt;

use super::PlanningError;
use super::obstacle::Obstacle;
use super::parry_bridge::{
    Bounds, ParryPose, ParryShape, bounds_overlap, intersects, obstacle_shape, to_parry,
    world_bounds,
};
use super::robot_shapes::RobotShapes;
use super::shape_core::ShapeCore;
use super::voxel_obstacles::VoxelObstacles;
use crate::kinematics::{Joints, Robot};
use crate::occupancy::{GridGeometry, ReducedMap};

/// Margin (m) added to bounding boxes in the broad phases, covering f32 rounding.
const BOUNDS_MARGIN: f64 = 1e-4;

/// What a robot link touches.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum CollisionTarget {
    /// A voxel of the reduced map (an obstacle because occupied or unknown).
    Voxel {
        /// Its linear index.
        linear: usize,
    },
    /// A known obstacle.
    Obstacle {
        /// Its name.
        name: String,
    },
    /// Another link of the robot (non-adjacent).
    Link {
        /// Its name.
        name: String,
    },
}

/// A contact found at a configuration.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Collision {
    /// The robot link.
    pub link: String,
    /// What it touches.
    pub with: CollisionTarget,
}

impl Collision {
    /// Whether the contact is with a map voxel.
    pub fn is_voxel(&self) -> bool {
        matches!(self.with, CollisionTarget::Voxel { .. })
    }
}

impl fmt::Display for Collision {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.with {
            CollisionTarget::Voxel { linear } => {
                write!(f, "link `{}` touches map voxel {linear}", self.link)
            }
            CollisionTarget::Obstacle { name } => {
                write!(f, "link `{}` touches obstacle `{name}`", self.link)
            }
            CollisionTarget::Link { name } => {
                write!(f, "link `{}` touches link `{name}`", self.link)
            }
        }
    }
}

/// A link shape placed at a configuration.
struct PosedShape {
    pose: ParryPose,
    core: Option<ShapeCore>,
    bounds: Bounds,
    sphere: ([f64; 3], f64),
}

impl PosedShape {
    /// Visits the obstacle voxels this posed `shape` touches
    /// ([`VoxelObstacles::for_each_hit`]).
    fn voxel_hits(
        &self,
        voxels: &VoxelObstacles,
        shape: &ParryShape,
        visit: impl FnMut(usize) -> bool,
    ) -> bool {
        voxels.for_each_hit(
            &self.pose,
            shape,
            self.core.as_ref(),
            &self.bounds,
            self.sphere,
            visit,
        )
    }
}

#[derive(Debug, Clone)]
struct ObstacleEntry {
    name: String,
    shape: ParryShape,
    pose: ParryPose,
    bounds: Bounds,
}

/// The robot's links at a configuration tested against (in this order) themselves
/// (pairs on bodies that are neither the same nor adjacent, see
/// [`Robot::body_of`]), the known obstacles, and the obstacle voxels of a reduced map.
///
/// Obstacle voxels are the occupied and unknown voxels of M̄ (the paper's planning
/// obstacles), each a cube of the voxel's edge, kept as a bitset over the dense lattice:
/// for each link shape only the voxels its bounding box overlaps are tested exactly, with
/// parry (f32). Known obstacles are tested exactly after a bounding-box check.
///
/// ```
/// use nbv_core::kinematics::{Joints, Robot};
/// use nbv_core::planning::{CollisionTarget, CollisionWorld, Obstacle};
/// let path = nbv_core::kinematics::COMAU_URDF;
/// let robot = Robot::from_urdf_file(path)?;
/// let table = Obstacle::cuboid("table", [0.85, 0.0, 0.125], [0.5, 0.6, 0.125]);
/// let world = CollisionWorld::new(&robot, &[table])?;
/// let home = Joints::new(0.0, 0.0, -std::f64::consts::FRAC_PI_2, 0.0, 0.0, 0.0);
/// assert!(world.first_collision(&home).is_none());
/// // Shoulder far forward, elbow folded down: the wrist plunges into the table.
/// let down = Joints::new(0.0, 1.2, -2.2, 0.0, 0.5, 0.0);
/// let hit = world.first_collision(&down).unwrap();
/// assert_eq!(hit.with, CollisionTarget::Obstacle { name: "table".into() });
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone)]
pub struct CollisionWorld {
    robot: Robot,
    links: RobotShapes,
    obstacles: Vec<ObstacleEntry>,
    voxels: Option<VoxelObstacles>,
}

impl CollisionWorld {
    /// The robot (its collision geometry: primitives only) and the known obstacles.
    pub fn new(robot: &Robot, obstacles: &[Obstacle]) -> Result<Self, PlanningError> {
        let links = RobotShapes::new(robot, 0.0)?;
        let mut entries = Vec::with_capacity(obstacles.len());
        for o in obstacles {
            let finite = o.pose.translation.vector.iter().all(|v| v.is_finite())
                && o.pose.rotation.coords.iter().all(|v| v.is_finite());
            if !finite {
                return Err(PlanningError::InvalidObstacle {
                    name: o.name.clone(),
                    reason: "pose is not finite".into(),
                });
            }
            let shape =
                obstacle_shape(&o.shape).map_err(|reason| PlanningError::InvalidObstacle {
                    name: o.name.clone(),
                    reason,
                })?;
            let pose = to_parry(&o.pose);
            let bounds = world_bounds(&pose, &shape, BOUNDS_MARGIN);
            entries.push(ObstacleEntry {
                name: o.name.clone(),
                shape,
                pose,
                bounds,
            });
        }
        Ok(Self {
            robot: robot.clone(),
            links,
            obstacles: entries,
            voxels: None,
        })
    }

    /// Adds the occupied and unknown voxels of a reduced map as obstacles (replacing those
    /// of a previous map).
    pub fn with_reduced_map(mut self, map: &ReducedMap) -> Self {
        self.set_reduced_map(map);
        self
    }

    /// Replaces the obstacle voxels by those of `map` (after each grid update).
    pub fn set_reduced_map(&mut self, map: &ReducedMap) {
        self.voxels = Some(VoxelObstacles::from_reduced_map(map));
    }

    /// Grows every robot primitive by `padding` metres (its Minkowski sum with a ball), so
    /// that a configuration counts as colliding when a link comes closer than `padding` to
    /// an obstacle or voxel, or two links closer than twice `padding` (finite, ≥ 0; default
    /// 0). [`MotionPlanner`](super::MotionPlanner) sets at least half its edge resolution,
    /// which makes its checked edges collision free in between checks too (see
    /// [`MotionBound`](super::MotionBound)).
    pub fn set_padding(&mut self, padding: f64) -> Result<(), PlanningError> {
        self.links = RobotShapes::new(&self.robot, padding)?;
        Ok(())
    }

    /// The padding of the robot's primitives (m).
    pub fn padding(&self) -> f64 {
        self.links.padding
    }

    /// Stops treating the given voxels (linear indices) as obstacles, e.g. the voxels of
    /// unknown space found enveloping the arm at its start configuration
    /// ([`CollisionWorld::colliding_voxels`]). Returns how many were obstacles.
    pub fn ignore_voxels(&mut self, voxels: &[usize]) -> usize {
        self.voxels.as_mut().map_or(0, |v| v.remove(voxels))
    }

    /// The robot.
    pub fn robot(&self) -> &Robot {
        &self.robot
    }

    /// Number of obstacle voxels.
    pub fn voxel_count(&self) -> usize {
        self.voxels.as_ref().map_or(0, VoxelObstacles::len)
    }

    /// The lattice of the obstacle voxels, if a map was added.
    pub fn voxel_geometry(&self) -> Option<&GridGeometry> {
        self.voxels.as_ref().map(VoxelObstacles::geometry)
    }

    /// Number of robot collision primitives.
    pub fn link_shape_count(&self) -> usize {
        self.links.shapes.len()
    }

    /// Number of primitive pairs tested for self-collision.
    pub fn self_pair_count(&self) -> usize {
        self.links.self_pairs.len()
    }

    /// World poses, bounding boxes and bounding spheres of the link shapes at `q`.
    fn posed_links(&self, q: &Joints) -> Vec<PosedShape> {
        let frames = self.robot.link_poses(q);
        self.links
            .shapes
            .iter()
            .map(|s| {
                let world = frames[s.frame] * s.local;
                let pose = to_parry(&world);
                let t = world.translation.vector;
                let core = s.core.map(|k| k.posed(&pose));
                PosedShape {
                    pose,
                    core,
                    bounds: core.map_or_else(
                        || world_bounds(&pose, &s.shape, BOUNDS_MARGIN),
                        |k| k.bounds(BOUNDS_MARGIN),
                    ),
                    sphere: (
                        [t.x, t.y, t.z],
                        s.radius + self.links.padding + BOUNDS_MARGIN,
                    ),
                }
            })
            .collect()
    }

    /// The first contact at `q`, testing self-collision, then obstacles, then voxels (in
    /// collision-geometry order); `None` if `q` is collision free. `q` is not checked
    /// against the joint limits.
    pub fn first_collision(&self, q: &Joints) -> Option<Collision> {
        let posed = self.posed_links(q);
        let shapes = &self.links.shapes;
        for &(i, j) in &self.links.self_pairs {
            let (a, b) = (&posed[i], &posed[j]);
            if bounds_overlap(&a.bounds, &b.bounds)
                && intersects(&a.pose, &shapes[i].shape, &b.pose, &shapes[j].shape)
            {
                return Some(Collision {
                    link: shapes[i].link.clone(),
                    with: CollisionTarget::Link {
                        name: shapes[j].link.clone(),
                    },
                });
            }
        }
        for (s, p) in shapes.iter().zip(&posed) {
            for o in &self.obstacles {
                if bounds_overlap(&p.bounds, &o.bounds)
                    && intersects(&p.pose, &s.shape, &o.pose, &o.shape)
                {
                    return Some(Collision {
                        link: s.link.clone(),
                        with: CollisionTarget::Obstacle {
                            name: o.name.clone(),
                        },
                    });
                }
            }
        }
        if let Some(voxels) = &self.voxels {
            for (s, p) in shapes.iter().zip(&posed) {
                let mut hit = None;
                p.voxel_hits(voxels, &s.shape, |l| {
                    hit = Some(l);
                    false
                });
                if let Some(linear) = hit {
                    return Some(Collision {
                        link: s.link.clone(),
                        with: CollisionTarget::Voxel { linear },
                    });
                }
            }
        }
        None
    }

    /// Whether `q` is in collision.
    pub fn in_collision(&self, q: &Joints) -> bool {
        self.first_collision(q).is_some()
    }

    /// Every obstacle voxel any link touches at `q` (ascending, each once).
    pub fn colliding_voxels(&self, q: &Joints) -> Vec<usize> {
        let Some(voxels) = &self.voxels else {
            return Vec::new();
        };
        let mut out = Vec::new();
        for (s, p) in self.links.shapes.iter().zip(self.posed_links(q)) {
            p.voxel_hits(voxels, &s.shape, |l| {
                out.push(l);
                true
            });
        }
        out.sort_unstable();
        out.dedup();
        out
    }

    /// The link shapes' bodies, local poses and bounding radii (for the motion bound).
    pub(crate) fn shapes(&self) -> &RobotShapes {
        &self.links
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::TriMesh;
    use crate::occupancy::{OccupancyGrid, OccupancyParams, VoxelState};
    use crate::planning::ObstacleShape;
    use nalgebra::Point3;

    fn robot() -> Robot {
        crate::kinematics::comau_smart_six().unwrap()
    }

    fn calibration() -> Joints {
        Joints::new(0.0, 0.0, -std::f64::consts::FRAC_PI_2, 0.0, 0.0, 0.0)
    }

    #[test]
    fn self_collision_skips_adjacent_bodies_only() {
        let r = robot();
        let w = CollisionWorld::new(&r, &[]).unwrap();
        assert_eq!(w.link_shape_count(), 18);
        // Pairs on bodies at least two apart: counted from the bodies of the 18 shapes.
        let bodies: Vec<usize> = r
            .collision_geometry()
            .iter()
            .map(|g| r.body_of(&g.link).unwrap())
            .collect();
        let expected = (0..18)
            .flat_map(|i| (i + 1..18).map(move |j| (i, j)))
            .filter(|&(i, j)| bodies[i].abs_diff(bodies[j]) >= 2)
            .count();
        assert_eq!(w.self_pair_count(), expected);
        assert_eq!(expected, 105);
        assert_eq!(w.first_collision(&calibration()), None);
        // J5 at ±126°: the sensor bracket folds onto the forearm.
        for q5 in [-2.2, 2.2] {
            let q = Joints::new(0.0, 0.0, -1.0, 0.0, q5, 0.0);
            let c = w.first_collision(&q).unwrap();
            assert_eq!(
                c,
                Collision {
                    link: "link_4".into(),
                    with: CollisionTarget::Link {
                        name: "ee_bracket".into()
                    }
                }
            );
            assert_eq!(c.to_string(), "link `link_4` touches link `ee_bracket`");
            assert!(!c.is_voxel());
        }
        // ±1.8 rad is clear.
        assert!(!w.in_collision(&Joints::new(0.0, 0.0, -1.0, 0.0, 1.8, 0.0)));
    }

    /// A grid of 2 cm voxels around the flange in the calibration pose, all empty but the
    /// voxel containing `p` (state given by its log-odds).
    fn single_voxel_map(p: Point3<f64>, value: f32) -> (ReducedMap, usize) {
        let g = GridGeometry::new(
            Point3::new(0.6, -0.3, 0.9),
            Point3::new(1.3, 0.3, 1.5),
            0.02,
        )
        .unwrap();
        let mut v = vec![-1.0f32; g.len()];
        let l = g.linear(g.voxel_of(&p).unwrap()).unwrap();
        v[l] = value;
        let grid = OccupancyGrid::from_log_odds(g, OccupancyParams::default(), v).unwrap();
        (ReducedMap::from_grid(&grid), l)
    }

    /// Every voxel reported touching a link lies within a voxel's half diagonal of a link,
    /// and every voxel whose centre lies deeper in a link than a voxel's half edge is
    /// reported: the test is the links' geometry, not GJK's approximation of it (parry's
    /// GJK reports contact millimetres off the padded links' rounded shapes).
    #[test]
    fn reported_voxels_are_those_the_links_geometry_touches() {
        let r = robot();
        let q = calibration();
        let g = GridGeometry::new(
            Point3::new(0.6, -0.3, 0.9),
            Point3::new(1.3, 0.3, 1.5),
            0.02,
        )
        .unwrap();
        let all = vec![1.0f32; g.len()];
        let grid = OccupancyGrid::from_log_odds(g, OccupancyParams::default(), all).unwrap();
        let map = ReducedMap::from_grid(&grid);
        let w = CollisionWorld::new(&r, &[]).unwrap().with_reduced_map(&map);
        let half = 0.5 * g.resolution();
        let (mut deep, mut shell) = (0, 0);
        // The calibration pose and each wrist joint turned by a few angles (parry's GJK
        // reports contact with voxels 22 mm from a link by centre at some of them).
        let wrist = (3..6).flat_map(|k| [0.0, 0.52, -1.12, 2.09].map(|t| (k, t)));
        for (k, t) in wrist {
            let mut q = q;
            q[k] += t;
            let touching = w.colliding_voxels(&q);
            let cores: Vec<ShapeCore> = w.posed_links(&q).iter().filter_map(|p| p.core).collect();
            assert_eq!(cores.len(), w.link_shape_count());
            for l in 0..g.len() {
                let c = g.center(g.unlinear(l).unwrap());
                let nearest = cores
                    .iter()
                    .map(|core| core.distance(&c))
                    .fold(f64::INFINITY, f64::min);
                let reported = touching.binary_search(&l).is_ok();
                if reported {
                    assert!(
                        nearest <= half * 3f64.sqrt() + 1e-3,
                        "voxel {l} {nearest} m off"
                    );
                    shell += usize::from(nearest > half);
                }
                if nearest < half - 1e-3 {
                    assert!(
                        reported,
                        "voxel {l} {nearest} m inside a link, not reported"
                    );
                    deep += 1;
                }
            }
        }
        assert!(deep > 50 && shell > 0, "{deep} deep, {shell} in the shell");
    }

    #[test]
    fn voxels_are_obstacles_and_can_be_ignored() {
        let r = robot();
        let q = calibration();
        // The Dinast window centre at q, and a point 5 cm in front of it.
        let dinast = r.fk(&q, "dinast").unwrap();
        let inside = dinast * Point3::new(0.0, 0.0, -0.01);
        let ahead = dinast * Point3::new(0.0, 0.0, 0.05);
        for (value, state) in [(1.0, VoxelState::Occupied), (0.0, VoxelState::Unknown)] {
            let (map, l) = single_voxel_map(inside, value);
            assert_eq!(map.state(l), Some(state));
            let mut w = CollisionWorld::new(&r, &[]).unwrap().with_reduced_map(&map);
            assert_eq!(w.voxel_count(), 1);
            let c = w.first_collision(&q).unwrap();
            assert_eq!(c.link, "dinast");
            assert_eq!(c.with, CollisionTarget::Voxel { linear: l });
            assert!(c.is_voxel());
            assert_eq!(w.colliding_voxels(&q), vec![l]);
            assert_eq!(w.ignore_voxels(&[l, l, usize::MAX]), 1);
            assert_eq!(w.voxel_count(), 0);
            assert_eq!(w.first_collision(&q), None);
        }
        // A voxel 5 cm in front of the window is free.
        let (map, _) = single_voxel_map(ahead, 1.0);
        let w = CollisionWorld::new(&r, &[]).unwrap().with_reduced_map(&map);
        assert_eq!(w.first_collision(&q), None);
        assert!(w.colliding_voxels(&q).is_empty());
        // An empty-only map: no obstacle voxel.
        let g = GridGeometry::new(
            Point3::new(0.6, -0.3, 0.9),
            Point3::new(1.3, 0.3, 1.5),
            0.02,
        )
        .unwrap();
        let empty =
            OccupancyGrid::from_log_odds(g, OccupancyParams::default(), vec![-1.0; g.len()])
                .unwrap();
        let w = CollisionWorld::new(&r, &[])
            .unwrap()
            .with_reduced_map(&ReducedMap::from_grid(&empty));
        assert_eq!(w.voxel_count(), 0);
        assert_eq!(w.voxel_geometry(), Some(&g));
    }

    #[test]
    fn obstacles_boxes_and_mesh_surfaces() {
        let r = robot();
        let q = calibration();
        let flange = r.fk(&q, "tool0").unwrap().translation.vector;
        // A box around the flange.
        let around = Obstacle::cuboid("block", [flange.x, flange.y, flange.z], [0.05; 3]);
        let w = CollisionWorld::new(&r, &[around]).unwrap();
        let c = w.first_collision(&q).unwrap();
        assert_eq!(
            c.with,
            CollisionTarget::Obstacle {
                name: "block".into()
            }
        );
        assert!(c.to_string().contains("obstacle `block`"));
        // The same as a mesh: its surface is tested, and a link entirely inside is missed.
        let mut mesh = Obstacle::cuboid("mesh", [flange.x, flange.y, flange.z], [0.05; 3]);
        mesh.shape = ObstacleShape::TriMesh(TriMesh::cuboid([0.05; 3]));
        let w = CollisionWorld::new(&r, &[mesh.clone()]).unwrap();
        assert!(
            w.in_collision(&q),
            "the mesh cuts through the wrist and bracket"
        );
        mesh.shape = ObstacleShape::TriMesh(TriMesh::cuboid([3.0; 3]));
        let w = CollisionWorld::new(&r, &[mesh]).unwrap();
        assert!(!w.in_collision(&q), "documented: mesh surfaces only");
        // Bad obstacles.
        let flat = Obstacle::cuboid("flat", [0.0; 3], [1.0, 1.0, 0.0]);
        assert!(matches!(
            CollisionWorld::new(&r, &[flat]),
            Err(PlanningError::InvalidObstacle { name, .. }) if name == "flat"
        ));
        let mut nan = Obstacle::cuboid("nan", [0.0; 3], [1.0; 3]);
        nan.pose.translation.vector.x = f64::NAN;
        assert!(CollisionWorld::new(&r, &[nan]).is_err());
    }

    #[test]
    fn mesh_links_are_refused() {
        let path = crate::kinematics::COMAU_URDF;
        let text = std::fs::read_to_string(path).unwrap();
        // Replace the first <collision>'s geometry (base_link's foot plate) by a mesh.
        let start = text.find("<collision>").unwrap();
        let g0 = start + text[start..].find("<geometry>").unwrap();
        let g1 = g0 + text[g0..].find("</geometry>").unwrap() + "</geometry>".len();
        let patched = format!(
            "{}<geometry><mesh filename=\"base.stl\"/></geometry>{}",
            &text[..g0],
            &text[g1..]
        );
        let r = Robot::from_urdf_str(&patched).unwrap();
        assert!(matches!(
            CollisionWorld::new(&r, &[]),
            Err(PlanningError::UnsupportedLinkShape { link, .. }) if link == "base_link"
        ));
    }
}
