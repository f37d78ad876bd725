//! View objectives beside the paper's eq. (4): the seven volumetric information gains of
//! Isler et al. (ICRA 2016) and Delmerico et al. (Auton. Robots 2018), as
//! the authors' `rpg_ig_active_reconstruction` library defines them, and Isler's
//! movement-cost utility.
//!
//! - [`Objective`]: the choice (`[nbv] objective`);
//! - [`cast_ray`], [`RayVoxel`], [`VoxelClass`], [`entropy`]: a camera ray through the full
//!   log-odds grid, on the grid's DDA;
//! - [`Visibility`]: `P_v = Π (1 − p)`, the papers' (the reference code's differs);
//! - one file per formula: [`occlusion_aware_ray`], [`unobserved_voxel_ray`],
//!   [`rear_side_voxel_ray`], [`rear_side_entropy_ray`], [`proximity_count_ray`],
//!   [`area_factor_ray`]/[`area_factor_view`], [`average_entropy_ray`]/[`average_entropy_view`];
//! - [`view_gain`]: G(v) over the sensor's subsampled rays (those of eq. (4)'s O_v);
//! - [`apply_movement_cost`]: `U = G/ΣG − λ·c/Σc`.

mod area_factor;
mod average_entropy;
mod movement_cost;
mod objective;
mod occlusion_aware;
mod proximity_count;
mod ray_voxels;
mod rear_side_entropy;
mod rear_side_voxel;
#[cfg(test)]
mod test_rays;
mod unobserved_voxel;
mod view_gain;
mod visibility_probability;

pub use area_factor::{AreaRay, area_factor_ray, area_factor_view};
pub use average_entropy::{average_entropy_ray, average_entropy_view};
pub use movement_cost::{apply_movement_cost, joint_distance, lazy_best, movement_cost_total};
pub use objective::Objective;
pub use occlusion_aware::occlusion_aware_ray;
pub use proximity_count::proximity_count_ray;
pub use ray_voxels::{RayVoxel, VoxelClass, cast_ray, entropy};
pub use rear_side_entropy::rear_side_entropy_ray;
pub use rear_side_voxel::rear_side_voxel_ray;
pub use unobserved_voxel::unobserved_voxel_ray;
pub use view_gain::{GainMap, view_gain};
pub use visibility_probability::Visibility;
