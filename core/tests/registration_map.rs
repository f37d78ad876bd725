//! The MAP registration on synthetic views with known truth: a view with a known offset
//! comes back within the noise bound; a view without overlap keeps its prior and says
//! so; a symmetric object keeps the prior's rotation about its axis; neither the surface
//! past the reference's edge nor a box's edges under noise drag a view off the truth; the
//! laser's free space pulls a view slid along a box's top back; matching along the
//! camera's rays agrees with the nearest point on noise-free views and brings a noisy view of a thin
//! cylinder closer; the camera's own free space pulls a view slid along a box's top back
//! and holds one started at the truth; the objective never rises; the result is the same at any thread count;
//! a run started where another ended stays there, and refined along the rays from the
//! nearest points' solution it ends where the two stages of one run end.

use nalgebra::{Isometry3, Point3, Unit, UnitQuaternion, Vector3};
use nbv_core::cloud::PointCloud;
use nbv_core::evaluation::alignment_error;
use nbv_core::math::Pose;
use nbv_core::registration::{
    DepthImageFreeSpace, FreeSpace, MapPreparation, MapReport, Method, MethodReport, PosePrior,
    RangeNoise, Registration, RegistrationError, RegistrationParams, ViewModel, register_prepared,
    register_prepared_from, register_with_models,
};
use nbv_fixtures::SyntheticSweep;
use proptest::prelude::*;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;

/// A bumpy surface z = f(x, y) seen from above (no symmetry).
fn bumpy(x: f64, y: f64) -> Point3<f64> {
    Point3::new(
        x,
        y,
        0.01 * (110.0 * x).sin() * (90.0 * y).cos() + 0.006 * (150.0 * (x + 0.5 * y)).sin(),
    )
}

/// A view of true points `truth` from `sensor` with range noise `sigma` (seeded), moved by
/// `error` (the reported pose's error: the points as the robot would place them).
fn view(
    truth: Vec<Point3<f64>>,
    sensor: Point3<f64>,
    sigma: f64,
    seed: u64,
    error: &Pose,
) -> PointCloud {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let points: Vec<Point3<f64>> = truth
        .iter()
        .map(|t| {
            let ray = (t - sensor).normalize();
            let n: f64 = rng.sample(StandardNormal);
            error * (t + ray * sigma * n)
        })
        .collect();
    let mut cloud = PointCloud::from_points(points);
    cloud.origins = Some(vec![error * sensor; truth.len()]);
    cloud.truth = Some(truth);
    cloud
}

fn grid(x0: f64, x1: f64, y0: f64, y1: f64, step: f64) -> Vec<Point3<f64>> {
    let nx = ((x1 - x0) / step) as usize;
    let ny = ((y1 - y0) / step) as usize;
    (0..nx)
        .flat_map(|i| (0..ny).map(move |j| bumpy(x0 + i as f64 * step, y0 + j as f64 * step)))
        .collect()
}

fn params() -> RegistrationParams {
    let mut p = RegistrationParams {
        method: Method::Map,
        max_correspondence_distance: 0.03,
        ..Default::default()
    };
    p.map.view_to_view = false;
    p
}

fn models(n: usize, camera_sigma: f64, prior: PosePrior) -> Vec<ViewModel> {
    (0..n)
        .map(|k| ViewModel {
            noise: RangeNoise::constant(if k == 0 { 0.0005 } else { camera_sigma }),
            prior: (k > 0).then_some(prior),
        })
        .collect()
}

/// A view of range noise `sigma` without a prior.
fn free(sigma: f64) -> ViewModel {
    ViewModel {
        noise: RangeNoise::constant(sigma),
        prior: None,
    }
}

fn map_report(r: &Registration) -> &MapReport {
    match &r.report {
        MethodReport::Map(m) => m,
        _ => panic!("not a MAP report"),
    }
}

/// The laser view (front, accurate) and a camera view that overlaps it, the camera's
/// reported pose off by `error`.
fn two_views(error: &Pose, camera_sigma: f64, seed: u64) -> Vec<PointCloud> {
    let laser = view(
        grid(0.0, 0.12, 0.0, 0.12, 0.004),
        Point3::new(0.06, -0.5, 1.0),
        0.0005,
        seed,
        &Pose::identity(),
    );
    let camera = view(
        grid(0.03, 0.15, 0.02, 0.14, 0.003),
        Point3::new(0.09, 0.08, 0.45),
        camera_sigma,
        seed + 1,
        error,
    );
    vec![laser, camera]
}

