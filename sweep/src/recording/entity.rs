//! The entity paths of an episode recording, named by the paper's terms: one place, so
//! the recorder and whoever reads a recording back agree.

/// The world frame (z up).
pub const WORLD: &str = "world";
/// The robot; each link is a child (`world/robot/<link>`).
pub const ROBOT: &str = "world/robot";
/// The current laser scan line of the phase-1 sweep.
pub const SWEEP_LINE: &str = "world/sweep/line";
/// The phase-1 object clusters.
pub const CLUSTERS: &str = "world/sweep/clusters";
/// Occupied voxels of the reduced map.
pub const GRID_OCCUPIED: &str = "world/grid/occupied";
/// Unknown voxels of the reduced map (the unknown crust around what was seen).
pub const GRID_UNKNOWN: &str = "world/grid/unknown";
/// The decisions, as a text log.
pub const LOG: &str = "log";
/// The timeline of the rig's clock (seconds).
pub const SIM_TIME: &str = "sim_time";
/// The timeline of pipeline events.
pub const STEP: &str = "step";

/// Batch `k` of the growing phase-1 cloud.
pub fn sweep_cloud(k: usize) -> String {
    format!("world/sweep/cloud/{k:03}")
}

/// Object `j`'s next-best-view loop, or one of its parts (`candidates`, `failed`,
/// `path`, `camera`, `frame`).
///
/// ```
/// assert_eq!(nbv_sweep::recording::entity::object(2, "camera"), "world/objects/2/camera");
/// ```
pub fn object(j: usize, part: &str) -> String {
    format!("world/objects/{j}/{part}")
}

/// View `k` (1-based, as the report counts) of object `j`: the object's points of it.
///
/// ```
/// assert_eq!(nbv_sweep::recording::entity::view(0, 3), "world/objects/0/views/view_03");
/// ```
pub fn view(j: usize, k: usize) -> String {
    format!("world/objects/{j}/views/view_{k:02}")
}

/// Object `j`'s model, `before` or `after` registration, or its fused surface (`mesh`).
pub fn model(j: usize, which: &str) -> String {
    format!("world/models/{j}/{which}")
}

/// A time series of object `j`: `gain`, `coverage` or `times/<step>`.
pub fn plot(series: &str, j: usize) -> String {
    format!("plots/{series}/{j}")
}
