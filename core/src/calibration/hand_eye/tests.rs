//! Tests of the hand-eye estimate: synthetic views with a known correction, outliers,
//! and directions the views cannot observe.

use super::*;
use nalgebra::Vector3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;

fn robot() -> Robot {
    crate::kinematics::comau_smart_six().unwrap()
}

/// The rig of paper-env1: its hand-eye error's size as σ, 0.05° joints, 2 mm / 0.2°.
fn uncertainty() -> PoseUncertainty {
    let prior = |r: f64, t: f64| PosePrior {
        rotation_sigma: r,
        translation_sigma: t,
    };
    PoseUncertainty {
        laser_noise: crate::registration::RangeNoise::constant(0.002),
        camera_noise: crate::registration::RangeNoise {
            sigma_at_1m: 0.04,
            exponent: 1.0,
        },
        laser_pose: prior(1e-4, 3e-4),
        camera_pose: prior(0.0075, 0.0035),
        hand_eye: prior(0.0071, 0.0031),
        joint_offset_sigma: 0.05f64.to_radians(),
        view_noise: prior(0.2f64.to_radians() / 3f64.sqrt(), 0.002),
    }
}

/// The truth `(E, δq)` of the tests.
fn truth() -> SVector<f64, PARAMS> {
    let deg = f64::to_radians;
    SVector::<f64, PARAMS>::from_column_slice(&[
        deg(0.4),
        deg(-0.3),
        deg(0.5),
        0.004,
        -0.003,
        0.002,
        deg(0.05),
        deg(-0.04),
        deg(0.03),
        deg(0.05),
        deg(-0.05),
        deg(0.05),
    ])
}

/// Information of the mount's prior for [`solve`].
fn mount() -> Matrix6<f64> {
    mount_information(&robot(), "dinast", &uncertainty()).unwrap()
}

/// The truth as the views determine it: the last joint's offset folded into `E`, to
/// first order (its column of the frame Jacobian is constant).
fn identifiable() -> SVector<f64, PARAMS> {
    let j = robot()
        .frame_jacobian(&crate::kinematics::Joints::zeros(), "dinast")
        .unwrap();
    let mut t = truth();
    let folded = j.column(5) * t[11];
    let mut e = t.fixed_rows_mut::<6>(0);
    e += folded;
    t[11] = 0.0;
    t
}

/// `n` camera views around the workspace: the true correction of each is `A·θ` plus the
/// standstill noise; the data pin every direction down to 0.5 mm / 0.1° except the
/// turn about `free` (world frame, or the view's optical axis where `None`), which
/// they leave free (and report garbage in).
fn views(n: usize, seed: u64, free: Option<Vector3<f64>>) -> Vec<ViewEvidence> {
    let (dr, dt) = (0.1f64.to_radians(), 0.0005);
    views_with(n, seed, |pose| {
        let axis = free.unwrap_or(pose.rotation * Vector3::z());
        let mut h = Matrix6::from_diagonal(&Vector6::new(
            1.0 / (dr * dr),
            1.0 / (dr * dr),
            1.0 / (dr * dr),
            1.0 / (dt * dt),
            1.0 / (dt * dt),
            1.0 / (dt * dt),
        ));
        // No information about the turn about the axis.
        let p = Matrix3::identity() - axis * axis.transpose();
        let hr = p * h.fixed_view::<3, 3>(0, 0) * p;
        h.fixed_view_mut::<3, 3>(0, 0).copy_from(&hr);
        (h, axis, [dr, dt])
    })
}