#[test]
fn a_known_offset_returns_to_truth_within_the_noise_bound() {
    let axis = Unit::new_normalize(Vector3::new(0.3, -0.5, 0.8));
    let error = Pose::from_parts(
        Vector3::new(0.004, -0.003, 0.002).into(),
        UnitQuaternion::from_axis_angle(&axis, 1f64.to_radians()),
    );
    let views = two_views(&error, 0.004, 7);
    let prior = PosePrior {
        rotation_sigma: 0.6f64.to_radians(),
        translation_sigma: 0.004,
    };
    let initial = vec![Pose::identity(); 2];
    let r = register_with_models(&views, &initial, &models(2, 0.004, prior), &params()).unwrap();
    let start = alignment_error(&views[1..], &initial[1..]).mean;
    let end = alignment_error(&views[1..], &r.poses[1..]).mean;
    let report = map_report(&r);
    assert!(r.converged && report.accepted, "{}", report.verdict);
    assert!(report.objective_final < report.objective_initial);
    // At most half the starting error (measured: 4.7 -> 1.3 mm; the noise alone would
    // allow a few tenths of a millimetre, which this patch does not reach).
    assert!(end < 0.5 * start, "{end} vs {start}");
    assert!(end < 1.5e-3, "end {end} (start {start})");
    assert_eq!(r.poses[0], initial[0]);
}

/// A run started where another ended (the pipeline's calibrated passes) ends where that
/// one ended: the priors stay centred on the initial poses, so the objective and each
/// view's correction are those of the first run; one start pose per view is required.
#[test]
fn a_run_started_where_another_ended_stays_there() {
    let error = Pose::from_parts(
        Vector3::new(0.003, 0.002, -0.002).into(),
        UnitQuaternion::from_axis_angle(&Vector3::x_axis(), 0.6f64.to_radians()),
    );
    let views = two_views(&error, 0.004, 11);
    let prior = PosePrior {
        rotation_sigma: 0.6f64.to_radians(),
        translation_sigma: 0.004,
    };
    let models = models(2, 0.004, prior);
    let params = params();
    let initial = vec![Pose::identity(); 2];
    let prepared = MapPreparation::new(&views, &models, &params).unwrap();
    let first = register_prepared(&prepared, &views, &initial, &models, &params).unwrap();
    let again = register_prepared_from(&prepared, &views, &initial, &first.poses, &models, &params)
        .unwrap();
    let (a, b) = (map_report(&first), map_report(&again));
    assert!(a.accepted && b.accepted, "{} / {}", a.verdict, b.verdict);
    assert_eq!(a.objective_initial, b.objective_initial);
    assert!(b.objective_final <= a.objective_final * (1.0 + 1e-9) + 1e-9);
    // Measured: the second run takes one step of well under a micrometre.
    let moved = first.poses[1].inverse() * again.poses[1];
    let centre = views[1].centroid().unwrap();
    assert!((moved * centre - centre).norm() < 1e-5, "{moved}");
    assert!(moved.rotation.angle() < 0.001f64.to_radians(), "{moved}");
    for (x, y) in a.views[1].correction.iter().zip(&b.views[1].correction) {
        assert!(
            (x - y).abs() < 2e-5,
            "{:?} vs {:?}",
            a.views[1].correction,
            b.views[1].correction
        );
    }
    let short =
        register_prepared_from(&prepared, &views, &initial, &initial[..1], &models, &params);
    assert!(matches!(
        short,
        Err(RegistrationError::PoseCountMismatch { views: 2, poses: 1 })
    ));
}

/// Points of an upright cylinder about the z axis (`radius`, `height`; its radius
/// rippled by `bump`) between azimuths `from` and `to` (degrees, 0 facing −y), every
/// ~`step`.
fn cylinder_band(
    radius: f64,
    height: f64,
    step: f64,
    bump: f64,
    (from, to): (f64, f64),
) -> Vec<Point3<f64>> {
    let arc = (to - from).to_radians() * radius;
    let (na, nz) = ((arc / step) as usize, (height / step) as usize);
    (0..=na)
        .flat_map(|i| (0..=nz).map(move |j| (i, j)))
        .map(|(i, j)| {
            let a = (from + (to - from) * i as f64 / na as f64).to_radians();
            let z = height * j as f64 / nz as f64;
            let r = radius + bump * (5.0 * a).sin() * (40.0 * z).cos();
            Point3::new(r * a.sin(), -r * a.cos(), z)
        })
        .collect()
}

/// A bumpy cylinder (radius 4 cm, 10 cm tall), every ~3 mm.
fn cylinder(from: f64, to: f64) -> Vec<Point3<f64>> {
    cylinder_band(0.04, 0.1, 0.003, 0.003, (from, to))
}

