//! [`Episode`]: what every stage of one run of the method shares — the rig, the
//! configuration, the observer, the collisions counted, the paths executed since phase 1
//! and the objects' regions.

use super::{ExploreConfig, ExploreObserver, ObjectRegion};
use crate::rig::{JointPath, Rig};

/// One run of the method in progress.
pub(super) struct Episode<'e, 'r> {
    /// The rig.
    pub rig: &'e mut Rig<'r>,
    /// The configuration.
    pub config: &'e ExploreConfig,
    /// Where progress goes.
    pub observer: &'e mut dyn ExploreObserver,
    /// Collisions the rig reported so far.
    pub collisions: usize,
    /// The paths executed since phase 1, to go back along when the arm is boxed in.
    pub trail: Vec<JointPath>,
    /// Every object's region after phase 1: where the table is not the table's alone.
    pub footprints: Vec<ObjectRegion>,
}

impl<'e, 'r> Episode<'e, 'r> {
    /// A run starting on `rig`.
    pub fn new(
        rig: &'e mut Rig<'r>,
        config: &'e ExploreConfig,
        observer: &'e mut dyn ExploreObserver,
    ) -> Self {
        Self {
            rig,
            config,
            observer,
            collisions: 0,
            trail: Vec::new(),
            footprints: Vec::new(),
        }
    }
}
