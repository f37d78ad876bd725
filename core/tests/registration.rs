//! Registration on synthetic views of a known surface (see `registration_data`):
//! p-ICP-GPA and ICP recover known transforms, sequential ICP drifts along a chain of
//! views where GPA does not, bad input gives typed errors, views without overlap give a
//! reported non-convergence, and results are bit-identical at 1 and 2 threads.

mod registration_data;

use nalgebra::{Point3, Vector3};
use nbv_core::cloud::PointCloud;
use nbv_core::math::Pose;
use nbv_core::registration::{
    GpaReport, IcpParams, Method, MethodReport, Registration, RegistrationError,
    RegistrationParams, SetRule, StopReason, align, register,
};
use registration_data::{
    Scenario, Spec, generate, generate_shared, pose_error, worst_error, worst_point_error,
};

fn gpa_report(r: &Registration) -> &GpaReport {
    match &r.report {
        MethodReport::Gpa(g) => g,
        _ => panic!("not a GPA report"),
    }
}

fn params(method: Method, d_max: f64) -> RegistrationParams {
    RegistrationParams {
        method,
        max_correspondence_distance: d_max,
        max_iterations: 300,
        ..RegistrationParams::default()
    }
}

const GPA: Method = Method::Gpa;
const ICP_POINT: Method = Method::SequentialIcp {
    point_to_plane: false,
};
const ICP_PLANE: Method = Method::SequentialIcp {
    point_to_plane: true,
};

/// Worst rotation (°), sensor translation (mm) and object-point RMS (mm) errors.
fn errors(s: &Scenario, poses: &[Pose]) -> (f64, f64, f64) {
    let (r, t) = worst_error(poses, &s.truth);
    (
        r,
        t * 1e3,
        worst_point_error(&s.views, poses, &s.truth) * 1e3,
    )
}

#[test]
fn gpa_recovers_known_transforms() {
    // A top view and 3 views 36° apart around the object, 2500 points each, 0.3 mm range
    // noise, every view but the top (reference) one off by 1° and 5 mm.
    let s = generate(&Spec {
        views: 4,
        top_view: true,
        points_per_view: 2500,
        noise: 0.0003,
        rotation_error_deg: 1.0,
        translation_error: 0.005,
        ..Spec::default()
    });
    let before = errors(&s, &s.initial);
    let reg = register(&s.views, &s.initial, &params(GPA, 0.01)).unwrap();
    let g = gpa_report(&reg);
    let after = errors(&s, &reg.poses);
    println!(
        "GPA: worst error {:.2}° {:.1} mm (points {:.1} mm) -> {:.3}° {:.2} mm (points {:.2} mm); \
         {} iterations ({} fits), rms {:.3} mm, {} sets holding {} of {} linked points",
        before.0,
        before.1,
        before.2,
        after.0,
        after.1,
        after.2,
        g.iterations,
        g.inner_iterations,
        reg.rms.unwrap() * 1e3,
        g.independent_sets,
        g.points_in_sets,
        g.linked_points
    );
    assert!(reg.converged, "{:?}", g.stop);
    assert_eq!(reg.poses[0], s.initial[0]);
    assert!(g.unconnected_views.is_empty());
    assert!(g.correspondences_per_view.iter().all(|&n| n > 100));
    // The floor is set by the sampling (about 2.5 mm between points): point-to-point
    // correspondences between independent samplings are off by a fraction of that. On
    // the object the error falls below a third (measured 6.6 -> 1.5 mm); the sensor pose,
    // 0.4 m away, keeps a rotation the object barely shows (measured 1.0 -> 0.70°, 5.0 ->
    // 4.0 mm), so there it is held to its measured gain with a margin.
    assert!(
        after.2 < 0.3 * before.2 && after.2 < 2.0,
        "{after:?} vs {before:?}"
    );
    assert!(
        after.0 < 0.8 * before.0 && after.1 < 0.9 * before.1,
        "{after:?} vs {before:?}"
    );
    assert!(reg.rms.unwrap() < 0.001);
}

