//! Next best view for the short-range sensor (the paper's section III-A, Algorithm 2 in
//! Figure 3, eq. (3)–(5)).
//!
//! For one object:
//! 1. [`ViewSphere`]: samples (θ, φ) on a sphere of radius r around the object's current
//!    centroid (duplicates at φ = π and at the poles removed);
//! 2. [`view_pose`]: the sensor pose of eq. (3) — checked to be a proper rotation whose z
//!    axis points from the viewpoint to the centroid, used as the pose of the camera's
//!    optical frame (`dinast`: z forward), see [`view_pose`]'s module notes;
//! 3. [`NextBestView::viewpoints`]: drop samples close to a [`VisitedViews`] pose and those
//!    without an IK solution for the sensor frame (optionally trying other rolls about the
//!    optical axis);
//! 4. [`visible_voxels`]: the predicted visible set O_v — the closest reduced-map voxel of
//!    each ray of [`SensorRays`] (a subsampled Dinast pinhole ray set) within
//!    [r_min, r_max] — by DDA; [`visible_voxels_literal`] is the paper's literal
//!    every-ray-against-every-voxel loop and gives the same sets;
//! 5. [`ScoreWeights`]: eq. (4), candidates sorted best first ([`NextBestView::candidates`]);
//!    or, by [`NbvParams::objective`], one of the seven information gains of the
//!    literature over the full grid ([`Objective`], [`view_gain`]; `objectives/`), with an
//!    optional movement cost ([`apply_movement_cost`]);
//! 6. after the view was acquired and the grid updated: [`InformationGain`] (eq. (5) as
//!    printed; its sign is discussed there — it is negative for views that hit surface)
//!    and the [`StopRule`] (on eq. (5) by default, or on the Bernoulli KL divergence).
//!
//! # Deviations and choices
//!
//! - Eq. (3) is used as printed: it is a proper rotation (det = +1), no sign fix needed.
//! - The paper's loop `i_φ = 0..=⌊2π/Δφ⌋` repeats φ = −π at φ = π when 2π/Δφ is whole;
//!   the repeat is dropped, and at θ = 0 only one φ is kept (all φ give the same position
//!   and axis). See [`ViewSphere`].
//! - Defaults the paper does not give: Δθ = 15°, θ_max = 75°, Δφ = 30°, every 8th pixel,
//!   gain_thr = 5 nats of Bernoulli KL divergence ([`NbvPreset::Paper`]); the project's
//!   default is [`NbvPreset::Twin`].

mod hull_score;
mod hull_surface;
mod information_gain;
mod missed_voxels;
mod nbv_error;
mod new_surface;
mod objectives;
mod preset;
mod sensor_rays;
mod stop_rule;
mod surface_sides;
mod view_pose;
mod view_score;
mod view_sphere;
mod viewpoint_list;
mod visibility;
mod visited_views;

pub use hull_score::HullScore;
pub use hull_surface::HullSurface;
pub use information_gain::InformationGain;
pub use missed_voxels::MissedVoxels;
pub use nbv_error::NbvError;
pub use new_surface::{
    NEW_SURFACE_CELL, NEW_SURFACE_DISTANCE, TABLE_MARGIN, new_surface_share, settle_shift,
};
pub use objectives::{
    AreaRay, GainMap, Objective, RayVoxel, Visibility, VoxelClass, apply_movement_cost,
    area_factor_ray, area_factor_view, average_entropy_ray, average_entropy_view, cast_ray,
    entropy, joint_distance, lazy_best, movement_cost_total, occlusion_aware_ray,
    proximity_count_ray, rear_side_entropy_ray, rear_side_voxel_ray, unobserved_voxel_ray,
    view_gain,
};
pub use preset::NbvPreset;
pub use sensor_rays::SensorRays;
pub use stop_rule::{GainMeasure, StopReason, StopRule};
pub use surface_sides::{NewlySeen, SurfaceSides};
pub use view_pose::{view_pose, view_pose_rolled, view_position, view_rotation};
pub use view_score::ScoreWeights;
pub use view_sphere::{SphereSample, ViewSphere};
pub use viewpoint_list::{
    Candidate, GoalFilter, NbvParams, NextBestView, Viewpoint, ViewpointList, ViewpointSet,
    VisibilityForm, compare_best_first, sort_best_first,
};
pub use visibility::{
    RayHit, VisibleVoxels, first_hit, first_hit_literal, visible_voxels, visible_voxels_literal,
};
pub use visited_views::VisitedViews;
