//! The scene as the pipeline's whole configuration: [`Scene::explore_config`] gathers
//! phase 1, the sweep, `[nbv]`, `[planner]`, `[registration]`, the table and the known
//! obstacles (as the planner's obstacles) and the seed into an [`ExploreConfig`].

use crate::error::{Problem, SceneError};
use crate::placed::obstacle_local_mesh;
use crate::scene::Scene;
use nalgebra::{Isometry3, Vector3};
use nbv_core::kinematics::Joints;
use nbv_core::pipeline::{ExploreConfig, ExploreMode};
use nbv_core::planning::{Obstacle, ObstacleShape, PlannerConfig};
use nbv_core::registration::RegistrationParams;

impl Scene {
    /// The pipeline's configuration for this scene in `mode`.
    ///
    /// ```
    /// use nbv_core::pipeline::ExploreMode;
    /// let scene = nbv_scenes::builtin::load("paper-env1").unwrap();
    /// let c = scene.explore_config(ExploreMode::Hybrid).unwrap();
    /// assert_eq!(c.phase_one.grid.len(), 126_000);
    /// assert_eq!(c.obstacles.len(), 3); // the table, the back panel and the crate
    /// assert_eq!(c.seed, scene.seed);
    /// ```
    pub fn explore_config(&self, mode: ExploreMode) -> Result<ExploreConfig, SceneError> {
        let phase_one = self.phase_one_config()?;
        let mut obstacles = Vec::new();
        let t = &self.table;
        let centre = [
            (t.min[0] + t.max[0]) / 2.0,
            (t.min[1] + t.max[1]) / 2.0,
            (t.min[2] + t.max[2]) / 2.0,
        ];
        let half = [
            (t.max[0] - t.min[0]) / 2.0,
            (t.max[1] - t.min[1]) / 2.0,
            (t.max[2] - t.min[2]) / 2.0,
        ];
        obstacles.push(Obstacle::cuboid("table", centre, half));
        for (i, o) in self.obstacles.iter().enumerate().filter(|(_, o)| o.known) {
            let local = obstacle_local_mesh(o).map_err(|source| SceneError::Mesh {
                file: self.file(),
                key: format!("obstacles[{i}].mesh"),
                source,
            })?;
            let Some((lo, hi)) = local.bounds() else {
                continue;
            };
            // The planner gets the obstacle's box: a link can never end up inside it.
            let c = nalgebra::center(&lo, &hi);
            let half: Vector3<f64> = (hi - lo) / 2.0;
            obstacles.push(Obstacle {
                name: o.name.clone(),
                shape: ObstacleShape::Cuboid {
                    half_extents: [half.x, half.y, half.z],
                },
                pose: o.pose.to_pose() * Isometry3::translation(c.x, c.y, c.z),
            });
        }
        let planner = PlannerConfig {
            max_iterations: self.planner.max_iterations as usize,
            step: self.planner.step_rad,
            shortcut_iterations: self.planner.shortcut_iterations as usize,
            // No point of the robot moves more than half a voxel between two checks.
            max_link_displacement: self.workspace.resolution / 2.0,
            ..PlannerConfig::default()
        };
        planner.validate().map_err(|e| SceneError::Invalid {
            file: self.file(),
            key: "planner".into(),
            problem: Box::new(Problem::OutOfRange {
                value: format!("{:?}", self.planner),
                expected: e.to_string(),
            }),
        })?;
        let sweep = self
            .sweep
            .waypoints_deg
            .iter()
            .map(|w| Joints::from_iterator(w.iter().map(|d| d.to_radians())))
            .collect();
        Ok(ExploreConfig {
            mode,
            sweep,
            sweep_speed: self.sweep.joint_speed_fraction,
            phase_one,
            nbv: self.nbv.params(),
            stop: self.nbv.stop_rule(),
            visited: (self.nbv.visited_min_distance, 20f64.to_radians()),
            max_views_per_object: self.nbv.max_views_per_object as usize,
            planner,
            obstacles,
            registration: RegistrationParams {
                max_correspondence_distance: self.registration.d_max,
                max_iterations: self.registration.max_iterations as usize,
                tolerance: self.registration.tolerance,
                ..RegistrationParams::default()
            },
            registration_points: self.registration.points_per_view as usize,
            object_margin: 0.03,
            seed: self.seed,
        })
    }
}