#[test]
fn gpa_is_exact_on_shared_samples() {
    // Views that share their samples exactly: the mutual nearest neighbours become the
    // true correspondences and the transforms are recovered to rounding.
    let s = generate_shared(&Spec {
        points_per_view: 600,
        rotation_error_deg: 0.3,
        translation_error: 0.001,
        ..Spec::default()
    });
    for rule in [SetRule::Cliques, SetRule::Components] {
        // Without the pose-step criterion, which would stop once a step is below
        // 1e-5 rad / 1 µm, short of rounding level.
        let p = RegistrationParams {
            set_rule: rule,
            rotation_tolerance: 0.0,
            translation_tolerance: 0.0,
            ..params(GPA, 0.01)
        };
        let reg = register(&s.views, &s.initial, &p).unwrap();
        let (r, t) = worst_error(&reg.poses, &s.truth);
        println!("shared samples, {rule:?}: {r:.1e}° {t:.1e} m");
        assert!(reg.converged);
        assert!(r < 1e-7 && t < 1e-9, "{rule:?}: {r}° {t} m");
        assert!(reg.rms.unwrap() < 1e-9);
    }
}

#[test]
fn icp_recovers_a_known_transform() {
    // Two views 10° apart (large overlap); the source's reported pose is off by 1°, 5 mm.
    let s = generate(&Spec {
        views: 2,
        points_per_view: 1500,
        noise: 0.0003,
        azimuth_step_deg: 10.0,
        rotation_error_deg: 1.0,
        translation_error: 0.005,
        ..Spec::default()
    });
    let truth = s.truth[0].inverse() * s.truth[1];
    let start = s.initial[0].inverse() * s.initial[1];
    let (r0, t0) = pose_error(&start, &truth);
    for point_to_plane in [false, true] {
        let p = IcpParams {
            max_correspondence_distance: 0.01,
            point_to_plane,
            ..IcpParams::default()
        };
        let (pose, report) = align(&s.views[1], &s.views[0], &start, &p).unwrap();
        let (r, t) = pose_error(&pose, &truth);
        println!(
            "ICP point_to_plane={point_to_plane}: {r0:.2}° {:.1} mm -> {r:.3}° {:.2} mm, \
             {} iterations, fitness {:.3}, rms {:.3} mm",
            t0 * 1e3,
            t * 1e3,
            report.iterations,
            report.fitness,
            report.rms.unwrap() * 1e3
        );
        assert!(report.converged(), "{:?}", report.stop);
        // At most half the starting translation; point-to-plane a fifth of both (measured
        // 0.07°, 0.3 mm); point-to-point's rotation gains less (measured 1.0 -> 0.73°: it
        // slides on this smooth patch), held to that with a margin.
        let (max_r, max_t) = if point_to_plane {
            (0.2 * r0, 0.2 * t0)
        } else {
            (0.85 * r0, 0.5 * t0)
        };
        assert!(r < max_r && t < max_t, "{r}° {t} m from {r0}° {t0} m");
        assert!(report.fitness > 0.8);
    }
}

#[test]
fn sequential_icp_drifts_where_gpa_does_not() {
    // As in the paper: a top (mid-range) view overlapping all others, then a chain of 5
    // views 36° apart; 0.3 mm range noise, every view but the top one off by 1° and 5 mm.
    // Sequential ICP registers view h onto view h−1, so its errors add up along the
    // chain; GPA uses every overlap at once.
    let s = generate(&Spec {
        views: 6,
        top_view: true,
        points_per_view: 2000,
        noise: 0.0003,
        rotation_error_deg: 1.0,
        translation_error: 0.005,
        seed: 11,
        ..Spec::default()
    });
    let mut per_view = Vec::new();
    let mut worst = Vec::new();
    for method in [GPA, ICP_POINT, ICP_PLANE] {
        let reg = register(&s.views, &s.initial, &params(method, 0.01)).unwrap();
        let errs: Vec<f64> = (0..s.views.len())
            .map(|v| {
                let one = |x: &[Pose]| x[v..=v].to_vec();
                worst_point_error(&s.views[v..=v], &one(&reg.poses), &one(&s.truth)) * 1e3
            })
            .collect();
        let e = errors(&s, &reg.poses);
        println!(
            "{method:?}: worst {:.3}° {:.2} mm (points {:.2} mm), point error per view (mm) \
             {errs:.2?}",
            e.0, e.1, e.2
        );
        per_view.push(errs);
        worst.push(e);
    }
    let (gpa, icp_point, icp_plane) = (&per_view[0], &per_view[1], &per_view[2]);
    // Drift: mean error of the two views farthest along the chain over that of the two
    // nearest the reference.
    let drift = |e: &[f64]| (e[4] + e[5]) / (e[1] + e[2]);
    println!(
        "drift ratio: GPA {:.2}, ICP point-to-point {:.2}, ICP point-to-plane {:.2}",
        drift(gpa),
        drift(icp_point),
        drift(icp_plane)
    );
    assert!(drift(icp_plane) > 1.5, "{icp_plane:?}");
    assert!(drift(gpa) < 1.0, "{gpa:?}");
    // GPA beats both ICP variants on its worst view and at the end of the chain.
    let last = s.views.len() - 1;
    assert!(
        worst[0].2 < worst[1].2 && worst[0].2 < worst[2].2,
        "{worst:?}"
    );
    assert!(gpa[last] < icp_point[last] && gpa[last] < icp_plane[last]);
}