/// A camera view that sees around an object past the edge of what the reference saw
/// (the reference: the front of a bumpy cylinder, ±40°; the camera: 0–110°), noise-free,
/// started at the truth, without a prior: the surface the reference did not see must not
/// drag the view towards the reference's edge (without boundary rejection it moved it
/// 7.6 mm here).
#[test]
fn a_view_that_sees_past_the_references_edge_stays_at_the_truth() {
    let reference = view(
        cylinder(-40.0, 40.0),
        Point3::new(0.0, -0.8, 0.5),
        0.0,
        1,
        &Pose::identity(),
    );
    let camera = view(
        cylinder(0.0, 110.0),
        Point3::new(0.3, -0.2, 0.3),
        0.0,
        2,
        &Pose::identity(),
    );
    let views = vec![reference, camera];
    let free = vec![
        ViewModel {
            noise: RangeNoise::constant(0.0005),
            prior: None,
        },
        ViewModel {
            noise: RangeNoise::constant(0.004),
            prior: None,
        },
    ];
    let initial = vec![Pose::identity(); 2];
    let r = register_with_models(&views, &initial, &free, &params()).unwrap();
    let end = alignment_error(&views[1..], &r.poses[1..]).mean;
    // The overlap (0–40°) is matched: about a third of the camera's points.
    let inliers = map_report(&r).views[1].inliers;
    assert!(inliers > 200, "{inliers} inliers");
    assert!(
        end < 5e-5,
        "the camera view moved {:.3} mm off the truth",
        end * 1e3
    );
}

/// Points every 3 mm on the faces of a 10 × 8 × 12 cm box (x ∈ [0, 0.1], y ∈ [0, 0.08],
/// z ∈ [0, 0.12]): the front (y = 0) and the top, and the right side (x = 0.1) if `side`.
fn box_faces(side: bool) -> Vec<Point3<f64>> {
    let (w, d, h, step) = (0.1, 0.08, 0.12, 0.003);
    let steps = |len: f64| (0..=(len / step) as usize).map(move |i| i as f64 * step);
    let front = steps(w).flat_map(move |x| steps(h).map(move |z| Point3::new(x, 0.0, z)));
    let top = steps(w).flat_map(move |x| steps(d).map(move |y| Point3::new(x, y, h)));
    let mut points: Vec<Point3<f64>> = front.chain(top).collect();
    if side {
        points.extend(steps(d).flat_map(move |y| steps(h).map(move |z| Point3::new(w, y, z))));
    }
    points
}

/// A noisy camera view of a box's edges (6 mm along its rays), started at the truth,
/// without a prior, against an accurate reference of two of its faces: the noise scatters
/// the camera's points across the edges, where the reference has no plane. Matched
/// point-to-point with only the reference's spacing across the ray, those points dragged
/// the view sideways: 3.3, 1.9 and 2.1 mm at these seeds. With the source's noise counted
/// in every direction: 1.4, 0.8 and 0.4 mm (what is left comes from the side face the
/// reference did not see, next to its edges; without that face, < 0.6 mm each).
#[test]
fn a_noisy_view_of_a_boxs_edges_stays_at_the_truth() {
    let models = vec![free(0.0005), free(0.006)];
    let mut ends = Vec::new();
    for seed in [11, 12, 13] {
        let reference = view(
            box_faces(false),
            Point3::new(0.05, -0.8, 0.6),
            0.0005,
            seed,
            &Pose::identity(),
        );
        let camera = view(
            box_faces(true),
            Point3::new(0.3, -0.25, 0.35),
            0.006,
            seed + 100,
            &Pose::identity(),
        );
        let views = vec![reference, camera];
        let initial = vec![Pose::identity(); 2];
        let r = register_with_models(&views, &initial, &models, &params()).unwrap();
        ends.push(alignment_error(&views[1..], &r.poses[1..]).mean);
    }
    let mean = ends.iter().sum::<f64>() / ends.len() as f64;
    assert!(mean < 1.2e-3, "moved {ends:?} m off the truth");
}

/// A smooth cylinder of radius 2 cm (a handle), 12 cm tall, every 2.5 mm.
fn handle(from: f64, to: f64) -> Vec<Point3<f64>> {
    cylinder_band(0.02, 0.12, 0.0025, 0.0, (from, to))
}

/// An accurate reference of a handle's front and a camera view of its side (noise
/// `sigma` along the camera's rays), the camera's points and origins given in the camera's
/// own frame (reported pose `initial[1]`, off the truth by `error`).
fn handle_views(sigma: f64, seed: u64, error: &Pose) -> (Vec<PointCloud>, Vec<Pose>) {
    let reference = view(
        handle(-70.0, 70.0),
        Point3::new(0.0, -0.9, 0.5),
        0.0005,
        seed,
        &Pose::identity(),
    );
    let mut camera = view(
        handle(-20.0, 120.0),
        Point3::new(0.25, -0.3, 0.2),
        sigma,
        seed + 100,
        error,
    );
    let mount = Pose::from_parts(
        Vector3::new(0.25, -0.3, 0.2).into(),
        UnitQuaternion::from_euler_angles(2.0, -0.4, 0.9),
    );
    camera.transform(&mount.inverse());
    (vec![reference, camera], vec![Pose::identity(), mount])
}

