//! [`MotionPlanner`]: bidirectional RRT (RRT-Connect, Kuffner & LaValle 2000) in joint
//! space from a start configuration to any of several goal configurations, followed by
//! random shortcutting and optional resampling.

use std::cell::Cell;

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::motion_bound::bisection_order;
use super::path_shortcut::{dedup, interpolate, path_length, shortcut};
use super::{CollisionWorld, MotionBound, PlannerConfig, PlanningError};
use crate::kinematics::{DOF, Joints};
use crate::math::Pose;
use crate::rig::JointPath;

/// Slack on the joint limits for the start and goal configurations (rad).
const LIMIT_SLACK: f64 = 1e-9;

/// What one planning query did.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct PlanStats {
    /// RRT-Connect iterations (samples drawn); 0 when the direct segment was free.
    pub iterations: usize,
    /// Nodes in both trees (start and goal roots included).
    pub nodes: usize,
    /// Nodes in the start's tree (its root included): few against the goals' trees is an
    /// arm boxed in where it stands.
    pub start_nodes: usize,
    /// Configurations checked for collision (goals, edges, shortcuts).
    pub collision_checks: usize,
    /// Joint-space length (rad) of the path the trees produced.
    pub length_before_shortcut: f64,
    /// Joint-space length (rad) after shortcutting.
    pub length_after_shortcut: f64,
    /// Waypoints before shortcutting.
    pub waypoints_before_shortcut: usize,
    /// Shortcuts applied.
    pub shortcuts: usize,
    /// Goals given, and how many of them were usable (within limits, collision free).
    pub goals: usize,
    /// Usable goals.
    pub usable_goals: usize,
}

/// A planned motion.
#[derive(Debug, Clone, PartialEq)]
pub struct PlannedPath {
    /// The waypoints (first = start, last = the reached goal) and the speed fraction.
    pub path: JointPath,
    /// Index, in the goals given, of the goal reached. Its joints with ranges over 2π may
    /// differ from the given goal by whole turns (see
    /// [`PlannerConfig::wide_joint_window`]).
    pub goal_index: usize,
    /// Statistics.
    pub stats: PlanStats,
}

/// A joint-space planner over a [`CollisionWorld`].
///
/// A query ([`MotionPlanner::plan`]):
/// 1. checks the start (limits, collision: [`PlanningError::StartInCollision`]) and keeps the
///    goals that are within the limits and collision free
///    ([`PlanningError::NoGoalCollisionFree`] if none);
/// 2. tries the straight segment to each goal, nearest first;
/// 3. grows a tree from the start and a tree rooted at **every** usable goal: each
///    iteration samples a configuration uniformly within the (windowed) limits, extends one
///    tree one step towards it, then connects the other tree towards the new node as far as
///    it can (repeated steps); trees swap roles every iteration. Nearest neighbours by
///    Euclidean joint distance (linear scan, ties to the oldest node);
/// 4. on connection, shortcuts the path and optionally resamples it;
/// 5. fails with [`PlanningError::BudgetExhausted`] after `max_iterations`.
///
/// Every edge is checked at the resolution of [`MotionBound`] (no robot point moves more
/// than δ = `max_link_displacement` between checks) with the robot padded by δ/2 (see
/// [`CollisionWorld::set_padding`]): every point of the robot is then farther than δ/2
/// from any obstacle at both ends of each check interval and travels at most δ in
/// between, so it cannot reach an obstacle in between (two links, each padded, keep
/// apart likewise). Start and goals must be free with the padding. The random source is a `ChaCha8Rng`
/// seeded by the caller: the same query and seed give the same path (the planner is
/// sequential).
///
/// ```
/// use nbv_core::kinematics::{Joints, Robot};
/// use nbv_core::planning::{CollisionWorld, MotionPlanner, Obstacle, PlannerConfig};
/// let path = nbv_core::kinematics::COMAU_URDF;
/// let robot = Robot::from_urdf_file(path)?;
/// let table = Obstacle::cuboid("table", [0.85, 0.0, 0.125], [0.5, 0.6, 0.125]);
/// let world = CollisionWorld::new(&robot, &[table])?;
/// let planner = MotionPlanner::new(world, PlannerConfig::default())?;
/// let start = Joints::new(0.0, 0.0, -1.57, 0.0, 0.0, 0.0);
/// let goal = Joints::new(0.6, 0.5, -1.9, 0.3, 1.0, 0.2);
/// let planned = planner.plan(&start, &[goal], 7)?;
/// let w = &planned.path.waypoints;
/// assert_eq!((w[0], w[w.len() - 1]), (start, goal));
/// assert!(planner.path_is_free(w));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone)]
pub struct MotionPlanner {
    world: CollisionWorld,
    config: PlannerConfig,
    bound: MotionBound,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Extension {
    Trapped,
    Advanced(usize),
    Reached(usize),
}

#[derive(Debug, Clone, Default)]
struct Tree {
    nodes: Vec<Joints>,
    parents: Vec<Option<usize>>,
    /// For each node, the index of its root's goal (goal tree) or 0 (start tree).
    roots: Vec<usize>,
}

impl Tree {
    fn add(&mut self, q: Joints, parent: Option<usize>, root: usize) -> usize {
        self.nodes.push(q);
        self.parents.push(parent);
        self.roots.push(root);
        self.nodes.len() - 1
    }

