//! Shared fixtures of the NBV and planning tests (the scene is also included by the
//! benches).

pub mod brute_force;
pub mod scene;
