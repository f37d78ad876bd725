//! Phase 1 of the pipeline (paper section III, lines 2–6 of Figure 2): the mid-range cloud
//! P becomes object clusters P_j^0, the occupancy grid M and its reduced map M̄.
//!
//! - [`SegmentationParams`]: voxel filter, outlier removal, table plane and clustering
//!   parameters (the scene file's `[segmentation]` section);
//! - [`OrientedBox`]: a crop region or a known obstacle to leave out of the clusters;
//! - [`obstacle_sliver`]: a cluster that is only a known obstacle's face, moved by pose error;
//! - [`segment_objects`]: cloud → [`ObjectSegmentation`] (clusters with centroid and box);
//! - [`merge_stacked_parts`]: the parts of one object the sweep saw apart, one cluster again;
//! - [`merge_bridged_parts`]: the parts only the thin parts the outlier filter removed join
//!   (a rim, a leg, a tail), one cluster again;
//! - [`merge_fragments`]: the pieces of a small object, each too small alone, one cluster;
//! - [`build_map`]: cloud with origins → [`PhaseOneMap`] (grid, scan counters, reduced map);
//! - [`phase_one`]: both, with a [`PhaseOneConfig`] → [`PhaseOne`].

mod fragments;
mod obstacle_sliver;
mod oriented_box;
mod perception_error;
mod segment_and_map;
mod segmentation;
mod segmentation_params;
mod stacked_parts;
mod table_filter;
mod thin_parts;
mod workcell_alignment;

pub use fragments::merge_fragments;
pub use obstacle_sliver::{ObstacleSliver, obstacle_sliver};
pub use oriented_box::OrientedBox;
pub use perception_error::PerceptionError;
pub use segment_and_map::{PhaseOne, PhaseOneConfig, PhaseOneMap, build_map, phase_one};
pub use segmentation::{ObjectSegmentation, SegmentationCounts, segment_objects};
pub use segmentation_params::SegmentationParams;
pub use stacked_parts::merge_stacked_parts;
pub use table_filter::TableFilter;
pub use thin_parts::merge_bridged_parts;
pub use workcell_alignment::{WorkcellAlignment, align_to_workcell};
