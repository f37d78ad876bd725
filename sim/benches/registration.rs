//! The MAP registration of each paper-env1 object on the views the twin takes of it — the
//! pipeline's registration step as an episode runs it (the phase-1 cluster as the anchor,
//! the camera views with their sensor origins, the rig's noise and priors), first pass and
//! calibrated pass. The episode that makes the views runs once, before the measurements.
//!
//! `cargo bench -p nbv-sim --bench registration`

use criterion::{Criterion, criterion_group, criterion_main};
use nbv_core::math::Pose;
use nbv_core::pipeline::{ExploreMode, NoObserver};
use nbv_core::registration::{Method, RegistrationParams, register_with_models};
use nbv_sim::rig::SimRig;
use std::hint::black_box;

fn registration(c: &mut Criterion) {
    let scene = nbv_scenes::builtin::load("paper-env1").expect("built-in scene");
    let config = scene.explore_config(ExploreMode::Hybrid).expect("config");
    let mut rig = SimRig::from_scene(&scene).expect("twin");
    let exploration = rig.explore(&config, &mut NoObserver).expect("episode");
    let params = RegistrationParams {
        method: Method::Map,
        reference: 0,
        ..config.registration.clone()
    };
    let mut group = c.benchmark_group("registration");
    group.sample_size(10);
    for object in &exploration.objects {
        let Some(r) = &object.registration else {
            continue;
        };
        let first = vec![Pose::identity(); r.views.len()];
        let name = format!("object{}_{}views", object.index, r.views.len());
        // The first pass: priors from the scene's [errors], centred on the reported poses.
        let models = config
            .uncertainty
            .view_models(&r.views, config.frames_per_view);
        group.bench_function(format!("map_first_pass/{name}"), |b| {
            b.iter(|| black_box(register_with_models(&r.views, &first, &models, &params)))
        });
        // The calibrated pass, as the episode ran it last.
        if r.calibrated {
            group.bench_function(format!("map_calibrated/{name}"), |b| {
                b.iter(|| {
                    black_box(register_with_models(
                        &r.views,
                        &r.map_initial,
                        &r.models,
                        &params,
                    ))
                })
            });
        }
    }
    group.finish();
}

criterion_group!(benches, registration);
criterion_main!(benches);
