//! `nbv tune`'s proposals: the time egobox takes to propose a batch of two trials after 20
//! finished ones, in three parameters, for one objective (expected improvement) and two
//! (expected hypervolume improvement, its batch form) — the optimiser's share of a trial,
//! beside the episodes' seconds.
//!
//! Run with `cargo bench -p nbv-sweep --bench tune`.

use criterion::{Criterion, criterion_group, criterion_main};
use nbv_sweep::tune::proposer::{Observation, Proposer};
use nbv_sweep::tune::space::Space;
use nbv_sweep::tune::spec::{Method, Parameter, Range};
use std::hint::black_box;

fn proposer(objectives: usize) -> Proposer {
    let float = |key: &str, min: f64, max: f64| Parameter {
        key: key.into(),
        range: Range::Float {
            min,
            max,
            log: true,
        },
    };
    Proposer {
        space: Space::new(&[
            float("nbv.alpha_o", 0.25, 4.0),
            float("nbv.alpha_u", 0.5, 8.0),
            float("nbv.gain_threshold", 1.0, 40.0),
        ]),
        method: Method::Bayesian,
        seed: 1,
        initial: 7,
        objectives,
    }
}

/// 20 trials of a smooth stand-in for (−F-score, views): F peaks inside the box, views
/// fall with the threshold.
fn observed(p: &Proposer) -> Vec<Observation> {
    let mut out = Vec::new();
    while out.len() < 20 {
        for (x, _) in p.propose(out.len(), 2, &out).expect("proposals") {
            let f = 0.95 - 0.01 * ((x[0] - 0.3).powi(2) + (x[1] - 1.0).powi(2));
            let views = 12.0 - 2.0 * x[2];
            let losses = vec![-f, views][..p.objectives].to_vec();
            out.push(Observation { x, losses });
        }
    }
    out
}

fn tune(c: &mut Criterion) {
    let mut g = c.benchmark_group("tune");
    g.sample_size(10);
    for (name, objectives) in [
        ("propose_batch_2_after_20_one_objective", 1),
        ("propose_batch_2_after_20_two_objectives", 2),
    ] {
        let p = proposer(objectives);
        let seen = observed(&p);
        g.bench_function(name, |b| b.iter(|| p.propose(20, 2, black_box(&seen))));
    }
    g.finish();
}

criterion_group!(benches, tune);
criterion_main!(benches);
