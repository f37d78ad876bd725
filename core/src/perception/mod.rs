//! Phase 1 of the pipeline (paper section III, lines 2–6 of Figure 2): the mid-range cloud
//! P becomes object clusters P_j^0, the occupancy grid M and its reduced map M̄.
//!
//! - [`SegmentationParams`]: voxel filter, outlier removal, table plane and clustering
//!   parameters (the scene file's `[segmentation]` section);
//! - [`OrientedBox`]: a crop region or a known obstacle to leave out of the clusters;
//! - [`segment_objects`]: cloud → [`ObjectSegmentation`] (clusters with centroid and box);
//! - [`build_map`]: cloud with origins → [`PhaseOneMap`] (grid, scan counters, reduced map);
//! - [`phase_one`]: both, with a [`PhaseOneConfig`] → [`PhaseOne`].

mod oriented_box;
mod perception_error;
mod phase_one;
mod segmentation;
mod segmentation_params;
mod workcell_alignment;

pub use oriented_box::OrientedBox;
pub use perception_error::PerceptionError;
pub use phase_one::{PhaseOne, PhaseOneConfig, PhaseOneMap, build_map, phase_one};
pub use segmentation::{ObjectSegmentation, SegmentationCounts, segment_objects};
pub use segmentation_params::SegmentationParams;
pub use workcell_alignment::{WorkcellAlignment, align_to_workcell};
