//! The twin world: a Rapier world holding the robot (loaded from its URDF with
//! `rapier3d-urdf`), the table, the obstacles and the objects, in which the robot is posed
//! kinematically and asked what it touches, and through which sensor rays are cast.

mod contact;
mod frame_caster;
mod from_scene;
mod ray_caster;
mod static_body;
mod twin_world;
mod world_error;

pub use contact::{Contact, Contacted};
pub use from_scene::{SceneWorldError, home_configuration, scene_statics};
pub use ray_caster::{RayCaster, RayHit};
pub use static_body::{StaticBody, StaticShape};
pub use twin_world::TwinWorld;
pub use world_error::WorldError;
