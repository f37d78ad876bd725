//! Building a [`TwinWorld`] from a validated scene: the robot at its base pose and home
//! configuration, the table, every obstacle (known to the planner or not: the twin is the
//! truth) and every object.

use super::{StaticBody, StaticShape, TwinWorld, WorldError};
use nalgebra::Isometry3;
use nbv_core::kinematics::{Joints, Robot};
use nbv_core::rig::TruthLabel;
use nbv_scenes::Scene;
use nbv_scenes::placed::obstacle_local_mesh;
use thiserror::Error;

/// Why a scene could not become a twin world.
#[derive(Debug, Error)]
pub enum SceneWorldError {
    /// The robot's URDF could not be read as a kinematic model.
    #[error("{scene}: robot: {source}")]
    Robot {
        /// Scene name.
        scene: String,
        /// The kinematic model's error.
        #[source]
        source: nbv_core::kinematics::UrdfError,
    },
    /// A mesh of the scene could not be read.
    #[error("{scene}: {source}")]
    Scene {
        /// Scene name.
        scene: String,
        /// The scene's error.
        #[source]
        source: Box<nbv_scenes::SceneError>,
    },
    /// An obstacle mesh could not be read.
    #[error("{scene}: obstacle `{name}`: {detail}")]
    Obstacle {
        /// Scene name.
        scene: String,
        /// Obstacle name.
        name: String,
        /// What went wrong.
        detail: String,
    },
    /// Rapier refused a part of the world.
    #[error("{scene}: {source}")]
    World {
        /// Scene name.
        scene: String,
        /// The world's error.
        #[source]
        source: WorldError,
    },
}

/// The static bodies of a scene in the world frame: the table (`TruthLabel::Table`), the
/// obstacles (`Obstacle(i)`) and the objects (`Object(i)`), in that order.
pub fn scene_statics(scene: &Scene) -> Result<Vec<StaticBody>, SceneWorldError> {
    let t = &scene.table;
    let half = [0, 1, 2].map(|a| 0.5 * (t.max[a] - t.min[a]));
    let centre = [0, 1, 2].map(|a| 0.5 * (t.max[a] + t.min[a]));
    let mut out = vec![StaticBody {
        name: "table".into(),
        label: TruthLabel::Table,
        shape: StaticShape::Cuboid {
            half_extents: half,
            pose: Isometry3::translation(centre[0], centre[1], centre[2]),
        },
    }];
    for (i, o) in scene.obstacles.iter().enumerate() {
        let shape = match o.box_size {
            // A box obstacle's frame is the centre of its bottom face.
            Some([sx, sy, sz]) => StaticShape::Cuboid {
                half_extents: [0.5 * sx, 0.5 * sy, 0.5 * sz],
                pose: o.pose.to_pose() * Isometry3::translation(0.0, 0.0, 0.5 * sz),
            },
            None => StaticShape::Mesh(
                obstacle_local_mesh(o)
                    .map_err(|e| SceneWorldError::Obstacle {
                        scene: scene.name.clone(),
                        name: o.name.clone(),
                        detail: e.to_string(),
                    })?
                    .transformed(&o.pose.to_pose()),
            ),
        };
        out.push(StaticBody {
            name: o.name.clone(),
            label: TruthLabel::Obstacle(i as u32),
            shape,
        });
    }
    let meshes = scene
        .object_meshes()
        .map_err(|source| SceneWorldError::Scene {
            scene: scene.name.clone(),
            source: Box::new(source),
        })?;
    for (i, (o, mesh)) in scene.objects.iter().zip(meshes).enumerate() {
        out.push(StaticBody {
            name: o.name.clone(),
            label: TruthLabel::Object(i as u32),
            shape: StaticShape::Mesh(mesh),
        });
    }
    Ok(out)
}

/// The scene's home configuration (radians).
pub fn home_configuration(scene: &Scene) -> Joints {
    Joints::from_iterator(scene.robot.home_deg.iter().map(|d| d.to_radians()))
}

impl TwinWorld {
    /// The twin world of a (validated) scene, with the robot at its home configuration.
    ///
    /// ```no_run
    /// let scene = nbv_scenes::builtin::load("paper-env1")?;
    /// let world = nbv_sim::world::TwinWorld::from_scene(&scene)?;
    /// assert!(!world.in_collision());
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn from_scene(scene: &Scene) -> Result<Self, SceneWorldError> {
        let robot =
            Robot::from_urdf_file(&scene.robot.urdf).map_err(|source| SceneWorldError::Robot {
                scene: scene.name.clone(),
                source,
            })?;
        let statics = scene_statics(scene)?;
        TwinWorld::new(
            robot,
            &scene.robot.urdf,
            scene.robot.base.to_pose(),
            statics,
            home_configuration(scene),
        )
        .map_err(|source| SceneWorldError::World {
            scene: scene.name.clone(),
            source,
        })
    }
}