/// `n` camera views as in [`views`], each with what `info` gives at its pose: the data's
/// information, the axis of the turn it leaves free (garbage in the estimate), and the σ
/// of the estimate's noise per rotation and translation component.
fn views_with(
    n: usize,
    seed: u64,
    info: impl Fn(&crate::math::Pose) -> (Matrix6<f64>, Vector3<f64>, [f64; 2]),
) -> Vec<ViewEvidence> {
    let robot = robot();
    let u = uncertainty();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut normal = || -> f64 { rng.sample(StandardNormal) };
    (0..n)
        .map(|_| {
            let q = crate::kinematics::Joints::from([
                0.5 * normal(),
                0.2 + 0.2 * normal(),
                -0.6 + 0.2 * normal(),
                0.5 * normal(),
                0.9 + 0.3 * normal(),
                normal(),
            ]);
            let pose = robot.fk(&q, "dinast").unwrap();
            let a = design(&robot, "dinast", &q, &pose).unwrap();
            // The views move with every joint, the last one included.
            let mut physical = a;
            let r = pose.rotation.to_rotation_matrix().into_inner();
            let last = robot
                .frame_jacobian(&q, "dinast")
                .unwrap()
                .column(5)
                .into_owned();
            let mut column = physical.fixed_view_mut::<6, 1>(0, 11);
            column
                .fixed_rows_mut::<3>(0)
                .copy_from(&(r * last.fixed_rows::<3>(0)));
            column
                .fixed_rows_mut::<3>(3)
                .copy_from(&(r * last.fixed_rows::<3>(3)));
            let (sr, st) = (u.view_noise.rotation_sigma, u.view_noise.translation_sigma);
            let noise = Vector6::new(
                sr * normal(),
                sr * normal(),
                sr * normal(),
                st * normal(),
                st * normal(),
                st * normal(),
            );
            let truth = physical * truth() + noise;
            let (h, axis, [dr, dt]) = info(&pose);
            let mut estimate = truth
                + Vector6::new(
                    dr * normal(),
                    dr * normal(),
                    dr * normal(),
                    dt * normal(),
                    dt * normal(),
                    dt * normal(),
                );
            let garbage = axis * 0.05 * normal();
            let mut turn = estimate.fixed_rows_mut::<3>(0);
            turn += garbage;
            let m = (Matrix6::identity() + h * covariance_of(&u.view_noise))
                .try_inverse()
                .unwrap();
            let weight = m * h;
            ViewEvidence {
                design: a,
                weight: (weight + weight.transpose()) * 0.5,
                estimate,
                table: false,
            }
        })
        .collect()
}

fn errors(e: &HandEyeEstimate) -> (f64, f64) {
    let t = identifiable();
    let r = (Vector3::from(e.rotation) - t.fixed_rows::<3>(0)).norm();
    let d = (Vector3::from(e.translation) - t.fixed_rows::<3>(3)).norm();
    (r.to_degrees(), d * 1e3)
}

/// Whether every component of `(E, δq)` lies within 4σ of the truth by the estimate's
/// own covariance.
fn within_its_sigma(e: &HandEyeEstimate) -> bool {
    let t = identifiable();
    let est: Vec<f64> = e
        .rotation
        .iter()
        .chain(&e.translation)
        .chain(&e.joint_offsets)
        .copied()
        .collect();
    (0..PARAMS).all(|k| (est[k] - t[k]).abs() <= 4.0 * e.covariance[(k, k)].sqrt())
}

#[test]
fn forty_views_recover_the_hand_eye_within_its_own_sigma() {
    // Every view blind to the turn about the vertical (a bottle's axis).
    let e = solve(&views(40, 3, Some(Vector3::z())), &mount(), &uncertainty()).unwrap();
    assert!(within_its_sigma(&e), "{e:?}");
    // Far better than the prior alone (the error itself: 0.7°, 5.4 mm): at 2 mm /
    // 0.2° of noise per standstill, 40 views pin the mount down to about 0.06° / 0.5 mm.
    assert!(
        e.sigma[0].to_degrees() < 0.08 && e.sigma[1] < 6e-4,
        "{:?}",
        e.sigma
    );
    let (r, t) = errors(&e);
    assert!(r < 0.2 && t < 1.0, "off by {r}° and {t} mm");
    assert_eq!(e.views, 40);
}