/// The pipeline's refinement: matching along the rays, in a run started where the
/// nearest points' run ended (with the same priors), is accepted and takes the view no
/// farther from the truth than the nearest points left it.
#[test]
fn refining_along_the_rays_from_the_nearest_solution_keeps_or_lowers_the_error() {
    let error = Pose::from_parts(
        Vector3::new(0.003, -0.002, 0.001).into(),
        UnitQuaternion::from_axis_angle(&Vector3::z_axis(), 0.4f64.to_radians()),
    );
    let prior = PosePrior {
        rotation_sigma: 0.5f64.to_radians(),
        translation_sigma: 0.004,
    };
    let models = models(2, 0.004, prior);
    for seed in [41, 42] {
        let (views, initial) = handle_views(0.004, seed, &error);
        let prepared = MapPreparation::new(&views, &models, &params()).unwrap();
        let nearest = register_prepared(&prepared, &views, &initial, &models, &params()).unwrap();
        let mut rays = params();
        rays.map.along_rays = true;
        let refined =
            register_prepared_from(&prepared, &views, &initial, &nearest.poses, &models, &rays)
                .unwrap();
        assert!(
            map_report(&refined).accepted,
            "{}",
            map_report(&refined).verdict
        );
        let start = alignment_error(&views[1..], &initial[1..]).mean;
        let near = alignment_error(&views[1..], &nearest.poses[1..]).mean;
        let along = alignment_error(&views[1..], &refined.poses[1..]).mean;
        println!(
            "seed {seed}: {:.3} mm as given, {:.3} mm nearest, {:.3} mm refined",
            start * 1e3,
            near * 1e3,
            along * 1e3
        );
        // Measured: 3.72 → 2.04 → 1.86 mm (seed 41), 3.73 → 1.54 → 1.21 mm (seed 42).
        assert!(
            along < 0.6 * start,
            "seed {seed}: refined {along} from {start}"
        );
        assert!(
            along <= near,
            "seed {seed}: refined {along}, nearest {near}"
        );
    }
}

/// Noise-free points of a view started at the truth: matched where their rays cross the
/// reference (`along_rays`), they end where matched at their nearest reference points —
/// the ray, the crossing and the surfel in the right frames. (Both move the view 0.4 mm,
/// measured: a surfel is the mean of 16 points, which lies inside a 2 cm cylinder.)
#[test]
fn matching_along_the_rays_agrees_with_the_nearest_on_noise_free_views() {
    let models = vec![free(0.0005), free(0.004)];
    let (views, initial) = handle_views(0.0, 31, &Pose::identity());
    let end = |along_rays: bool| {
        let mut params = params();
        params.map.along_rays = along_rays;
        let r = register_with_models(&views, &initial, &models, &params).unwrap();
        assert!(map_report(&r).views[1].inliers > 300);
        alignment_error(&views[1..], &r.poses[1..]).mean
    };
    let (nearest, along) = (end(false), end(true));
    assert!(
        nearest < 6e-4,
        "nearest: {:.3} mm off the truth",
        nearest * 1e3
    );
    assert!(
        (along - nearest).abs() < 5e-5,
        "along the rays {:.3} mm, nearest {:.3} mm off the truth",
        along * 1e3,
        nearest * 1e3
    );
}

/// A camera view of a thin cylinder with 6 mm of noise along its rays, started at the
/// truth: matched along the rays it ends no farther from the truth than matched at its
/// nearest reference points (within 0.1 mm), and within 2 mm, at each of three seeds
/// (measured: 1.40, 0.22, 0.25 mm nearest; 0.23, 0.25, 0.25 mm along the rays): the truth
/// is a fixed point of both, and where the nearest points hold the view 1.4 mm off, the
/// rays do not.
///
/// Matching along the rays captures a view from less far off than nearest points do, so
/// the pipeline matches along the rays only to refine a registration where it ended
/// (docs/registration.md, "Refining along the camera's rays once").
#[test]
fn matching_along_the_rays_keeps_a_noisy_view_started_at_the_truth() {
    let models = vec![free(0.0005), free(0.006)];
    for seed in [21, 22, 23] {
        let (views, initial) = handle_views(0.006, seed, &Pose::identity());
        let end = |along_rays: bool| {
            let mut params = params();
            params.map.along_rays = along_rays;
            let r = register_with_models(&views, &initial, &models, &params).unwrap();
            assert!(map_report(&r).accepted, "{}", map_report(&r).verdict);
            alignment_error(&views[1..], &r.poses[1..]).mean
        };
        let (nearest, along) = (end(false), end(true));
        assert!(
            along < nearest + 1e-4 && along < 2e-3,
            "seed {seed}: along the rays {:.3} mm, nearest {:.3} mm off the truth",
            along * 1e3,
            nearest * 1e3
        );
    }
}