    fn nearest(&self, q: &Joints) -> usize {
        let mut best = (0, f64::INFINITY);
        for (i, n) in self.nodes.iter().enumerate() {
            let d = (n - q).norm_squared();
            if d < best.1 {
                best = (i, d);
            }
        }
        best.0
    }

    /// Node `i` and its ancestors up to the root.
    fn branch(&self, mut i: usize) -> Vec<Joints> {
        let mut out = vec![self.nodes[i]];
        while let Some(p) = self.parents[i] {
            out.push(self.nodes[p]);
            i = p;
        }
        out
    }
}

/// One query's state: the counters and the sampling box.
struct Query<'a> {
    planner: &'a MotionPlanner,
    checks: Cell<usize>,
    lower: Joints,
    upper: Joints,
}

impl Query<'_> {
    /// The straight segment from `start` to the nearest usable goal it reaches free of
    /// collision (ties by index), as a path and the goal's index in `usable`.
    fn direct_segment(
        &self,
        start: &Joints,
        usable: &[(usize, Joints)],
    ) -> Option<(Vec<Joints>, usize)> {
        let mut order: Vec<usize> = (0..usable.len()).collect();
        order.sort_by(|&a, &b| {
            (usable[a].1 - start)
                .norm()
                .total_cmp(&(usable[b].1 - start).norm())
                .then(a.cmp(&b))
        });
        order
            .into_iter()
            .find(|&i| self.segment_free(start, &usable[i].1))
            .map(|i| (vec![*start, usable[i].1], i))
    }

    /// RRT-Connect: a tree from the start and one from the usable goals, grown in turns
    /// towards random samples and towards each other until they meet (the path and the
    /// goal's index in `usable`) or the iterations run out; the iterations and nodes go
    /// into `stats`.
    fn rrt_connect(
        &self,
        start: &Joints,
        usable: &[(usize, Joints)],
        rng: &mut ChaCha8Rng,
        stats: &mut PlanStats,
    ) -> Option<(Vec<Joints>, usize)> {
        let mut start_tree = Tree::default();
        start_tree.add(*start, None, 0);
        let mut goal_tree = Tree::default();
        for (i, (_, g)) in usable.iter().enumerate() {
            goal_tree.add(*g, None, i);
        }
        let mut found = None;
        let (mut a, mut b) = (&mut start_tree, &mut goal_tree);
        let mut a_is_start = true;
        for it in 1..=self.planner.config.max_iterations {
            stats.iterations = it;
            let target = self.sample(rng);
            let new = match self.extend(a, &target) {
                Extension::Trapped => None,
                Extension::Advanced(i) | Extension::Reached(i) => Some(i),
            };
            if let Some(i) = new {
                let q_new = a.nodes[i];
                if let Extension::Reached(j) = self.connect(b, &q_new) {
                    let (from_a, from_b) = (a.branch(i), b.branch(j));
                    let (mut s, g, goal) = if a_is_start {
                        (from_a, from_b, b.roots[j])
                    } else {
                        (from_b, from_a, a.roots[i])
                    };
                    s.reverse();
                    // `s` ends and `g` begins at the junction node.
                    s.extend(g.into_iter().skip(1));
                    found = Some((s, goal));
                    break;
                }
            }
            std::mem::swap(&mut a, &mut b);
            a_is_start = !a_is_start;
        }
        stats.nodes = start_tree.nodes.len() + goal_tree.nodes.len();
        stats.start_nodes = start_tree.nodes.len();
        found
    }
}