#[test]
fn pose_step_criterion_stops_early() {
    // Loose step tolerances (0.05°, 0.1 mm) end the run once the updates are that small:
    // fewer iterations than the residual criterion alone, at some cost in accuracy, since
    // point-to-point steps slide slowly along smooth surfaces.
    let s = generate(&Spec {
        views: 3,
        points_per_view: 800,
        noise: 0.0003,
        rotation_error_deg: 1.0,
        translation_error: 0.005,
        ..Spec::default()
    });
    let off = RegistrationParams {
        rotation_tolerance: 0.0,
        translation_tolerance: 0.0,
        ..params(GPA, 0.01)
    };
    let loose = RegistrationParams {
        rotation_tolerance: 0.05f64.to_radians(),
        translation_tolerance: 1e-4,
        ..off.clone()
    };
    let (a, b) = (
        register(&s.views, &s.initial, &off).unwrap(),
        register(&s.views, &s.initial, &loose).unwrap(),
    );
    let (ga, gb) = (gpa_report(&a), gpa_report(&b));
    println!(
        "criterion off: {} iterations, {:.3} mm; loose: {} iterations, {:.3} mm",
        ga.iterations,
        errors(&s, &a.poses).2,
        gb.iterations,
        errors(&s, &b.poses).2
    );
    assert!(a.converged && b.converged);
    assert!(
        gb.iterations < ga.iterations,
        "{} vs {}",
        gb.iterations,
        ga.iterations
    );
    assert!(errors(&s, &b.poses).2 < 0.5 * errors(&s, &s.initial).2);
    // The report describes the returned poses: one residual per correspondence search.
    assert_eq!(gb.mse_history.len(), gb.iterations + 1);
    assert_eq!(b.rms, gb.mse_history.last().map(|m| m.sqrt()));
    let nan = RegistrationParams {
        rotation_tolerance: f64::NAN,
        ..off
    };
    assert!(matches!(
        register(&s.views, &s.initial, &nan),
        Err(RegistrationError::InvalidParameter {
            name: "rotation_tolerance",
            ..
        })
    ));
}

#[test]
fn results_are_identical_at_one_and_two_threads() {
    let s = generate(&Spec {
        views: 3,
        points_per_view: 600,
        noise: 0.0005,
        ..Spec::default()
    });
    for method in [GPA, ICP_POINT, ICP_PLANE] {
        let p = RegistrationParams {
            max_iterations: 20,
            ..params(method, 0.02)
        };
        let run = |threads: usize| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| register(&s.views, &s.initial, &p).unwrap())
        };
        let (one, two) = (run(1), run(2));
        let bits = |r: &Registration| -> Vec<u64> {
            r.poses
                .iter()
                .flat_map(|p| {
                    p.to_homogeneous()
                        .iter()
                        .map(|v| v.to_bits())
                        .collect::<Vec<_>>()
                })
                .collect()
        };
        assert_eq!(bits(&one), bits(&two), "{method:?}");
        assert_eq!(one, two, "{method:?}");
    }
}

#[test]
fn reference_view_fixes_the_gauge_only() {
    let s = generate(&Spec {
        views: 3,
        points_per_view: 600,
        ..Spec::default()
    });
    let p0 = params(GPA, 0.02);
    let p2 = RegistrationParams {
        reference: 2,
        ..p0.clone()
    };
    let a = register(&s.views, &s.initial, &p0).unwrap();
    let b = register(&s.views, &s.initial, &p2).unwrap();
    assert_eq!(a.poses[0], s.initial[0]);
    assert_eq!(b.poses[2], s.initial[2]);
    // Same relative poses whatever the reference.
    for v in 0..3 {
        let ra = a.poses[2].inverse() * a.poses[v];
        let rb = b.poses[2].inverse() * b.poses[v];
        let (r, t) = pose_error(&ra, &rb);
        assert!(r < 1e-6 && t < 1e-8, "view {v}: {r}° {t} m");
    }
}

fn grid(offset: [f64; 3]) -> PointCloud {
    // A bumpy 20 × 20 patch, 5 mm apart.
    PointCloud::from_points(
        (0..400)
            .map(|i| {
                let (x, y) = ((i % 20) as f64 * 0.005, (i / 20) as f64 * 0.005);
                Point3::new(
                    x + offset[0],
                    y + offset[1],
                    0.01 * (40.0 * x).sin() * (30.0 * y).cos() + offset[2],
                )
            })
            .collect(),
    )
}