#[test]
fn a_view_without_overlap_keeps_its_prior_and_is_flagged() {
    let error = Pose::translation(0.003, 0.0, 0.0);
    let mut views = two_views(&error, 0.004, 3);
    // Move the camera view half a metre away from everything.
    views[1].transform(&Pose::translation(0.5, 0.0, 0.0));
    let prior = PosePrior {
        rotation_sigma: 0.01,
        translation_sigma: 0.004,
    };
    let initial = vec![Pose::identity(); 2];
    let r = register_with_models(&views, &initial, &models(2, 0.004, prior), &params()).unwrap();
    let report = map_report(&r);
    assert!(report.views[1].unconstrained);
    assert_eq!(report.views[1].inliers, 0);
    assert!((r.poses[1].to_homogeneous() - initial[1].to_homogeneous()).norm() < 1e-12);
}

#[test]
fn a_symmetric_object_keeps_the_priors_rotation_about_its_axis() {
    // A cylinder of radius 5 cm about the vertical axis through (0.5, 0, 0).
    let centre = Point3::new(0.5, 0.0, 0.0);
    let at = |a: f64, z: f64| centre + Vector3::new(0.05 * a.cos(), 0.05 * a.sin(), z);
    let band = |a0: f64, a1: f64, z0: f64, z1: f64| -> Vec<Point3<f64>> {
        (0..60)
            .flat_map(|i| {
                (0..30).map(move |j| {
                    at(
                        a0 + (a1 - a0) * i as f64 / 60.0,
                        z0 + (z1 - z0) * j as f64 / 30.0,
                    )
                })
            })
            .collect()
    };
    let pi = std::f64::consts::PI;
    let laser = view(
        band(0.6 * pi, 1.4 * pi, -0.05, 0.05),
        Point3::new(-0.5, 0.0, 0.3),
        0.0005,
        1,
        &Pose::identity(),
    );
    // The camera sees a sector overlapping the laser's, its reported pose turned 1.5°
    // about the cylinder's axis (which the data cannot see) and 3 mm off sideways.
    let spin = Pose::rotation_wrt_point(
        UnitQuaternion::from_axis_angle(&Vector3::z_axis(), 1.5f64.to_radians()),
        centre,
    );
    let error = Pose::translation(0.0, 0.003, 0.0) * spin;
    let camera = view(
        band(0.9 * pi, 1.7 * pi, -0.04, 0.04),
        Point3::new(0.3, -0.35, 0.1),
        0.003,
        2,
        &error,
    );
    let views = vec![laser, camera];
    let initial = vec![Pose::identity(); 2];
    let prior = PosePrior {
        rotation_sigma: 0.02,
        translation_sigma: 0.005,
    };
    let r = register_with_models(&views, &initial, &models(2, 0.003, prior), &params()).unwrap();
    assert!(map_report(&r).accepted);
    // What is left of the error: the spin about the axis, and nothing else.
    let left = r.poses[1] * error;
    let turned = left.rotation.scaled_axis();
    // (The band's finite extent tells a little: 0.3° of the 1.5° move, measured.)
    assert!(
        (turned.z - 1.5f64.to_radians()).abs() < 0.4f64.to_radians(),
        "axis rotation {:.3}°",
        turned.z.to_degrees()
    );
    // The tilt of the axis is left within the noise: 0.5° moves the 8 cm band's ends by
    // 0.35 mm, a tenth of the camera's σ.
    assert!(turned.xy().norm() < 0.5f64.to_radians(), "{turned}");
    // The sideways error is not made worse (it is not removed either on this band: the
    // view stays at its prior; docs/registration.md, "What is left: the box").
    let axis_error = (left * centre - centre).xy().norm();
    assert!(axis_error <= 0.0031, "axis moved {axis_error}");
}

