//! The paper's Table II case: global registration of 5 views with 15K points in all
//! (3000 per view: a top, mid-range-like view and 4 views 36° apart around the object,
//! 0.3 mm range noise, every view but the reference off by 1° and 5 mm), by p-ICP-GPA and
//! by sequential ICP (point-to-point and point-to-plane), each on custom rayon pools of 1,
//! 2 and all threads. Each run goes to convergence; the iteration count does not depend
//! on the thread count, so the times compare like for like. Accuracy and iteration counts
//! are printed once before timing.

use std::hint::black_box;
use std::time::{Duration, Instant};

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use nbv_core::registration::{Method, MethodReport, RegistrationParams, register};

#[path = "../tests/registration_data/mesh_scans.rs"]
mod mesh_scans;
#[path = "../tests/registration_data/mod.rs"]
mod registration_data;

use registration_data::{Spec, generate, worst_error, worst_point_error};

/// The paper's Table II case (see the file's doc).
fn table_ii_spec() -> Spec {
    Spec {
        views: 5,
        top_view: true,
        points_per_view: 3000,
        noise: 0.0003,
        rotation_error_deg: 1.0,
        translation_error: 0.005,
        ..Spec::default()
    }
}

fn table_ii(c: &mut Criterion) {
    let s = generate(&table_ii_spec());
    let methods = [
        ("map", Method::Map),
        ("gpa", Method::Gpa),
        (
            "sequential_icp_point",
            Method::SequentialIcp {
                point_to_plane: false,
            },
        ),
        (
            "sequential_icp_plane",
            Method::SequentialIcp {
                point_to_plane: true,
            },
        ),
    ];
    let all = std::thread::available_parallelism().map_or(1, |n| n.get());
    let mut threads = vec![1, 2, all];
    threads.dedup();
    let pools: Vec<(usize, rayon::ThreadPool)> = threads
        .iter()
        .map(|&n| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(n)
                .build()
                .expect("thread pool");
            (n, pool)
        })
        .collect();
    for (name, method) in methods {
        let params = RegistrationParams {
            method,
            max_correspondence_distance: 0.01,
            max_iterations: 300,
            ..RegistrationParams::default()
        };
        let reg = register(&s.views, &s.initial, &params).expect("registration");
        let (r, t) = worst_error(&reg.poses, &s.truth);
        let p = worst_point_error(&s.views, &reg.poses, &s.truth);
        let iterations = match &reg.report {
            MethodReport::Map(m) => format!(
                "{} steps, {} evaluations, {} correspondences",
                m.iterations, m.evaluations, m.inliers
            ),
            MethodReport::Gpa(g) => format!(
                "{} iterations, {} fits, {} sets",
                g.iterations, g.inner_iterations, g.independent_sets
            ),
            MethodReport::SequentialIcp(q) => format!(
                "iterations per pair {:?}",
                q.pairs.iter().map(|p| p.icp.iterations).collect::<Vec<_>>()
            ),
        };
        eprintln!(
            "{name}: converged {}, worst error {r:.3}° {:.2} mm, object points {:.2} mm, \
             rms {:.3} mm, {iterations}",
            reg.converged,
            t * 1e3,
            p * 1e3,
            reg.rms.unwrap_or(f64::NAN) * 1e3
        );
        let mut group = c.benchmark_group(format!("table_ii_5_views_15k/{name}"));
        group.sample_size(10);
        // Enough time for 10 runs to convergence (GPA takes seconds on one thread).
        let one_run = Instant::now();
        let _ = black_box(register(&s.views, &s.initial, &params));
        group.measurement_time((one_run.elapsed() * 12).max(Duration::from_secs(5)));
        for (n, pool) in &pools {
            group.bench_with_input(BenchmarkId::new("threads", n), n, |b, _| {
                b.iter(|| pool.install(|| register(black_box(&s.views), &s.initial, &params)))
            });
        }
        group.finish();
    }
}

/// A paper object's registration at the pipeline's size: an anchor view and 16 views with
/// 6 mm noise (the Dinast's averaged noise at 0.45 m), off by 0.5° and 5 mm, 2,000 points
/// each, each with the pose prior; the MAP registration into the anchor (no view-to-view
/// terms, as the pipeline runs it), at 1 and 2 threads.
fn paper_object(c: &mut Criterion) {
    use nbv_core::registration::{PosePrior, RangeNoise, ViewModel, register_with_models};
    let s = generate(&Spec {
        views: 17,
        top_view: true,
        points_per_view: 2000,
        noise: 0.006,
        rotation_error_deg: 0.5,
        translation_error: 0.005,
        ..Spec::default()
    });
    let views = &s.views;
    let models: Vec<ViewModel> = (0..views.len())
        .map(|k| ViewModel {
            noise: RangeNoise::constant(if k == 0 { 0.0005 } else { 0.006 }),
            prior: (k > 0).then_some(PosePrior {
                rotation_sigma: 0.5f64.to_radians(),
                translation_sigma: 0.004,
            }),
        })
        .collect();
    let mut params = RegistrationParams {
        method: Method::Map,
        max_correspondence_distance: 0.03,
        ..RegistrationParams::default()
    };
    params.map.view_to_view = false;
    let mut group = c.benchmark_group("paper_object_17_views_map");
    group.sample_size(10);
    for n in [1usize, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .expect("thread pool");
        group.bench_with_input(BenchmarkId::new("threads", n), &n, |b, _| {
            b.iter(|| {
                pool.install(|| {
                    register_with_models(black_box(views), &s.initial, &models, &params)
                })
            })
        });
    }
    group.finish();
}