#[test]
fn views_without_overlap_report_non_convergence() {
    let views = [grid([0.0; 3]), grid([1.0, 0.0, 0.0])];
    let initial = [Pose::identity(); 2];
    for method in [GPA, ICP_POINT, ICP_PLANE] {
        let reg = register(&views, &initial, &params(method, 0.01)).unwrap();
        assert!(!reg.converged, "{method:?}");
        assert_eq!(reg.rms, None);
        assert_eq!(reg.poses, initial.to_vec());
        match &reg.report {
            MethodReport::Gpa(g) => {
                assert_eq!(g.stop, StopReason::NoCorrespondences);
                assert_eq!((g.iterations, g.independent_sets), (0, 0));
            }
            MethodReport::SequentialIcp(r) => {
                assert_eq!(r.pairs.len(), 1);
                assert_eq!(r.pairs[0].icp.stop, StopReason::NoCorrespondences);
            }
            MethodReport::Map(_) => unreachable!("not run here"),
        }
    }
    // Two overlapping pairs far apart: GPA registers each pair but reports that views
    // 2 and 3 are not tied to the reference view.
    let views = [
        grid([0.0; 3]),
        grid([0.0; 3]),
        grid([1.0, 0.0, 0.0]),
        grid([1.0, 0.0, 0.0]),
    ];
    let initial = [Pose::identity(); 4];
    let reg = register(&views, &initial, &params(GPA, 0.01)).unwrap();
    assert!(!reg.converged);
    assert_eq!(gpa_report(&reg).unconnected_views, vec![2, 3]);
    assert_eq!(gpa_report(&reg).stop, StopReason::Converged);
}

#[test]
fn bad_input_gives_typed_errors() {
    let ok = grid([0.0; 3]);
    let id = Pose::identity();
    let p = RegistrationParams::default();
    assert_eq!(
        register(std::slice::from_ref(&ok), &[id], &p),
        Err(RegistrationError::TooFewViews(1))
    );
    assert_eq!(
        register(&[ok.clone(), ok.clone()], &[id], &p),
        Err(RegistrationError::PoseCountMismatch { views: 2, poses: 1 })
    );
    assert_eq!(
        register(&[ok.clone(), PointCloud::default()], &[id, id], &p),
        Err(RegistrationError::EmptyView(1))
    );
    let mut nan = ok.clone();
    nan.points[7].x = f64::NAN;
    assert!(matches!(
        register(&[ok.clone(), nan], &[id, id], &p),
        Err(RegistrationError::InvalidView { view: 1, .. })
    ));
    let mut far = ok.clone();
    far.points[3].z = 1e300;
    assert_eq!(
        register(&[far, ok.clone()], &[id, id], &p),
        Err(RegistrationError::PointOutOfRange { view: 0, index: 3 })
    );
    let bad_ref = RegistrationParams {
        reference: 2,
        ..p.clone()
    };
    assert_eq!(
        register(&[ok.clone(), ok.clone()], &[id, id], &bad_ref),
        Err(RegistrationError::ReferenceOutOfRange {
            reference: 2,
            views: 2
        })
    );
    let nan_pose = Pose::translation(f64::NAN, 0.0, 0.0);
    assert_eq!(
        register(&[ok.clone(), ok.clone()], &[id, nan_pose], &p),
        Err(RegistrationError::NonFinitePose(1))
    );
    for bad in [
        RegistrationParams {
            max_correspondence_distance: 0.0,
            ..p.clone()
        },
        RegistrationParams {
            tolerance: f64::NAN,
            ..p.clone()
        },
        RegistrationParams {
            max_iterations: 0,
            ..p.clone()
        },
        RegistrationParams {
            max_inner_iterations: 0,
            ..p.clone()
        },
        RegistrationParams {
            normal_neighbours: 2,
            ..p.clone()
        },
    ] {
        assert!(matches!(
            register(&[ok.clone(), ok.clone()], &[id, id], &bad),
            Err(RegistrationError::InvalidParameter { .. })
        ));
    }
    // A view with a wrong normal column is refused before any work.
    let mut short = ok.clone();
    short.normals = Some(vec![Vector3::z(); 3]);
    assert!(matches!(
        register(&[ok, short], &[id, id], &p),
        Err(RegistrationError::InvalidView { view: 1, .. })
    ));
}