#[test]
fn the_result_is_the_same_at_any_thread_count() {
    let error = Isometry3::new(
        Vector3::new(0.003, 0.002, -0.002),
        Vector3::new(0.01, 0.0, -0.01),
    );
    let views = two_views(&error, 0.004, 11);
    let prior = PosePrior {
        rotation_sigma: 0.01,
        translation_sigma: 0.004,
    };
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| {
                register_with_models(
                    &views,
                    &[Pose::identity(); 2],
                    &models(2, 0.004, prior),
                    &params(),
                )
                .unwrap()
            })
    };
    assert_eq!(run(1), run(2));
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 12, ..ProptestConfig::default() })]

    /// Whatever the reported error within the prior, the objective does not rise, the
    /// view never ends beyond the χ² gate, and it ends no farther from the truth than the
    /// farther of its start and its noise floor ([`never_worse`]). (How far it gets is not
    /// asserted here: from some starts this near-2.5-D patch leaves most of a pure shift
    /// along x in place.)
    #[test]
    fn never_worse_than_the_reported_pose(
        t in prop::array::uniform3(-0.006f64..0.006),
        w in prop::array::uniform3(-0.012f64..0.012),
        seed in 0u64..1000,
    ) {
        let error = Isometry3::new(Vector3::from(t), Vector3::from(w));
        if let Err(e) = never_worse(&error, seed) {
            return Err(TestCaseError::fail(e));
        }
    }
}

/// The camera's noise (m) and pose prior of [`never_worse`].
const NOISY_CAMERA: f64 = 0.004;
const NOISY_PRIOR: PosePrior = PosePrior {
    rotation_sigma: 0.01,
    translation_sigma: 0.005,
};

/// How far (m) the MAP's end may lie beyond where it ends started at the truth, on
/// [`two_views`] with a camera of 4 mm noise: its landing point moves with the start by
/// up to 0.36 mm there (measured over 20 starts 0–0.7 mm along y off the truth at seed
/// 11: 1.07–1.43 mm from the truth at the end, 1.07 mm started at the truth),
/// since at this noise the nearest-point matches change from one start to the next.
const LANDING_SPREAD: f64 = 5e-4;

/// Registers the camera of [`two_views`] reported off by `error` (noise seed `seed`),
/// and checks that the objective fell, the view passes the χ² gate, and it ends no
/// farther from the truth than it started (+0.2 mm) or than the registration started at
/// the truth ends (its noise floor, + [`LANDING_SPREAD`]) — a start already nearer than
/// the estimate's own error cannot be kept.
fn never_worse(error: &Pose, seed: u64) -> Result<(), String> {
    let views = two_views(error, NOISY_CAMERA, seed);
    let initial = vec![Pose::identity(); 2];
    let models = models(2, NOISY_CAMERA, NOISY_PRIOR);
    let r = register_with_models(&views, &initial, &models, &params()).unwrap();
    let report = map_report(&r);
    let prepared = MapPreparation::new(&views, &models, &params()).unwrap();
    let truth = [Pose::identity(), error.inverse()];
    let floor =
        register_prepared_from(&prepared, &views, &initial, &truth, &models, &params()).unwrap();
    let start = alignment_error(&views[1..], &initial[1..]).mean;
    let end = alignment_error(&views[1..], &r.poses[1..]).mean;
    let from_truth = alignment_error(&views[1..], &floor.poses[1..]).mean;
    if report.objective_final > report.objective_initial {
        return Err(format!("the objective rose: {report:?}"));
    }
    if end > (start + 2e-4).max(from_truth + LANDING_SPREAD) {
        return Err(format!(
            "end {end} from start {start}; started at the truth, {from_truth}"
        ));
    }
    match report.views[1].chi2 {
        Some(chi2) if chi2 <= 22.458 => Ok(()),
        other => Err(format!("χ² {other:?}")),
    }
}

/// The case that showed the noise floor: reported 0.72 mm off along y (0.74 mm of
/// alignment error with the noise), the view ends 1.41 mm off, and 1.07 mm off started at
/// the truth (measured) — farther than it started, but within the estimate's own spread
/// at 4 mm of noise.
#[test]
fn a_start_nearer_than_the_noise_floor_ends_within_its_landing_spread() {
    let error = Isometry3::new(Vector3::new(0.0, 0.00072, 0.0), Vector3::zeros());
    never_worse(&error, 11).unwrap();
}

/// A laser sweep from above (one ray every 2 mm, lines 2 mm apart, from a scanner 0.9 m
/// above the table, 0.25 m to the box's −x side) over a 10 × 8 × 12 cm box on a table:
/// every hit (box and table) with its origin, noise-free.
fn box_sweep() -> PointCloud {
    let sweep = SyntheticSweep {
        table_z: 0.0,
        table_xy: None,
        boxes: vec![([0.0, 0.0, 0.0], [0.1, 0.08, 0.12])],
        lines: 111,
        rays: 121,
        fan_deg: [11.3, 25.0],
        scanner_xz: [-0.25, 0.9],
        y_span: [-0.07, 0.15],
        range: [0.1, 3.0],
    };
    let (origins, points) = sweep.scan();
    let mut cloud = PointCloud::from_points(points);
    cloud.origins = Some(origins);
    cloud
}