impl Query<'_> {
    fn free(&self, q: &Joints) -> bool {
        self.checks.set(self.checks.get() + 1);
        !self.planner.world.in_collision(q)
    }

    /// Whether the segment a → b is free, `a` assumed free.
    fn segment_free(&self, a: &Joints, b: &Joints) -> bool {
        let (n, at) = self.planner.edge_steps(a, b);
        bisection_order(n).into_iter().all(|i| self.free(&at(i)))
    }

    fn sample(&self, rng: &mut ChaCha8Rng) -> Joints {
        Joints::from_fn(|k, _| {
            if self.upper[k] > self.lower[k] {
                rng.random_range(self.lower[k]..=self.upper[k])
            } else {
                self.lower[k]
            }
        })
    }

    fn extend(&self, tree: &mut Tree, target: &Joints) -> Extension {
        let near = tree.nearest(target);
        let from = tree.nodes[near];
        let d = (target - from).norm();
        let step = self.planner.config.step;
        let (to, reached) = if d <= step {
            (*target, true)
        } else {
            (from + (target - from) * (step / d), false)
        };
        if !self.segment_free(&from, &to) {
            return Extension::Trapped;
        }
        let root = tree.roots[near];
        let i = tree.add(to, Some(near), root);
        if reached {
            Extension::Reached(i)
        } else {
            Extension::Advanced(i)
        }
    }

    fn connect(&self, tree: &mut Tree, target: &Joints) -> Extension {
        loop {
            match self.extend(tree, target) {
                Extension::Advanced(_) => {}
                other => return other,
            }
        }
    }
}

impl MotionPlanner {
    /// A planner over `world` (the lever arms of its robot are computed here). The world's
    /// padding is raised to half of `config.max_link_displacement` if it is smaller.
    pub fn new(mut world: CollisionWorld, config: PlannerConfig) -> Result<Self, PlanningError> {
        config.validate()?;
        let half = 0.5 * config.max_link_displacement;
        if world.padding() < half {
            world.set_padding(half)?;
        }
        let bound = MotionBound::new(&world);
        Ok(Self {
            world,
            config,
            bound,
        })
    }

    /// The collision world.
    pub fn world(&self) -> &CollisionWorld {
        &self.world
    }

    /// Mutable access to the collision world (e.g. a new reduced map after a view).
    pub fn world_mut(&mut self) -> &mut CollisionWorld {
        &mut self.world
    }

    /// The parameters.
    pub fn config(&self) -> &PlannerConfig {
        &self.config
    }

    /// The motion bound used for edges.
    pub fn motion_bound(&self) -> &MotionBound {
        &self.bound
    }

    /// Whether every segment of `path` is collision free at the planner's edge resolution
    /// (the first waypoint included).
    pub fn path_is_free(&self, path: &[Joints]) -> bool {
        let q = self.query(&[]);
        path.first().is_none_or(|p| q.free(p))
            && path.windows(2).all(|w| q.segment_free(&w[0], &w[1]))
    }

