//! [`ExploreObserver`]: how the pipeline tells a front end what it is doing.

use crate::nbv::StopReason;

/// Something the pipeline did, in the order it happened.
#[derive(Debug, Clone, PartialEq)]
pub enum ExploreEvent {
    /// The laser sweep is starting (`waypoints` joint waypoints).
    SweepStarted {
        /// Waypoints of the sweep.
        waypoints: usize,
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
    /// The exploration of object `object` (0-based) starts.
    ObjectStarted {
        /// Object index.
        object: usize,
    },
    /// Algorithm 2 produced `candidates` candidate viewpoints.
    Candidates {
        /// Object index.
        object: usize,
        /// Candidates in the sorted list.
        candidates: usize,
    },
    /// A viewpoint could not be reached (planning or execution failed).
    ViewFailed {
        /// Object index.
        object: usize,
        /// Why.
        reason: String,
    },
    /// A short-range view was taken.
    ViewTaken {
        /// Object index.
        object: usize,
        /// Views of this object so far.
        views: usize,
        /// Its gain, by the stop rule's measure.
        gain: f64,
    },
    /// The exploration of an object ended.
    ObjectDone {
        /// Object index.
        object: usize,
        /// Why, if the stop rule decided; `None` when the view cap was reached.
        reason: Option<StopReason>,
    },
    /// The views of an object were registered.
    Registered {
        /// Object index.
        object: usize,
    },
}

/// Receives [`ExploreEvent`]s.
pub trait ExploreObserver {
    /// Called for each event.
    fn event(&mut self, event: &ExploreEvent);
}

/// An observer that ignores everything.
#[derive(Debug, Clone, Copy, Default)]
pub struct NoObserver;

impl ExploreObserver for NoObserver {
    fn event(&mut self, _event: &ExploreEvent) {}
}