/// The laser sees a box's top (and its −x face) from above; a noisy camera
/// view sees its top and the two far sides, its reported pose slid 8 mm along the top and
/// 6 mm across. The top fixes the view's height and tilt, only the top's rim its slide:
/// beyond the rim, camera points either float where the laser saw through to the table
/// (a contradiction: they are pulled back) or lie on the faces the laser never saw (no
/// evidence either way: they cost the same wherever the view goes). Without the laser's
/// free space the rim's evidence is thrown away with the unseen faces' (boundary
/// rejection), and the objective rewards sliding the unseen faces' points within reach of
/// the rim.
#[test]
fn the_lasers_free_space_pulls_a_slid_view_back_onto_a_boxs_top() {
    let size = Vector3::new(0.1, 0.08, 0.12);
    let step = 0.003;
    let steps = |len: f64| (0..=(len / step) as usize).map(move |i| i as f64 * step);
    let top = steps(size.x).flat_map(|x| steps(size.y).map(move |y| Point3::new(x, y, size.z)));
    let right = steps(size.y).flat_map(|y| steps(size.z).map(move |z| Point3::new(size.x, y, z)));
    let back = steps(size.x).flat_map(|x| steps(size.z).map(move |z| Point3::new(x, size.y, z)));
    let seen: Vec<Point3<f64>> = top.chain(right).chain(back).collect();
    let prior = PosePrior {
        rotation_sigma: 1f64.to_radians(),
        translation_sigma: 0.01,
    };
    let models = models(2, 0.006, prior);
    let mut params = params();
    params.max_correspondence_distance = 0.05;
    let error = Pose::from_parts(
        Vector3::new(0.008, 0.006, 0.0).into(),
        UnitQuaternion::from_axis_angle(&Vector3::z_axis(), 0.5f64.to_radians()),
    );
    let (mut with, mut without, mut start) = (Vec::new(), Vec::new(), Vec::new());
    for seed in [21, 22, 23] {
        let sweep = box_sweep();
        let on_box: Vec<usize> = (0..sweep.len())
            .filter(|&k| sweep.points[k].z > 0.005)
            .collect();
        let reference = sweep.select(&on_box);
        let camera = view(
            seen.clone(),
            Point3::new(0.3, 0.3, 0.4),
            0.006,
            seed + 100,
            &error,
        );
        let views = vec![reference, camera];
        let initial = vec![Pose::identity(); 2];
        let lo = Point3::new(-0.05, -0.05, -0.05);
        let hi = Point3::new(0.15, 0.13, 0.17);
        let free_space = FreeSpace::of_scan(&sweep, lo, hi, 0.0015).unwrap().unwrap();
        let prepared = MapPreparation::new(&views, &models, &params)
            .unwrap()
            .with_free_space(0, free_space)
            .unwrap();
        let r = register_prepared(&prepared, &views, &initial, &models, &params).unwrap();
        assert!(map_report(&r).accepted, "{}", map_report(&r).verdict);
        with.push(alignment_error(&views[1..], &r.poses[1..]).mean);
        let r = register_with_models(&views, &initial, &models, &params).unwrap();
        without.push(alignment_error(&views[1..], &r.poses[1..]).mean);
        start.push(alignment_error(&views[1..], &initial[1..]).mean);
    }
    let mean = |e: &[f64]| e.iter().sum::<f64>() / e.len() as f64 * 1e3;
    let each = |e: &[f64]| {
        e.iter()
            .map(|x| (x * 1e4).round() / 10.0)
            .collect::<Vec<_>>()
    };
    let (with_each, without_each) = (each(&with), each(&without));
    let (with, without, start) = (mean(&with), mean(&without), mean(&start));
    let report = format!(
        "start {start:.2} mm; without free space {without:.2} mm {without_each:?}; with \
         {with:.2} mm {with_each:?}"
    );
    // Measured: 9.92 mm -> 7.81 mm without free space (8.6, 8.0, 6.8), 2.51 mm with it
    // (2.4, 2.6, 2.5).
    println!("{report}");
    assert!(with < 0.4 * start, "{report}");
    assert!(with < 0.5 * without, "{report}");
}

/// A camera 0.45 m above the table looking straight down at a 10 × 8 × 12 cm box's top
/// (160 × 120 pixels, focal 150): each pixel's depth on the top or the table, and the
/// true points of the top's pixels.
fn camera_over_box(eye: Point3<f64>) -> (Pose, Vec<f32>, Vec<Point3<f64>>) {
    let (w, h, f) = (160usize, 120usize, 150.0);
    let optical = Pose::from_parts(
        eye.coords.into(),
        UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::PI),
    );
    let (mut depth, mut top) = (Vec::with_capacity(w * h), Vec::new());
    for v in 0..h {
        for u in 0..w {
            let ray = Vector3::new(
                (u as f64 + 0.5 - 0.5 * w as f64) / f,
                (v as f64 + 0.5 - 0.5 * h as f64) / f,
                1.0,
            );
            let z_top = eye.z - 0.12;
            let at_top = optical * Point3::from(ray * z_top);
            if (0.0..=0.1).contains(&at_top.x) && (0.0..=0.08).contains(&at_top.y) {
                depth.push(z_top as f32);
                top.push(at_top);
            } else {
                depth.push(eye.z as f32);
            }
        }
    }
    (optical, depth, top)
}