/// The 16 nearest points of every point of one Table II view (3000 points), as the MAP's
/// surfels take them: `KNearest`'s cell grid against one kiddo k-d tree query per point
/// (the previous way), on one thread.
fn neighbourhoods(c: &mut Criterion) {
    use kiddo::{ImmutableKdTree, SquaredEuclidean};
    use nbv_core::cloud::KNearest;
    use std::num::NonZeroUsize;
    // The pose errors move whole views, not the neighbourhoods within one.
    let s = generate(&table_ii_spec());
    let points = &s.views[1].points;
    let k = NonZeroUsize::new(16).expect("k > 0");
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("thread pool");
    let mut group = c.benchmark_group("neighbourhoods_16_of_3000");
    group.bench_function("k_nearest_cell_grid", |b| {
        b.iter(|| pool.install(|| KNearest::of_each(black_box(points), k)))
    });
    group.bench_function("kiddo_query_per_point", |b| {
        b.iter(|| {
            let coords: Vec<[f64; 3]> = points.iter().map(|p| [p.x, p.y, p.z]).collect();
            let tree = ImmutableKdTree::<f64, 3>::new_from_slice(&coords).expect("tree");
            coords
                .iter()
                .map(|q| {
                    tree.query(q)
                        .nearest_n::<SquaredEuclidean<f64>>(k)
                        .execute()
                        .len()
                })
                .sum::<usize>()
        })
    });
    group.finish();
}

/// `nbv register`'s default on a user's scans (`user_scans`' sets of docs/peers.md): 12
/// views of 4000 points of a library mesh, 0.3 mm of noise along the rays, every view but
/// the reference 2° and 5 mm off, no sensor origins and no pose prior — the sensors placed
/// (`assign_sensor_origins`), the noise estimated from the views, then the MAP from coarse
/// to fine, at 2 threads. The figurine's ring is a typical set; the box's hand-held path
/// the slowest (its fine stage creeps along the slides its faces leave loose).
fn users_scans(c: &mut Criterion) {
    use mesh_scans::{MeshScanSpec, ScanPath, scan_mesh};
    use nbv_core::evaluation::alignment_error;
    use nbv_core::mesh::io::read_mesh;
    use nbv_core::registration::{
        RangeNoise, SensorOrigin, ViewModel, assign_sensor_origins, estimate_range_sigma,
        register_coarse_to_fine,
    };
    let meshes = concat!(env!("CARGO_MANIFEST_DIR"), "/../assets/meshes/");
    let sets = [
        ("figurine_ring", "figurine.stl", ScanPath::Ring, 7),
        ("box_handheld", "box.stl", ScanPath::Handheld, 11),
    ];
    let params = RegistrationParams {
        method: Method::Map,
        ..RegistrationParams::default()
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .expect("thread pool");
    let mut group = c.benchmark_group("users_scans_12_views");
    group.sample_size(10);
    for (name, mesh, path, seed) in sets {
        let object = read_mesh(std::path::Path::new(&format!("{meshes}{mesh}"))).expect("mesh");
        let spec = MeshScanSpec {
            path,
            seed,
            ..MeshScanSpec::default()
        };
        let (s, _) = scan_mesh(&object, &spec).expect("scans");
        let run = || {
            pool.install(|| {
                let mut views = s.views.clone();
                assign_sensor_origins(&mut views, SensorOrigin::Auto);
                let sigma = estimate_range_sigma(&views).expect("noise");
                let model = ViewModel {
                    noise: RangeNoise::constant(sigma),
                    prior: None,
                };
                let models = vec![model; views.len()];
                register_coarse_to_fine(&views, &s.initial, &models, &params).expect("registered")
            })
        };
        let r = run();
        // The registered poses against the truth, in the reference's frame.
        let to_truth = s.truth[0] * r.poses[0].inverse();
        let registered: Vec<_> = r.poses.iter().map(|p| to_truth * p).collect();
        let mut truthful = s.views.clone();
        for (v, t) in truthful.iter_mut().zip(&s.truth) {
            v.truth = Some(v.points.iter().map(|p| t * p).collect());
        }
        println!(
            "users_scans_12_views/{name}: mean alignment error {:.3} mm (initial {:.3} mm)",
            alignment_error(&truthful[1..], &registered[1..]).mean * 1e3,
            alignment_error(&truthful[1..], &s.initial[1..]).mean * 1e3,
        );
        group.bench_function(name, |b| b.iter(|| black_box(run())));
    }
    group.finish();
}

criterion_group!(benches, table_ii, paper_object, neighbourhoods, users_scans);
criterion_main!(benches);