#[test]
fn forty_views_of_the_table_alone_fix_every_direction_of_the_mount() {
    // What a view's table tells (TableEvidence): its two tilts and its height, to 0.01°
    // and 0.1 mm, nothing about the turn about the vertical or a slide along the table.
    // The views look at the table from many directions, so together they see the mount's
    // every direction.
    let (dr, dt) = (0.01f64.to_radians(), 0.0001);
    let up = Vector3::z();
    let tilts = Matrix3::identity() - up * up.transpose();
    let table = |_: &crate::math::Pose| {
        let mut h = Matrix6::zeros();
        h.fixed_view_mut::<3, 3>(0, 0)
            .copy_from(&(tilts / (dr * dr)));
        h.fixed_view_mut::<3, 3>(3, 3)
            .copy_from(&(up * up.transpose() / (dt * dt)));
        (h, up, [dr, dt])
    };
    let e = solve(&views_with(40, 5, table), &mount(), &uncertainty()).unwrap();
    assert!(within_its_sigma(&e), "{e:?}");
    // The standstill's 2 mm / 0.2° per view is what is left: σ 0.036° / 0.92 mm here
    // (off by 0.049° and 0.71 mm).
    assert!(
        e.sigma[0].to_degrees() < 0.05 && e.sigma[1] < 1.2e-3,
        "{:?}",
        e.sigma
    );
    let (r, t) = errors(&e);
    assert!(r < 0.1 && t < 1.2, "off by {r}° and {t} mm");
}

#[test]
fn four_hundred_views_recover_it_within_a_fiftieth_of_a_degree_and_a_third_of_a_millimetre() {
    // The last joint's offset is folded into the mount (the two move the camera alike),
    // so no split is left to the priors: the error falls as the views add up (0.012° and
    // 0.16 mm here, against 0.02° and 0.2 mm of the estimate's own σ).
    let e = solve(&views(400, 4, Some(Vector3::z())), &mount(), &uncertainty()).unwrap();
    assert!(within_its_sigma(&e), "{e:?}");
    let (r, t) = errors(&e);
    assert!(r < 0.05 && t < 0.3, "off by {r}° and {t} mm");
    assert!(e.sigma[0].to_degrees() < 0.03, "{:?}", e.sigma);
    assert_eq!(e.joint_offsets[5], 0.0);
}

#[test]
fn a_few_registrations_pulled_far_off_do_not_move_the_estimate() {
    let mut terms = views(40, 5, Some(Vector3::z()));
    for t in terms.iter_mut().take(4) {
        t.estimate += Vector6::new(0.09, -0.05, 0.02, 0.02, 0.015, -0.01);
    }
    let e = solve(&terms, &mount(), &uncertainty()).unwrap();
    assert!(within_its_sigma(&e), "{e:?}");
    let (r, t) = errors(&e);
    assert!(r < 0.2 && t < 1.0, "off by {r}° and {t} mm");
}

#[test]
fn a_turn_no_view_observes_stays_at_the_prior() {
    // Every view blind to the turn about its own optical axis: the mount's turn about
    // the camera's z is then seen by no view and stays at the prior's 0.
    let e = solve(&views(40, 3, None), &mount(), &uncertainty()).unwrap();
    let t = identifiable();
    assert!(
        e.rotation[2].abs() < 0.05f64.to_radians(),
        "{:?}",
        e.rotation
    );
    assert!((e.rotation[0] - t[0]).abs() < 0.1f64.to_radians());
    assert!((e.rotation[1] - t[1]).abs() < 0.1f64.to_radians());
    // The estimate says so: its worst rotation σ is the prior's.
    assert!(e.sigma[0] > 0.9 * uncertainty().hand_eye.rotation_sigma);
}

#[test]
fn without_views_there_is_no_estimate() {
    assert!(solve(&[], &mount(), &uncertainty()).is_none());
}