/// The mean alignment error (mm) over three noise seeds of a camera view of a box's top
/// (from [`camera_over_box`]) registered into the laser's view of the top, its reported
/// pose off by `error`: as acquired, without the camera's free space, and with it.
fn box_top_with_and_without_camera_free_space(error: &Pose) -> (f64, f64, f64) {
    let prior = PosePrior {
        rotation_sigma: 1f64.to_radians(),
        translation_sigma: 0.01,
    };
    let sigma = 0.002;
    let models = models(2, sigma, prior);
    let params = params();
    let eye = Point3::new(0.05, 0.04, 0.45);
    let (optical, depth, top) = camera_over_box(eye);
    let sweep = box_sweep();
    let on_top: Vec<usize> = (0..sweep.len())
        .filter(|&k| sweep.points[k].z > 0.115)
        .collect();
    let reference = sweep.select(&on_top);
    let (mut with, mut without, mut start) = (Vec::new(), Vec::new(), Vec::new());
    for seed in [31, 32, 33] {
        let camera = view(top.clone(), eye, sigma, seed, error);
        let views = vec![reference.clone(), camera];
        let initial = vec![Pose::identity(); 2];
        let free_space =
            DepthImageFreeSpace::new(error * optical, 150.0, 160, 120, &depth, |_| 3.0 * sigma)
                .unwrap();
        let prepared = MapPreparation::new(&views, &models, &params).unwrap();
        let r = register_prepared(&prepared, &views, &initial, &models, &params).unwrap();
        assert!(map_report(&r).accepted, "{}", map_report(&r).verdict);
        assert_eq!(map_report(&r).pairs, 1);
        without.push(alignment_error(&views[1..], &r.poses[1..]).mean);
        let prepared = prepared.with_depth_image(1, free_space).unwrap();
        let r = register_prepared(&prepared, &views, &initial, &models, &params).unwrap();
        assert!(map_report(&r).accepted, "{}", map_report(&r).verdict);
        // The laser → camera pair is there, for contradictions only.
        assert_eq!(map_report(&r).pairs, 2);
        with.push(alignment_error(&views[1..], &r.poses[1..]).mean);
        start.push(alignment_error(&views[1..], &initial[1..]).mean);
    }
    let mean = |e: &[f64]| e.iter().sum::<f64>() / e.len() as f64 * 1e3;
    (mean(&start), mean(&without), mean(&with))
}

/// The laser sees a box's top; a camera view sees the top alone, from above, its reported
/// pose slid 6 mm along the top and 4 mm across. The top fixes the view's height and tilt,
/// and nothing the laser saw fixes the slide: the camera's points past the laser's rim
/// cost the same wherever they go. The camera's own depth image does: where the view's
/// rim has slid in from the laser's, the laser's points lie where the camera saw through
/// to the table — a contradiction that pulls the view back.
#[test]
fn the_cameras_free_space_pulls_a_slid_view_back_onto_a_boxs_top() {
    let error = Pose::from_parts(
        Vector3::new(0.006, -0.004, 0.0).into(),
        UnitQuaternion::from_axis_angle(&Vector3::z_axis(), 0.3f64.to_radians()),
    );
    let (start, without, with) = box_top_with_and_without_camera_free_space(&error);
    let report = format!(
        "start {start:.2} mm; without the camera's free space {without:.2} mm; with it {with:.2} mm"
    );
    // Measured: 6.89 mm -> 6.20 mm without, 1.04 mm with.
    println!("{report}");
    assert!(with < 0.3 * start, "{report}");
    assert!(with < 0.4 * without, "{report}");
}

/// Started at the truth, the same view drifts no farther with the camera's free space than
/// without it: at the truth no laser point of the top lies where the camera saw through,
/// and the term holds the slide that the camera's noise alone would leave free.
#[test]
fn the_cameras_free_space_keeps_a_view_near_the_truth() {
    let (start, without, with) = box_top_with_and_without_camera_free_space(&Pose::identity());
    let report = format!(
        "start {start:.2} mm; without the camera's free space {without:.2} mm; with it {with:.2} mm"
    );
    // Measured: 0.05 mm -> 0.82 mm without, 0.55 mm with.
    println!("{report}");
    assert!(with < 0.7 && with <= without, "{report}");
}
