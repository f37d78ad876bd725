//! [`ExploreObserver`]: how the pipeline tells a front end what it is doing — progress
//! counts for the progress bars, and the data behind each step, borrowed, for a recorder.
//!
//! Every payload is a borrow of what the pipeline holds anyway, so an observer that
//! ignores the data costs nothing beyond the call.

use super::{AcquiredView, ObjectExploration, ObjectStop, StepTimes};
use crate::cloud::PointCloud;
use crate::math::Pose;
use crate::nbv::ViewpointList;
use crate::occupancy::OccupancyGrid;
use crate::rig::{JointPath, Motion, ScanLine};

/// Something the pipeline did, in the order it happened.
#[derive(Debug, Clone)]
pub enum ExploreEvent<'a> {
    /// The laser sweep is starting (`waypoints` joint waypoints).
    SweepStarted {
        /// Waypoints of the sweep.
        waypoints: usize,
    },
    /// The arm executed a motion (the sweep, a survey pose, a path to a viewpoint, the
    /// retreat), as the controller reported it.
    Moved {
        /// The reported joint samples, with rig times.
        motion: &'a Motion,
    },
    /// The sweep's scan lines turned into the phase-1 cloud (world frame, after the
    /// workcell alignment): the cloud holds each line's valid returns in line order.
    SweepCloud {
        /// The scan lines, in time order.
        lines: &'a [ScanLine],
        /// The mid-range cloud.
        cloud: &'a PointCloud,
    },
    /// The sweep finished.
    SweepDone {
        /// Scan lines streamed.
        lines: usize,
        /// Points in the mid-range cloud.
        points: usize,
    },
    /// Phase 1 found `objects` object clusters.
    Segmented {
        /// Number of clusters.
        objects: usize,
    },
    /// The occupancy grid was updated: by phase 1, then after every short-range view.
    GridUpdated {
        /// The grid after the update.
        grid: &'a OccupancyGrid,
    },
    /// The exploration of object `object` (0-based) starts.
    ObjectStarted {
        /// Object index.
        object: usize,
        /// Its phase-1 cluster.
        cluster: &'a PointCloud,
    },
    /// Algorithm 2 produced `candidates` candidate viewpoints.
    Candidates {
        /// Object index.
        object: usize,
        /// Candidates in the sorted list.
        candidates: usize,
        /// The list, best first, each with its eq. (4) score.
        list: &'a ViewpointList,
    },
    /// A viewpoint could not be reached (planning or execution failed).
    ViewFailed {
        /// Object index.
        object: usize,
        /// Why.
        reason: String,
        /// The sensor pose that was tried.
        viewpoint: &'a Pose,
    },
    /// A short-range view was taken.
    ViewTaken {
        /// Object index.
        object: usize,
        /// Views of this object so far.
        views: usize,
        /// Its gain, by the stop rule's measure.
        gain: f64,
        /// The view as recorded in the exploration.
        view: &'a AcquiredView,
        /// The path executed to reach it.
        path: &'a JointPath,
        /// The whole depth frame as a world-frame cloud (the view keeps the object's
        /// points only).
        frame: &'a PointCloud,
        /// The object's step times so far.
        times: &'a StepTimes,
    },
    /// No viewpoint was reachable: the arm goes back along the paths it executed.
    Retreated {
        /// Object index.
        object: usize,
    },
    /// The exploration of an object ended.
    ObjectDone {
        /// Object index.
        object: usize,
        /// Why.
        stop: ObjectStop,
    },
    /// The views of an object were registered.
    Registered {
        /// Object index.
        object: usize,
        /// The object with its views and registrations.
        exploration: &'a ObjectExploration,
    },
}

/// Receives [`ExploreEvent`]s.
pub trait ExploreObserver {
    /// Called for each event.
    fn event(&mut self, event: &ExploreEvent<'_>);
}

/// An observer that ignores everything.
#[derive(Debug, Clone, Copy, Default)]
pub struct NoObserver;

impl ExploreObserver for NoObserver {
    fn event(&mut self, _event: &ExploreEvent<'_>) {}
}