#[test]
fn a_correction_pose_and_its_twist_are_inverse() {
    let o = Point3::new(0.4, -0.2, 0.9);
    let xi = Vector6::new(0.01, -0.02, 0.005, 0.003, -0.001, 0.002);
    let pose = correction_pose(&xi, &o);
    assert!((correction_of(&pose, &o) - xi).norm() < 1e-15);
    // The sensor origin moves by the translation alone.
    assert!(((pose * o - o) - xi.fixed_rows::<3>(3)).norm() < 1e-15);
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(64))]

    /// Folding the last joint's offset into the mount changes nothing the camera sees: at
    /// any joints, with any offsets and mount error, the true sensor pose is the same.
    #[test]
    fn the_identifiable_mount_moves_the_camera_as_the_injected_errors_do(
        q in proptest::array::uniform6(-1.5f64..1.5),
        offsets in proptest::array::uniform6(-0.01f64..0.01),
        turn in proptest::array::uniform3(-0.05f64..0.05),
        shift in proptest::array::uniform3(-0.01f64..0.01),
    ) {
        let robot = robot();
        let mount = Pose::from_parts(
            Translation3::from(Vector3::from(shift)),
            UnitQuaternion::from_scaled_axis(Vector3::from(turn)),
        );
        let (folded, rest) = identifiable_mount(&robot, "dinast", &mount, offsets).unwrap();
        proptest::prop_assert_eq!(rest[5], 0.0);
        proptest::prop_assert_eq!(&rest[..5], &offsets[..5]);
        let q = crate::kinematics::Joints::from(q);
        let injected = robot
            .fk(&(q + crate::kinematics::Joints::from(offsets)), "dinast")
            .unwrap()
            * mount;
        let identified = robot
            .fk(&(q + crate::kinematics::Joints::from(rest)), "dinast")
            .unwrap()
            * folded;
        let moved = (injected.translation.vector - identified.translation.vector).norm();
        proptest::prop_assert!(moved < 1e-12, "{moved}");
        proptest::prop_assert!(injected.rotation.angle_to(&identified.rotation) < 1e-12);
    }
}

/// The design maps the hand-eye error (a pose error in the sensor frame) and the joint
/// offsets to a view's world-frame correction about its sensor origin: each column against
/// a finite difference of the forward kinematics, at random joints. The last joint's
/// column is zero (it turns the frame as the mount does, and is folded into it).
#[test]
fn the_design_is_the_derivative_of_the_view_pose() {
    let robot = robot();
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let h = 1e-6;
    for _ in 0..5 {
        let q = crate::kinematics::Joints::from_fn(|_, _| rng.random_range(-0.8..0.8));
        let pose = robot.fk(&q, "dinast").unwrap();
        let origin = Point3::from(pose.translation.vector);
        let a = design(&robot, "dinast", &q, &pose).unwrap();
        for col in 0..PARAMS {
            let moved = if col < 6 {
                // The mount turned or shifted by h in the sensor frame.
                let mut xi = Vector6::zeros();
                xi[col] = h;
                let (w, t) = (xi.fixed_rows::<3>(0), xi.fixed_rows::<3>(3));
                pose * Pose::from_parts(
                    Translation3::from(t.into_owned()),
                    UnitQuaternion::from_scaled_axis(w.into_owned()),
                )
            } else {
                let mut qe = q;
                qe[col - 6] += h;
                robot.fk(&qe, "dinast").unwrap()
            };
            let numeric = correction_of(&(moved * pose.inverse()), &origin) / h;
            let expected = if col == PARAMS - 1 {
                Vector6::zeros()
            } else {
                a.column(col).into_owned()
            };
            assert!(
                (numeric - expected).amax() < 1e-5 || col == PARAMS - 1,
                "column {col}: finite difference {numeric:?}, design {expected:?}"
            );
            assert_eq!(
                a.column(col).norm() == 0.0,
                col == PARAMS - 1,
                "column {col}"
            );
        }
    }
}
