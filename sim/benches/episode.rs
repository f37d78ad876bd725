//! One whole episode of the method on paper-env1 in the twin, headless: the phase-1 sweep,
//! segmentation and grid, the next-best-view exploration of the three objects (planning,
//! execution with truth checks, Dinast frames, grid updates) and the registration of each
//! object (the model's MAP with the rig's self-calibration, and beside it the paper's
//! p-ICP-GPA and sequential ICP, as the scene's `[registration] baselines` asks) — `nbv
//! explore` without the evaluation and the files. Also the mid-only baseline. Episodes
//! per hour follow from the time.

use criterion::{Criterion, criterion_group, criterion_main};
use nbv_core::pipeline::{ExploreMode, NoObserver};
use nbv_sim::rig::SimRig;
use std::hint::black_box;

fn episode(c: &mut Criterion) {
    let scene = nbv_scenes::builtin::load("paper-env1").expect("built-in scene");
    let mut group = c.benchmark_group("episode");
    group.sample_size(10);
    for mode in [ExploreMode::Hybrid, ExploreMode::MidOnly] {
        let config = scene.explore_config(mode).expect("config");
        group.bench_function(format!("paper-env1_{}", mode.name()), |b| {
            b.iter(|| {
                let mut rig = SimRig::from_scene(&scene).expect("twin");
                let e = rig.explore(&config, &mut NoObserver).expect("episode");
                black_box(e.objects.len())
            })
        });
    }
    group.finish();
}

criterion_group!(benches, episode);
criterion_main!(benches);
