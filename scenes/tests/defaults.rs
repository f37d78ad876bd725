//! Every default is written once, in nbv-core's parameter types: a scene that leaves a
//! key out gets core's value, for both `[nbv]` presets.

mod common;

use nbv_core::nbv::{NbvParams, NbvPreset, StopRule, VisitedViews};
use nbv_core::perception::SegmentationParams;
use nbv_core::pipeline::{ExploreMode, ObjectRegion};
use nbv_core::planning::PlannerConfig;
use nbv_core::registration::RegistrationParams;
use nbv_scenes::schema::{Nbv, Planner, Registration, Segmentation};

#[test]
fn the_nbv_presets_are_cores() {
    assert_eq!(Nbv::default().params(), NbvParams::default());
    assert_eq!(Nbv::default().stop_rule(), StopRule::default());
    for preset in [NbvPreset::Twin, NbvPreset::Paper] {
        let scene = Nbv::preset(preset);
        assert_eq!(scene.params(), preset.params(), "{preset:?}");
        assert_eq!(scene.stop_rule(), preset.stop_rule(), "{preset:?}");
        assert_eq!(
            scene.max_views_per_object as usize,
            preset.max_views_per_object()
        );
        assert_eq!(scene.visited_min_distance, VisitedViews::default().distance);
    }
    // The degrees a scene shows are whole where core's are.
    let paper = Nbv::preset(NbvPreset::Paper);
    assert_eq!(
        (paper.dtheta_deg, paper.dphi_deg, paper.theta_max_deg),
        (15.0, 30.0, 75.0)
    );
}

#[test]
fn planner_defaults_are_cores() {
    let core = PlannerConfig::default();
    let scene = Planner::default();
    assert_eq!(scene.max_iterations as usize, core.max_iterations);
    assert_eq!(scene.step_rad, core.step);
    assert_eq!(scene.shortcut_iterations as usize, core.shortcut_iterations);
    // paper-env1 writes its [planner] out: the same values.
    let env1 = common::builtin_with_fixture("paper-env1").unwrap();
    assert_eq!(env1.planner, scene);
}

#[test]
fn registration_and_segmentation_defaults_are_cores() {
    let core = RegistrationParams::default();
    let scene = Registration::default();
    assert_eq!(scene.d_max, core.max_correspondence_distance);
    assert_eq!(scene.max_iterations as usize, core.max_iterations);
    assert_eq!(scene.tolerance, core.tolerance);
    assert_eq!(
        Segmentation::default().params(9),
        SegmentationParams {
            seed: 9,
            ..SegmentationParams::default()
        }
    );
}

#[test]
fn a_scenes_explore_config_takes_cores_defaults() {
    let scene = common::builtin_with_fixture("paper-env1").unwrap();
    let config = scene.explore_config(ExploreMode::Hybrid).unwrap();
    let visited = VisitedViews::default();
    assert_eq!(config.visited, (visited.distance, visited.angle));
    assert_eq!(config.object_margin, ObjectRegion::MARGIN);
    assert_eq!(config.nbv, NbvParams::default());
    let r = &config.registration;
    let core = RegistrationParams::default();
    assert_eq!(
        (r.max_correspondence_distance, r.max_iterations, r.tolerance),
        (
            core.max_correspondence_distance,
            core.max_iterations,
            core.tolerance
        )
    );
}