    /// Drops from the world the map voxels the robot touches along `path`, a path it has
    /// executed (checked at the edge resolution): it moved through them, so they are free,
    /// whatever the views since have made of them. Returns how many were dropped.
    ///
    /// A view taken close to the object can add voxels around the arm that stood
    /// there (its own crust of unknown space, a noisy return); without this the arm
    /// can be boxed in where it stands, every step out of it blocked.
    ///
    /// ```
    /// use nalgebra::Point3;
    /// use nbv_core::kinematics::{Joints, comau_smart_six};
    /// use nbv_core::occupancy::{GridGeometry, OccupancyGrid, OccupancyParams, ReducedMap};
    /// use nbv_core::planning::{CollisionWorld, MotionPlanner, PlannerConfig};
    /// // Every voxel in front of the arm occupied, as a view's crust can leave it.
    /// let g = GridGeometry::new(Point3::new(0.6, -0.4, 0.9), Point3::new(1.4, 0.4, 1.5), 0.02)?;
    /// let grid = OccupancyGrid::from_log_odds(g, OccupancyParams::default(), vec![1.0; g.len()])?;
    /// let world = CollisionWorld::new(&comau_smart_six()?, &[])?
    ///     .with_reduced_map(&ReducedMap::from_grid(&grid));
    /// let mut planner = MotionPlanner::new(world, PlannerConfig::default())?;
    /// let swing = |j1| Joints::new(j1, 0.0, -std::f64::consts::FRAC_PI_2, 0.0, 0.0, 0.0);
    /// let way_in = [swing(0.0), swing(0.15)];
    /// assert!(!planner.path_is_free(&way_in));
    /// assert!(planner.clear_way(&way_in) > 0);
    /// assert!(planner.path_is_free(&way_in));
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn clear_way(&mut self, path: &[Joints]) -> usize {
        let mut touched: Vec<usize> = path
            .first()
            .map(|q| self.world.colliding_voxels(q))
            .unwrap_or_default();
        for w in path.windows(2) {
            let (n, at) = self.edge_steps(&w[0], &w[1]);
            for i in 1..=n {
                touched.extend(self.world.colliding_voxels(&at(i)));
            }
        }
        touched.sort_unstable();
        touched.dedup();
        self.world.ignore_voxels(&touched)
    }

    /// The configurations an edge `a → b` is checked at: `n` equal steps, none moving a
    /// link point more than `max_link_displacement`, and the configuration after step
    /// `i` (`1..=n`; `n` is `b`).
    fn edge_steps(&self, a: &Joints, b: &Joints) -> (usize, impl Fn(usize) -> Joints) {
        let n = self.bound.steps(a, b, self.config.max_link_displacement);
        let (a, d) = (*a, b - a);
        (n, move |i| a + d * (i as f64 / n as f64))
    }

