//! The viewer's layout of an episode recording (a Rerun blueprint stored in the file):
//! the 3D world large, beside it the gain, the coverage, the step times and the decisions.

use super::entity;
use rerun::blueprint::{
    Blueprint, BlueprintActivation, Horizontal, Spatial3DView, TextLogView, TimePanel,
    TimeSeriesView, Vertical,
};

/// Sends the layout into the recording, as its default and active blueprint.
pub fn send(rec: &rerun::RecordingStream) -> rerun::RecordingStreamResult<()> {
    let plots = Vertical::new([
        TimeSeriesView::new("gain (eq. 5)")
            .with_origin("/plots/gain")
            .into(),
        TimeSeriesView::new("coverage of the true surface")
            .with_origin("/plots/coverage")
            .into(),
        TimeSeriesView::new("step times (s)")
            .with_origin("/plots/times")
            .into(),
        TextLogView::new("decisions")
            .with_origin(format!("/{}", entity::LOG))
            .into(),
    ]);
    let root = Horizontal::new([
        Spatial3DView::new("world")
            .with_origin(format!("/{}", entity::WORLD))
            .into(),
        plots.into(),
    ])
    .with_column_shares([2.0, 1.0]);
    Blueprint::new(root)
        .with_time_panel(TimePanel::new().with_timeline(entity::STEP))
        .send(
            rec,
            BlueprintActivation {
                make_active: true,
                make_default: true,
            },
        )
}
