//! [`ProgressObserver`]: the pipeline's events as indicatif progress lines on stderr.

use indicatif::{ProgressBar, ProgressStyle};
use nbv_core::pipeline::{ExploreEvent, ExploreObserver};
use std::time::Duration;

/// A spinner whose message follows the exploration; silent when `quiet`.
pub struct ProgressObserver {
    bar: ProgressBar,
}

impl ProgressObserver {
    /// A spinner on stderr (hidden when `quiet` or when stderr is not a terminal).
    pub fn new(quiet: bool) -> Self {
        let bar = if quiet {
            ProgressBar::hidden()
        } else {
            ProgressBar::new_spinner()
        };
        bar.set_style(
            ProgressStyle::with_template("{spinner} [{elapsed_precise}] {msg}")
                .unwrap_or_else(|_| ProgressStyle::default_spinner()),
        );
        bar.enable_steady_tick(Duration::from_millis(200));
        Self { bar }
    }

    /// Clears the spinner.
    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}

impl ExploreObserver for ProgressObserver {
    fn event(&mut self, event: &ExploreEvent<'_>) {
        let msg = match event {
            ExploreEvent::SweepStarted { waypoints } => {
                format!("phase 1: laser sweep through {waypoints} waypoints")
            }
            ExploreEvent::SweepDone { lines, points } => {
                format!("phase 1: {lines} scan lines, {points} points; segmenting")
            }
            ExploreEvent::Segmented { objects } => format!("phase 1: {objects} object(s)"),
            ExploreEvent::ObjectStarted { object, .. } => format!("object {object}: exploring"),
            ExploreEvent::Candidates {
                object, candidates, ..
            } => {
                format!("object {object}: {candidates} candidate viewpoints")
            }
            ExploreEvent::ViewFailed { object, reason, .. } => {
                tracing::info!(object, reason, "viewpoint failed");
                format!("object {object}: viewpoint failed, trying the next")
            }
            ExploreEvent::ViewTaken {
                object,
                views,
                gain,
                ..
            } => {
                format!("object {object}: view {views} taken, gain {gain:.2}")
            }
            ExploreEvent::ObjectDone { object, stop } => {
                format!("object {object}: done ({stop})")
            }
            ExploreEvent::Registered { object, .. } => format!("object {object}: registered"),
            ExploreEvent::Retreated { object } => {
                format!("object {object}: no viewpoint reachable, retreating")
            }
            // The data events carry nothing a progress line shows.
            ExploreEvent::Moved { .. }
            | ExploreEvent::SweepCloud { .. }
            | ExploreEvent::GridUpdated { .. } => return,
        };
        self.bar.set_message(msg);
    }
}