    fn query(&self, around: &[Joints]) -> Query<'_> {
        let limits = self.world.robot().limits();
        let mut lower = Joints::from_fn(|k, _| limits[k].lower);
        let mut upper = Joints::from_fn(|k, _| limits[k].upper);
        for k in 0..DOF {
            if limits[k].upper - limits[k].lower > std::f64::consts::TAU && !around.is_empty() {
                let lo = around.iter().map(|q| q[k]).fold(f64::INFINITY, f64::min);
                let hi = around
                    .iter()
                    .map(|q| q[k])
                    .fold(f64::NEG_INFINITY, f64::max);
                lower[k] = (lo - self.config.wide_joint_window).max(limits[k].lower);
                upper[k] = (hi + self.config.wide_joint_window).min(limits[k].upper);
            }
        }
        Query {
            planner: self,
            checks: Cell::new(0),
            lower,
            upper,
        }
    }

    fn within_limits(&self, q: &Joints) -> Option<usize> {
        let limits = self.world.robot().limits();
        (0..DOF).find(|&k| {
            !(q[k] >= limits[k].lower - LIMIT_SLACK && q[k] <= limits[k].upper + LIMIT_SLACK)
        })
    }

    /// Plans from `start` to any of `goals` with the random seed `seed`.
    pub fn plan(
        &self,
        start: &Joints,
        goals: &[Joints],
        seed: u64,
    ) -> Result<PlannedPath, PlanningError> {
        self.check_query(start, goals)?;
        let (usable, out_of_limits) = self.usable_goals(start, goals)?;
        let mut around: Vec<Joints> = usable.iter().map(|(_, g)| *g).collect();
        around.push(*start);
        let query = self.query(&around);
        query.checks.set(1 + goals.len() - out_of_limits);
        let mut stats = PlanStats {
            goals: goals.len(),
            usable_goals: usable.len(),
            ..PlanStats::default()
        };
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let found = match query.direct_segment(start, &usable) {
            Some(found) => {
                stats.nodes = 1 + usable.len();
                stats.start_nodes = 1;
                Some(found)
            }
            None => query.rrt_connect(start, &usable, &mut rng, &mut stats),
        };
        let Some((mut path, goal)) = found else {
            return Err(PlanningError::BudgetExhausted {
                iterations: stats.iterations,
                nodes: stats.nodes,
                start_nodes: stats.start_nodes,
            });
        };
        dedup(&mut path);
        stats.waypoints_before_shortcut = path.len();
        stats.length_before_shortcut = path_length(&path);
        stats.shortcuts = shortcut(
            &mut path,
            self.config.shortcut_iterations,
            &mut rng,
            |p, q| query.segment_free(p, q),
        );
        stats.length_after_shortcut = path_length(&path);
        if let Some(step) = self.config.interpolation_step {
            path = interpolate(&path, step);
        }
        stats.collision_checks = query.checks.get();
        Ok(PlannedPath {
            path: JointPath {
                waypoints: path,
                speed_fraction: self.config.speed_fraction,
            },
            goal_index: usable[goal].0,
            stats,
        })
    }

    /// Checks a query: finite start and goals, at least one goal, the start within the
    /// joint limits and free of collision.
    fn check_query(&self, start: &Joints, goals: &[Joints]) -> Result<(), PlanningError> {
        if !start.iter().all(|v| v.is_finite()) {
            return Err(PlanningError::NonFinite("start configuration"));
        }
        if goals.iter().any(|g| !g.iter().all(|v| v.is_finite())) {
            return Err(PlanningError::NonFinite("goal configuration"));
        }
        if goals.is_empty() {
            return Err(PlanningError::NoGoal);
        }
        if let Some(joint) = self.within_limits(start) {
            return Err(PlanningError::StartOutOfLimits {
                joint,
                value: start[joint],
            });
        }
        if let Some(c) = self.world.first_collision(start) {
            return Err(PlanningError::StartInCollision(c));
        }
        Ok(())
    }

    /// The goals a path may end at, each with its index in `goals`: joints wider than 2π
    /// moved next to the start, then those within the limits and free of collision,
    /// duplicates dropped; and how many were out of the limits. An error when none is
    /// left.
    fn usable_goals(
        &self,
        start: &Joints,
        goals: &[Joints],
    ) -> Result<(Vec<(usize, Joints)>, usize), PlanningError> {
        let limits = self.world.robot().limits();
        let mut usable: Vec<(usize, Joints)> = Vec::new();
        let (mut out_of_limits, mut in_collision, mut first) = (0, 0, None);
        for (gi, g) in goals.iter().enumerate() {
            let mut g = *g;
            for k in 0..DOF {
                if limits[k].upper - limits[k].lower > std::f64::consts::TAU
                    && let Some(v) = limits[k].representative_near(g[k], start[k], LIMIT_SLACK)
                {
                    g[k] = v;
                }
            }
            if self.within_limits(&g).is_some() {
                out_of_limits += 1;
                continue;
            }
            if let Some(c) = self.world.first_collision(&g) {
                in_collision += 1;
                first.get_or_insert(c);
                continue;
            }
            if !usable.iter().any(|(_, u)| (u - g).norm() < 1e-12) {
                usable.push((gi, g));
            }
        }
        if usable.is_empty() {
            return Err(PlanningError::NoGoalCollisionFree {
                goals: goals.len(),
                out_of_limits,
                in_collision,
                first,
            });
        }
        Ok((usable, out_of_limits))
    }

    /// Plans to any IK solution that puts `frame` at `pose` (every branch is a goal).
    pub fn plan_to_pose(
        &self,
        start: &Joints,
        frame: &str,
        pose: &Pose,
        seed: u64,
    ) -> Result<PlannedPath, PlanningError> {
        let goals: Vec<Joints> = self
            .world
            .robot()
            .ik(frame, pose)?
            .into_iter()
            .map(|s| s.joints)
            .collect();
        self.plan(start, &goals, seed)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kinematics::Robot;
    use crate::planning::{Collision, CollisionTarget, Obstacle};
    use std::f64::consts::{FRAC_PI_2, TAU};

    fn robot() -> Robot {
        crate::kinematics::comau_smart_six().unwrap()
    }

    /// A panel in front of the robot, across the forearm's swing at the calibration height.
    fn panel_planner(config: PlannerConfig) -> MotionPlanner {
        let panel = Obstacle::cuboid("panel", [0.9, 0.0, 1.2], [0.3, 0.05, 0.3]);
        MotionPlanner::new(CollisionWorld::new(&robot(), &[panel]).unwrap(), config).unwrap()
    }

    fn arm_at(j1: f64) -> Joints {
        Joints::new(j1, 0.0, -FRAC_PI_2, 0.0, 0.0, 0.0)
    }

    #[test]
    fn plans_around_a_panel() {
        let planner = panel_planner(PlannerConfig::default());
        let (start, goal) = (arm_at(-1.0), arm_at(1.0));
        assert!(
            !planner.path_is_free(&[start, goal]),
            "the straight swing is blocked"
        );
        let p = planner.plan(&start, &[goal], 3).unwrap();
        let w = &p.path.waypoints;
        assert_eq!((w[0], w[w.len() - 1], p.goal_index), (start, goal, 0));
        assert!(planner.path_is_free(w));
        let limits = planner.world().robot().limits();
        assert!(w.iter().all(|q| (0..DOF).all(|k| limits[k].contains(q[k]))));
        let s = p.stats;
        assert!(s.iterations >= 1 && s.nodes >= 3 && s.collision_checks > 0);
        assert!(s.length_after_shortcut <= s.length_before_shortcut + 1e-12);
        assert!((path_length(w) - s.length_after_shortcut).abs() < 1e-9);
        assert_eq!((s.goals, s.usable_goals), (1, 1));
        assert_eq!(p.path.speed_fraction, 0.2);
        // Same seed, same path; whatever the rayon pool.
        let again = planner.plan(&start, &[goal], 3).unwrap();
        assert_eq!(again, p);
        for threads in [1, 2] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            assert_eq!(
                pool.install(|| planner.plan(&start, &[goal], 3)).unwrap(),
                p
            );
        }
    }

    /// The arm stood in occupied voxels all along a path it executed: once the way is
    /// cleared, the path and the way back are free, and the voxels off it stay.
    #[test]
    fn clearing_the_way_in_frees_it_and_nothing_else() {
        use crate::occupancy::{GridGeometry, OccupancyGrid, OccupancyParams, ReducedMap};
        use nalgebra::Point3;
        let g = GridGeometry::new(
            Point3::new(0.6, -0.4, 0.9),
            Point3::new(1.4, 0.4, 1.5),
            0.02,
        )
        .unwrap();
        let grid = OccupancyGrid::from_log_odds(g, OccupancyParams::default(), vec![1.0; g.len()])
            .unwrap();
        let world = CollisionWorld::new(&robot(), &[])
            .unwrap()
            .with_reduced_map(&ReducedMap::from_grid(&grid));
        let mut planner = MotionPlanner::new(world, PlannerConfig::default()).unwrap();
        let before = planner.world().voxel_count();
        let (a, b, off) = (arm_at(0.0), arm_at(0.15), arm_at(-0.15));
        assert!(!planner.path_is_free(&[a, b]));
        let dropped = planner.clear_way(&[a, b]);
        assert!(dropped > 0);
        assert_eq!(planner.world().voxel_count(), before - dropped);
        assert!(planner.path_is_free(&[a, b]) && planner.path_is_free(&[b, a]));
        assert!(
            planner.world().in_collision(&off),
            "voxels off the way stay"
        );
        // Cleared twice: nothing more to drop.
        assert_eq!(planner.clear_way(&[a, b]), 0);
    }

    #[test]
    fn budget_of_one_iteration_fails_typed() {
        let planner = panel_planner(PlannerConfig {
            max_iterations: 1,
            ..PlannerConfig::default()
        });
        match planner.plan(&arm_at(-1.0), &[arm_at(1.0)], 3) {
            Err(PlanningError::BudgetExhausted {
                iterations,
                nodes,
                start_nodes,
            }) => {
                assert_eq!(iterations, 1);
                assert!(nodes >= 2);
                assert!((1..nodes).contains(&start_nodes));
            }
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn direct_segment_multi_goal_wrap_and_interpolation() {
        let planner = MotionPlanner::new(
            CollisionWorld::new(&robot(), &[]).unwrap(),
            PlannerConfig {
                interpolation_step: Some(0.05),
                ..PlannerConfig::default()
            },
        )
        .unwrap();
        let start = arm_at(0.0);
        // Goal 0 self-collides (J5 = 2.2); goal 1 has J6 two turns away from the start.
        let mut bad = arm_at(0.3);
        bad[4] = 2.2;
        let mut good = arm_at(0.3);
        good[5] = 2.0 * TAU + 0.1;
        let p = planner.plan(&start, &[bad, good], 0).unwrap();
        assert_eq!(p.goal_index, 1);
        assert_eq!(
            (p.stats.goals, p.stats.usable_goals, p.stats.iterations),
            (2, 1, 0)
        );
        let w = &p.path.waypoints;
        let end = w[w.len() - 1];
        assert!(
            (end[5] - 0.1).abs() < 1e-12,
            "J6 moved next to the start: {}",
            end[5]
        );
        assert!((end[0] - 0.3).abs() < 1e-12);
        assert!(w.windows(2).all(|s| (s[1] - s[0]).norm() <= 0.05 + 1e-12));
        assert!((path_length(w) - (end - start).norm()).abs() < 1e-9);
    }

    #[test]
    fn bad_queries_are_typed_errors() {
        let planner = panel_planner(PlannerConfig::default());
        let ok = arm_at(0.0);
        assert_eq!(planner.plan(&ok, &[], 0), Err(PlanningError::NoGoal));
        let mut nan = ok;
        nan[2] = f64::NAN;
        assert_eq!(
            planner.plan(&nan, &[ok], 0),
            Err(PlanningError::NonFinite("start configuration"))
        );
        assert_eq!(
            planner.plan(&ok, &[nan], 0),
            Err(PlanningError::NonFinite("goal configuration"))
        );
        let mut out = arm_at(-1.0);
        out[2] = 0.5;
        assert!(matches!(
            planner.plan(&out, &[ok], 0),
            Err(PlanningError::StartOutOfLimits { joint: 2, .. })
        ));
        // The start inside the panel (J1 = 0) and self-colliding.
        assert!(matches!(
            planner.plan(&ok, &[arm_at(1.0)], 0),
            Err(PlanningError::StartInCollision(Collision {
                with: CollisionTarget::Obstacle { .. },
                ..
            }))
        ));
        let mut folded = arm_at(1.0);
        folded[4] = -2.2;
        assert!(matches!(
            planner.plan(&folded, &[arm_at(-1.0)], 0),
            Err(PlanningError::StartInCollision(Collision {
                with: CollisionTarget::Link { .. },
                ..
            }))
        ));
        // Goals: one inside the panel, one outside the limits.
        match planner.plan(&arm_at(1.0), &[ok, out], 0) {
            Err(PlanningError::NoGoalCollisionFree {
                goals,
                out_of_limits,
                in_collision,
                first,
            }) => {
                assert_eq!((goals, out_of_limits, in_collision), (2, 1, 1));
                assert_eq!(
                    first.unwrap().with,
                    CollisionTarget::Obstacle {
                        name: "panel".into()
                    }
                );
            }
            other => panic!("{other:?}"),
        }
        // A pose the arm cannot reach.
        let far = crate::math::pose_from_xyz_rpy([3.0, 0.0, 1.0], [0.0; 3]);
        assert!(matches!(
            planner.plan_to_pose(&arm_at(1.0), "dinast", &far, 0),
            Err(PlanningError::Ik(_))
        ));
        for bad in [
            PlannerConfig {
                max_iterations: 0,
                ..PlannerConfig::default()
            },
            PlannerConfig {
                step: 0.0,
                ..PlannerConfig::default()
            },
            PlannerConfig {
                max_link_displacement: f64::NAN,
                ..PlannerConfig::default()
            },
            PlannerConfig {
                interpolation_step: Some(-1.0),
                ..PlannerConfig::default()
            },
            PlannerConfig {
                wide_joint_window: 0.0,
                ..PlannerConfig::default()
            },
            PlannerConfig {
                speed_fraction: 1.5,
                ..PlannerConfig::default()
            },
        ] {
            assert!(matches!(
                bad.validate(),
                Err(PlanningError::InvalidConfig { .. })
            ));
        }
    }

    #[test]
    fn plan_to_pose_reaches_the_pose() {
        let planner = panel_planner(PlannerConfig::default());
        let start = arm_at(-1.0);
        let target = planner.world().robot().fk(&arm_at(-0.6), "dinast").unwrap();
        let p = planner.plan_to_pose(&start, "dinast", &target, 1).unwrap();
        let end = p.path.waypoints[p.path.waypoints.len() - 1];
        let reached = planner.world().robot().fk(&end, "dinast").unwrap();
        assert!((reached.translation.vector - target.translation.vector).norm() < 1e-9);
        assert!(reached.rotation.angle_to(&target.rotation) < 1e-9);
    }
}
