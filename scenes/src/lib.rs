//! # nbv-scenes
//!
//! Scene files (TOML) of nbv-twin: the workspace, the robot, the sensors, the objects and
//! obstacles on the table, the planner/NBV/registration parameters, the error model and
//! the seed — with validation that names the file, the key and the problem.
//!
//! - [`Scene`]: load ([`Scene::load`]), validate, save; [`schema`] documents every key.
//! - [`builtin`]: the paper's two environments, embedded.
//! - [`generator`]: seeded random table-top scenes.
//! - [`meshgen`]: the object meshes (jug, two bottles, mallet, horse, box).
//! - [`overrides`]: a scene with dotted keys set (`--set`, a sweep's `[params]`), and a
//!   scene by path or built-in name.
//! - [`reachability`]: viewing-sphere viewpoints (eq. (3)) and the pluggable "is this
//!   sensor pose reachable" test that `describe` and the generator use.
//!
//! ```
//! // Parse only (`Scene::load` / `builtin::load` also resolve paths and validate).
//! let text = nbv_scenes::builtin::text("paper-env2").unwrap();
//! let scene = nbv_scenes::Scene::parse(text, "paper-env2.toml".as_ref()).unwrap();
//! assert_eq!(scene.workspace.dims(), [60, 70, 30]);
//! assert!(scene.obstacles.iter().all(|o| o.known));
//! assert_eq!(scene.nbv.radius, 0.45); // tuned for the twin (the paper's 0.3 is the default)
//! assert_eq!(scene.planner.max_iterations, 4000); // a default: env2 has no [planner] section
//! ```

pub mod builtin;
pub mod describe;
pub mod error;
pub mod explore_config;
pub mod generator;
pub mod mesh_distance;
pub mod meshgen;
mod nbv_params;
pub mod overrides;
pub mod paths;
pub mod pipeline_params;
pub mod placed;
pub mod reachability;
pub mod scene;
pub mod schema;
pub mod validate;

pub use error::{Problem, SceneError};
pub use scene::Scene;
