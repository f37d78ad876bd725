//! Tests of the kinematics on the real asset ([`super::COMAU_URDF`]): the
//! published geometry and sign conventions, FK∘IK properties, singular and unreachable
//! poses, sensor frames, and typed errors for malformed URDF.

use super::*;
use crate::math::{Pose, pose_from_xyz_rpy};
use nalgebra::{Point3, Rotation3, Translation3, UnitQuaternion, Vector3};
use proptest::prelude::*;
use std::f64::consts::{FRAC_PI_2, PI, TAU};
use std::sync::OnceLock;

const ASSET: &str = crate::kinematics::COMAU_URDF;

fn comau() -> &'static Robot {
    static ROBOT: OnceLock<Robot> = OnceLock::new();
    ROBOT.get_or_init(|| Robot::from_urdf_file(ASSET).unwrap())
}

fn asset_text() -> String {
    std::fs::read_to_string(ASSET).unwrap()
}

fn calibration() -> Joints {
    Joints::new(0.0, 0.0, -FRAC_PI_2, 0.0, 0.0, 0.0)
}

fn origin(robot: &Robot, q: &Joints, frame: &str) -> Vector3<f64> {
    robot.fk(q, frame).unwrap().translation.vector
}

fn axis(robot: &Robot, q: &Joints, frame: &str, local: Vector3<f64>) -> Vector3<f64> {
    robot.fk(q, frame).unwrap().rotation * local
}

fn pose_err(a: &Pose, b: &Pose) -> (f64, f64) {
    let dp = (a.translation.vector - b.translation.vector).norm();
    let dr = (a.rotation.to_rotation_matrix().matrix() - b.rotation.to_rotation_matrix().matrix())
        .norm();
    (dp, dr)
}

fn deg(d: f64) -> f64 {
    d.to_radians()
}

// ---------------------------------------------------------------- model and conventions

#[test]
fn asset_loads_with_expected_frames_and_limits() {
    let r = comau();
    assert_eq!(r.name(), "comau_smart_six");
    assert_eq!(r.base_frame(), "base_link");
    assert_eq!(r.tip_frame(), "link_6");
    assert_eq!(
        r.joint_names(),
        [
            "joint_1", "joint_2", "joint_3", "joint_4", "joint_5", "joint_6"
        ]
    );
    for f in [
        "base_link",
        "link_1",
        "link_6",
        "tool0",
        "ee_bracket",
        "lms400",
        "dinast",
    ] {
        assert!(r.frame_index(f).is_some(), "missing frame {f}");
    }
    let expected = [
        (-170.0, 170.0, 140.0),
        (-85.0, 155.0, 160.0),
        (-170.0, 0.0, 170.0),
        (-210.0, 210.0, 450.0),
        (-130.0, 130.0, 375.0),
        (-2700.0, 2700.0, 550.0),
    ];
    for (l, (lo, hi, v)) in r.limits().iter().zip(expected) {
        assert!((l.lower - deg(lo)).abs() < 1e-12);
        assert!((l.upper - deg(hi)).abs() < 1e-12);
        assert!((l.velocity - deg(v)).abs() < 1e-12);
        assert!(l.effort > 0.0);
    }
}

#[test]
fn ik_parameters_are_the_published_dh_lengths() {
    let p = comau().ik_parameters().unwrap();
    for (got, want) in [
        (p.a1, 0.150),
        (p.d1, 0.450),
        (p.a2, 0.590),
        (p.a3, 0.130),
        (p.d4, 0.64707),
        (p.d6, 0.095),
        (p.lateral, 0.0),
    ] {
        assert!((got - want).abs() < 1e-12, "{got} != {want}");
    }
    // Reach at the wrist centre: 1.400 m (the SMART SiX 6-1.4 data sheet).
    let reach = p.a1 + p.a2 + (p.a3 * p.a3 + p.d4 * p.d4).sqrt();
    assert!((reach - 1.400).abs() < 1e-3);
}

#[test]
fn calibration_pose_matches_the_published_geometry() {
    let r = comau();
    let q = calibration();
    let wrist = origin(r, &q, "link_5");
    assert!((wrist - Vector3::new(0.797, 0.0, 1.170)).norm() < 1e-3);
    assert!((wrist - Vector3::new(0.79707, 0.0, 1.17)).norm() < 1e-12);
    assert!((origin(r, &q, "link_2") - Vector3::new(0.15, 0.0, 0.45)).norm() < 1e-12);
    assert!((origin(r, &q, "link_3") - Vector3::new(0.15, 0.0, 1.04)).norm() < 1e-12);
    assert!((origin(r, &q, "link_6") - Vector3::new(0.89207, 0.0, 1.17)).norm() < 1e-12);
    // All link frames parallel to the base.
    for f in ["link_1", "link_2", "link_3", "link_4", "link_5", "link_6"] {
        let rot = r.fk(&q, f).unwrap().rotation;
        assert!(rot.angle() < 1e-12, "{f} is not parallel to the base");
    }
    // tool0: z along the forearm (out of the flange), x down, y left.
    assert!((axis(r, &q, "tool0", Vector3::z()) - Vector3::x()).norm() < 1e-12);
    assert!((axis(r, &q, "tool0", Vector3::x()) + Vector3::z()).norm() < 1e-12);
    assert!((axis(r, &q, "tool0", Vector3::y()) - Vector3::y()).norm() < 1e-12);
}

#[test]
fn joint_signs_follow_comau_conventions() {
    let r = comau();
    let base = calibration();
    let with = |k: usize, v: f64| {
        let mut q = base;
        q[k] += v;
        q
    };
    // +J1: clockwise seen from above (the wrist moves to -y).
    assert!(origin(r, &with(0, 0.3), "link_5").y < -0.1);
    // +J2: upper arm tilts forward (elbow moves to +x).
    assert!(origin(r, &with(1, 0.3), "link_3").x > 0.15 + 0.1);
    // J3 = 0: forearm straight up along the upper arm.
    let up = Joints::zeros();
    let w = origin(r, &up, "link_5");
    assert!((w - Vector3::new(0.02, 0.0, 1.04 + 0.64707)).norm() < 1e-12);
    // More negative J3 lowers the forearm.
    assert!(origin(r, &with(2, -0.3), "link_5").z < 1.17 - 0.1);
    // +J5 in the calibration pose tips the flange down.
    assert!(origin(r, &with(4, 0.3), "link_6").z < 1.17 - 0.02);
    assert!(axis(r, &with(4, 0.3), "tool0", Vector3::z()).z < -0.2);
    // J4 and J6 turn about -x: +J4 in the calibration pose turns the flange's tool0 y axis
    // from +y towards +z... about -x, i.e. y -> -z.
    assert!(axis(r, &with(3, 0.3), "tool0", Vector3::y()).z < -0.2);
    assert!(axis(r, &with(5, 0.3), "tool0", Vector3::y()).z < -0.2);
}

#[test]
fn sensor_frames_sit_on_the_bracket_as_documented() {
    let r = comau();
    let lms = r.frame_in_tip("lms400").unwrap();
    let din = r.frame_in_tip("dinast").unwrap();
    let tool = r.frame_in_tip("tool0").unwrap();
    let lms_t = tool.inverse() * lms;
    let din_t = tool.inverse() * din;
    let expect_rot = UnitQuaternion::from_euler_angles(0.0, 0.0, -FRAC_PI_2);
    assert!((lms_t.translation.vector - Vector3::new(-0.080, 0.0, 0.140)).norm() < 1e-12);
    assert!((din_t.translation.vector - Vector3::new(0.045, 0.0, 0.150)).norm() < 1e-12);
    assert!(lms_t.rotation.angle_to(&expect_rot) < 1e-12);
    assert!(din_t.rotation.angle_to(&expect_rot) < 1e-12);
    // Both look along tool0 +z; lms400 x (the fan) is tool0 -y; y is tool0 +x.
    for t in [lms_t, din_t] {
        assert!((t.rotation * Vector3::z() - Vector3::z()).norm() < 1e-12);
        assert!((t.rotation * Vector3::x() + Vector3::y()).norm() < 1e-12);
        assert!((t.rotation * Vector3::y() - Vector3::x()).norm() < 1e-12);
    }
    // In the calibration pose the LMS400 is on top and the Dinast below.
    let q = calibration();
    assert!(origin(r, &q, "lms400").z > origin(r, &q, "dinast").z + 0.1);
    // Fixed frames can be used for FK only: a frame before the tip is refused for IK.
    assert!(matches!(
        r.frame_in_tip("link_3"),
        Err(IkError::NotOnTip { .. })
    ));
}

/// Corners of a primitive's bounding box, in the frame of its link.
fn corners(g: &LinkGeometry) -> Vec<Point3<f64>> {
    let half = match g.shape {
        Shape::Box { size } => Vector3::from(size) / 2.0,
        Shape::Cylinder { radius, length } => Vector3::new(radius, radius, length / 2.0),
        Shape::Sphere { radius } => Vector3::repeat(radius),
        Shape::Capsule { radius, length } => Vector3::new(radius, radius, length / 2.0 + radius),
        Shape::Mesh { .. } => Vector3::zeros(),
    };
    (0..8)
        .map(|i| {
            let c = Vector3::new(
                if i & 1 == 0 { -half.x } else { half.x },
                if i & 2 == 0 { -half.y } else { half.y },
                if i & 4 == 0 { -half.z } else { half.z },
            );
            g.origin * Point3::from(c)
        })
        .collect()
}

#[test]
fn sensors_do_not_see_the_end_effector() {
    let r = comau();
    let q = calibration();
    let poses = r.link_poses(&q);
    let lms = r.fk(&q, "lms400").unwrap();
    let din = r.fk(&q, "dinast").unwrap();
    let ee = ["ee_bracket", "lms400", "dinast", "link_6"];
    for g in r
        .collision_geometry()
        .iter()
        .filter(|g| ee.contains(&g.link.as_str()))
    {
        for c in corners(g) {
            let world = poses[g.frame] * c;
            // Nothing is in front of the Dinast window.
            let in_din = din.inverse() * world;
            assert!(in_din.z <= 1e-12, "{} is in front of the Dinast", g.link);
            // The LMS400 fan plane (its x-z plane, in front of the window) meets nothing.
            let in_lms = lms.inverse() * world;
            if g.link != "lms400" && in_lms.z > 0.0 {
                assert!(in_lms.y > 0.01, "{} is in the LMS400 fan", g.link);
            }
        }
    }
    // The bodies sit behind their windows with the documented sizes.
    let body = |link: &str| {
        r.collision_geometry()
            .iter()
            .find(|g| g.link == link)
            .unwrap()
            .clone()
    };
    assert_eq!(
        body("lms400").shape,
        Shape::Box {
            size: [0.16, 0.10, 0.10]
        }
    );
    assert_eq!(
        body("dinast").shape,
        Shape::Box {
            size: [0.10, 0.05, 0.04]
        }
    );
    for link in ["lms400", "dinast"] {
        let max_z = corners(&body(link))
            .iter()
            .map(|c| c.z)
            .fold(f64::MIN, f64::max);
        assert!(max_z.abs() < 1e-12);
    }
}

#[test]
fn every_arm_link_has_collision_and_visual_geometry() {
    let r = comau();
    for link in [
        "base_link",
        "link_1",
        "link_2",
        "link_3",
        "link_4",
        "link_5",
        "link_6",
        "ee_bracket",
        "lms400",
        "dinast",
    ] {
        assert!(
            r.collision_geometry().iter().any(|g| g.link == link),
            "{link}"
        );
        assert!(r.visual_geometry().iter().any(|g| g.link == link), "{link}");
    }
    assert!(r.visual_geometry().iter().all(|g| g.rgba.is_some()));
    assert!(r.collision_geometry().iter().all(|g| g.rgba.is_none()));
    // Frames index the link poses.
    for g in r.collision_geometry() {
        assert_eq!(r.frame_names()[g.frame], g.link);
    }
}

/// An oriented box bounding a primitive, in the base frame: centre, axes, half extents.
fn bounding_obb(
    g: &LinkGeometry,
    link_pose: &Pose,
) -> (Vector3<f64>, [Vector3<f64>; 3], Vector3<f64>) {
    let half = match g.shape {
        Shape::Box { size } => Vector3::from(size) / 2.0,
        Shape::Cylinder { radius, length } => Vector3::new(radius, radius, length / 2.0),
        Shape::Sphere { radius } => Vector3::repeat(radius),
        Shape::Capsule { radius, length } => Vector3::new(radius, radius, length / 2.0 + radius),
        Shape::Mesh { .. } => Vector3::zeros(),
    };
    let pose = link_pose * g.origin;
    let axes = [Vector3::x(), Vector3::y(), Vector3::z()].map(|a| pose.rotation * a);
    (pose.translation.vector, axes, half)
}

/// Separating-axis test of two oriented boxes (true if they overlap).
fn obbs_overlap(
    a: &(Vector3<f64>, [Vector3<f64>; 3], Vector3<f64>),
    b: &(Vector3<f64>, [Vector3<f64>; 3], Vector3<f64>),
) -> bool {
    let d = b.0 - a.0;
    let mut candidates: Vec<Vector3<f64>> = a.1.iter().chain(b.1.iter()).copied().collect();
    for x in &a.1 {
        for y in &b.1 {
            let c = x.cross(y);
            if c.norm() > 1e-9 {
                candidates.push(c.normalize());
            }
        }
    }
    !candidates.iter().any(|axis| {
        let ra: f64 = (0..3).map(|i| a.2[i] * a.1[i].dot(axis).abs()).sum();
        let rb: f64 = (0..3).map(|i| b.2[i] * b.1[i].dot(axis).abs()).sum();
        d.dot(axis).abs() > ra + rb
    })
}

#[test]
fn no_self_collision_between_non_adjacent_links_in_working_poses() {
    // Bounding boxes of the primitives (conservative): links rigidly attached to the same
    // chain link form one body; bodies next to each other in the chain may overlap.
    let r = comau();
    assert_eq!(r.body_of("base_link").unwrap(), 0);
    assert_eq!(r.body_of("link_3").unwrap(), 3);
    assert_eq!(r.body_of("dinast").unwrap(), 6);
    let bodies: Vec<usize> = r
        .collision_geometry()
        .iter()
        .map(|g| r.body_of(&g.link).unwrap())
        .collect();
    assert_eq!(bodies.iter().max(), Some(&6));
    for q in [
        calibration(),
        Joints::zeros(),
        // Flange looking down at a table in front of the robot.
        Joints::new(0.0, 0.5, -1.8, 0.0, 0.84, 0.0),
        Joints::new(-0.8, 0.2, -1.2, 1.0, -1.2, 0.3),
    ] {
        let poses = r.link_poses(&q);
        let geoms = r.collision_geometry();
        for (i, a) in geoms.iter().enumerate() {
            for (j, b) in geoms.iter().enumerate().skip(i + 1) {
                if bodies[i].abs_diff(bodies[j]) < 2 {
                    continue;
                }
                let oa = bounding_obb(a, &poses[a.frame]);
                let ob = bounding_obb(b, &poses[b.frame]);
                assert!(
                    !obbs_overlap(&oa, &ob),
                    "{} hits {} at {q:?}",
                    a.link,
                    b.link
                );
            }
        }
    }
}

#[test]
fn link_poses_agree_with_fk() {
    let r = comau();
    let q = Joints::new(0.3, -0.2, -1.2, 0.7, 0.4, -2.0);
    let all = r.link_poses(&q);
    assert_eq!(all.len(), r.frame_names().len());
    for (name, pose) in r.frame_names().iter().zip(&all) {
        let (dp, dr) = pose_err(pose, &r.fk(&q, name).unwrap());
        assert!(dp == 0.0 && dr == 0.0);
    }
    assert!(matches!(r.fk(&q, "nope"), Err(FrameError { .. })));
}

// ---------------------------------------------------------------- inverse kinematics

/// Distance of `q` from the singularities, in the units of [`Singularity`].
fn singularity_distance(r: &Robot, q: &Joints) -> f64 {
    let q3_straight = -(0.13f64).atan2(0.64707);
    let wrist_radius = origin(r, q, "link_5").xy().norm();
    q[4].sin()
        .abs()
        .min((q[2] - q3_straight).abs())
        .min(wrist_radius)
}

fn joints_in_limits() -> impl Strategy<Value = Joints> {
    let l = comau().limits();
    (
        l[0].lower..l[0].upper,
        l[1].lower..l[1].upper,
        l[2].lower..l[2].upper,
        l[3].lower..l[3].upper,
        l[4].lower..l[4].upper,
        l[5].lower..l[5].upper,
    )
        .prop_map(|(a, b, c, d, e, f)| Joints::new(a, b, c, d, e, f))
}

fn same_mod_2pi(a: &Joints, b: &Joints, tol: f64) -> bool {
    a.iter().zip(b.iter()).all(|(x, y)| {
        let d = (x - y).rem_euclid(TAU);
        d.min(TAU - d) < tol
    })
}

fn check_round_trip(r: &Robot, frame: &str, q: &Joints) -> Result<(), TestCaseError> {
    let target = r.fk(q, frame).unwrap();
    let solutions = r.ik(frame, &target).unwrap();
    prop_assert!(!solutions.is_empty() && solutions.len() <= 8);
    for s in &solutions {
        let (dp, dr) = pose_err(&r.fk(&s.joints, frame).unwrap(), &target);
        prop_assert!(dp < 1e-9 && dr < 1e-9, "FK(IK) off by {dp:e} m, {dr:e}");
        prop_assert!(r.within_limits(&s.joints));
    }
    // Branches are distinct.
    for (i, a) in solutions.iter().enumerate() {
        for b in &solutions[i + 1..] {
            prop_assert!(!same_mod_2pi(&a.joints, &b.joints, 1e-9));
        }
    }
    if singularity_distance(r, q) > 1e-5 {
        prop_assert!(
            solutions.iter().any(|s| same_mod_2pi(&s.joints, q, 1e-7)),
            "no solution equals {q:?}: {solutions:?}"
        );
        let nearest = r.ik_nearest(frame, &target, q).unwrap();
        prop_assert!((nearest.joints - q).norm() < 1e-7);
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(10_000))]

    #[test]
    fn fk_ik_round_trip_on_the_flange(q in joints_in_limits()) {
        check_round_trip(comau(), "tool0", &q)?;
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(3000))]

    #[test]
    fn fk_ik_round_trip_on_the_sensor_frames(q in joints_in_limits()) {
        check_round_trip(comau(), "dinast", &q)?;
        check_round_trip(comau(), "lms400", &q)?;
        check_round_trip(comau(), "link_6", &q)?;
    }

    #[test]
    fn ik_nearest_returns_the_reference_even_at_singularities(
        q in joints_in_limits(), pick in 0usize..3,
    ) {
        // Force one singularity: wrist (J5 = 0), elbow (stretched), or none.
        let mut q = q;
        match pick {
            0 => q[4] = 0.0,
            1 => q[2] = -(0.13f64).atan2(0.64707),
            _ => {}
        }
        let r = comau();
        let target = r.fk(&q, "dinast").unwrap();
        let nearest = r.ik_nearest("dinast", &target, &q).unwrap();
        let (dp, dr) = pose_err(&r.fk(&nearest.joints, "dinast").unwrap(), &target);
        prop_assert!(dp < 1e-9 && dr < 1e-9);
        // Close to (but not at) the wrist singularity J4 and J6 are ill-conditioned: an
        // error ε in the wrist's rotation moves them by about ε / sin(J5), so the exact
        // pose (checked above) is reached by joints a little away from `q`.
        // At the stretched elbow, J2 and J3 move by about √ε for a pose error ε (the
        // elbow's position is quadratic in them there): 1e-12 in the pose is 1e-6 in them.
        let tol = if q[4] != 0.0 && q[4].sin().abs() < 1e-3 {
            1e-2
        } else if pick == 1 {
            1e-5
        } else {
            1e-6
        };
        prop_assert!((nearest.joints - q).norm() < tol, "{:?} vs {q:?}", nearest.joints);
        if pick == 0 {
            prop_assert!(nearest.singularity.wrist);
        }
    }
}

#[test]
fn calibration_pose_has_the_expected_branches() {
    let r = comau();
    let q = calibration();
    let target = r.fk(&q, "tool0").unwrap();
    let solutions = r.ik("tool0", &target).unwrap();
    // Front shoulder only (the back branch needs J1 = 180°); wrist singular (J5 = 0): one
    // wrist branch; elbow up and (stretched-over) elbow down if within J3's range.
    assert!(
        solutions
            .iter()
            .all(|s| s.branch.shoulder == Shoulder::Front)
    );
    assert!(solutions.iter().all(|s| s.singularity.wrist));
    let up = solutions
        .iter()
        .find(|s| s.branch.elbow == Elbow::Up)
        .unwrap();
    assert!((up.joints - q).norm() < 1e-12);
}

#[test]
fn eight_branches_for_a_generic_pose_with_wide_limits() {
    // Same arm with every joint range opened to ±180° (J3 included): all eight branches.
    let text = asset_text()
        .replace(
            r#"lower="-2.9670597283903604" upper="2.9670597283903604""#,
            r#"lower="-3.14159266" upper="3.14159266""#,
        )
        .replace(
            r#"lower="-1.4835298641951802" upper="2.705260340591211""#,
            r#"lower="-3.14159266" upper="3.14159266""#,
        )
        .replace(
            r#"lower="-2.9670597283903604" upper="0""#,
            r#"lower="-3.14159266" upper="3.14159266""#,
        )
        .replace(
            r#"lower="-2.2689280275926285" upper="2.2689280275926285""#,
            r#"lower="-3.14159266" upper="3.14159266""#,
        );
    let r = Robot::from_urdf_str(&text).unwrap();
    let q = Joints::new(0.4, -0.5, -1.9, 0.5, 0.8, -0.3);
    let target = r.fk(&q, "tool0").unwrap();
    let solutions = r.ik("tool0", &target).unwrap();
    assert_eq!(solutions.len(), 8);
    let branches: std::collections::HashSet<_> = solutions.iter().map(|s| s.branch).collect();
    assert_eq!(branches.len(), 8);
    for s in &solutions {
        let (dp, dr) = pose_err(&r.fk(&s.joints, "tool0").unwrap(), &target);
        assert!(dp < 1e-9 && dr < 1e-9);
        assert!(!s.singularity.any());
        // For the Comau the wrist branch is the sign of J5.
        assert_eq!(s.branch.wrist == Wrist::Positive, s.joints[4] > 0.0);
    }
    let original = solutions
        .iter()
        .find(|s| (s.joints - q).norm() < 1e-9)
        .unwrap();
    assert_eq!(
        original.branch,
        Branch {
            shoulder: Shoulder::Front,
            elbow: Elbow::Up,
            wrist: Wrist::Positive
        }
    );
}

#[test]
fn wrist_singularity_keeps_j4_at_the_reference() {
    let r = comau();
    let q = Joints::new(0.2, 0.3, -1.4, 0.4, 0.0, 0.5);
    let target = r.fk(&q, "tool0").unwrap();
    let reference = Joints::new(0.2, 0.3, -1.4, 1.1, 0.0, 0.0);
    let s = r.ik_nearest("tool0", &target, &reference).unwrap();
    assert!(s.singularity.wrist && !s.singularity.shoulder);
    assert!((s.joints[3] - 1.1).abs() < 1e-12);
    // Only J4 + J6 is determined (both axes along -x of the forearm).
    assert!((s.joints[3] + s.joints[5] - 0.9).abs() < 1e-9);
    let (dp, dr) = pose_err(&r.fk(&s.joints, "tool0").unwrap(), &target);
    assert!(dp < 1e-9 && dr < 1e-9);
    // Without a reference, ik() takes J4 at the middle of its range (0).
    let all = r.ik("tool0", &target).unwrap();
    assert!(
        all.iter()
            .filter(|s| s.singularity.wrist)
            .all(|s| s.joints[3] == 0.0)
    );
}

#[test]
fn shoulder_singularity_keeps_j1_at_the_reference() {
    let r = comau();
    // Wrist centre on the J1 axis, flange pointing straight up.
    let rot = Rotation3::from_axis_angle(&Vector3::y_axis(), -FRAC_PI_2);
    let w = Vector3::new(0.0, 0.0, 1.3);
    let tip = Pose::from_parts(
        Translation3::from(w + rot * Vector3::new(0.095, 0.0, 0.0)),
        UnitQuaternion::from_rotation_matrix(&rot),
    );
    let all = r.ik("link_6", &tip).unwrap();
    assert!(!all.is_empty());
    for s in &all {
        assert!(s.singularity.shoulder);
        assert_eq!(s.joints[0], 0.0);
        let (dp, dr) = pose_err(&r.fk(&s.joints, "link_6").unwrap(), &tip);
        assert!(dp < 1e-9 && dr < 1e-9);
    }
    let reference = Joints::new(0.7, 0.0, -1.5, 0.0, 0.5, 0.0);
    let s = r.ik_nearest("link_6", &tip, &reference).unwrap();
    assert!((s.joints[0] - 0.7).abs() < 1e-12);
    let (dp, dr) = pose_err(&r.fk(&s.joints, "link_6").unwrap(), &tip);
    assert!(dp < 1e-9 && dr < 1e-9);
}

#[test]
fn stretched_elbow_is_flagged_and_merged() {
    let r = comau();
    let q = Joints::new(0.1, 0.2, -(0.13f64).atan2(0.64707), 0.3, 0.6, 0.2);
    let target = r.fk(&q, "tool0").unwrap();
    let all = r.ik("tool0", &target).unwrap();
    assert!(all.iter().all(|s| s.singularity.elbow));
    // Elbow up and down coincide: only one per shoulder and wrist branch.
    assert!(all.len() <= 4);
    assert!(all.iter().any(|s| same_mod_2pi(&s.joints, &q, 1e-6)));
}

#[test]
fn out_of_reach_poses_say_why() {
    let r = comau();
    let far = pose_from_xyz_rpy([2.0, 0.0, 1.0], [0.0, 0.0, 0.0]);
    match r.ik("tool0", &far) {
        Err(IkError::Unreachable(Unreachable::TooFar { by, .. })) => assert!(by > 0.3),
        other => panic!("{other:?}"),
    }
    assert!(!r.reachable("tool0", &far).unwrap());
    // Wrist centre on the J2 axis: closer than the folded arm in front; the back branch
    // reaches it with J1 = 180°, outside J1's range.
    let tip = Pose::from_parts(
        Translation3::new(0.15 + 0.095, 0.0, 0.45),
        Default::default(),
    );
    assert!(matches!(
        r.ik("link_6", &tip),
        Err(IkError::Unreachable(Unreachable::JointLimits { .. }))
    ));
    // Without the shoulder offset both branches are too close.
    let centred =
        Robot::from_urdf_str(&asset_text().replace(r#"xyz="0.150 0 0.450""#, r#"xyz="0 0 0.450""#))
            .unwrap();
    let tip = Pose::from_parts(Translation3::new(0.095, 0.0, 0.45), Default::default());
    match centred.ik("link_6", &tip) {
        Err(IkError::Unreachable(Unreachable::TooClose { by, .. })) => {
            assert!((by - 0.07).abs() < 1e-3)
        }
        other => panic!("{other:?}"),
    }
    // Reachable geometrically, but J1 is limited to [0.5, 0.6] rad.
    let text = asset_text().replace(
        r#"lower="-2.9670597283903604" upper="2.9670597283903604" effort="400""#,
        r#"lower="0.5" upper="0.6" effort="400""#,
    );
    let narrow = Robot::from_urdf_str(&text).unwrap();
    let target = narrow.fk(&calibration(), "tool0").unwrap();
    assert!(matches!(
        narrow.ik("tool0", &target),
        Err(IkError::Unreachable(Unreachable::JointLimits { solutions })) if solutions > 0
    ));
    // Non-finite input.
    let mut nan = far;
    nan.translation.x = f64::NAN;
    assert!(matches!(r.ik("tool0", &nan), Err(IkError::NonFinite(_))));
    let target = r.fk(&calibration(), "tool0").unwrap();
    assert!(matches!(
        r.ik_nearest("tool0", &target, &Joints::repeat(f64::NAN)),
        Err(IkError::NonFinite(_))
    ));
    assert!(matches!(r.ik("nope", &target), Err(IkError::Frame(_))));
    assert!(matches!(
        r.ik("link_2", &target),
        Err(IkError::NotOnTip { .. })
    ));
}

#[test]
fn sensor_frame_reachability() {
    let r = comau();
    // The depth camera 0.3 m above a table point, looking straight down: reachable.
    let look_down = |x: f64, y: f64, z: f64| {
        Pose::from_parts(
            Translation3::new(x, y, z),
            UnitQuaternion::from_euler_angles(PI, 0.0, 0.0),
        )
    };
    let above_table = look_down(0.8, 0.1, 0.45);
    assert!(r.reachable("dinast", &above_table).unwrap());
    for s in r.ik("dinast", &above_table).unwrap() {
        let cam = r.fk(&s.joints, "dinast").unwrap();
        assert!((cam.rotation * Vector3::z() + Vector3::z()).norm() < 1e-9);
    }
    // Beyond the reach of the arm plus the bracket.
    assert!(!r.reachable("dinast", &look_down(1.8, 0.0, 0.45)).unwrap());
    // The LMS400 pose differs from the Dinast pose by the bracket offset, so the same pose
    // for the two frames needs different joints.
    let a = r
        .ik_nearest("dinast", &above_table, &calibration())
        .unwrap();
    let b = r
        .ik_nearest("lms400", &above_table, &calibration())
        .unwrap();
    assert!((a.joints - b.joints).norm() > 1e-3);
}

#[test]
fn a_mounted_base_is_folded_into_the_chain() {
    // The same arm on a pedestal: a `world` root with a fixed, yawed and raised base.
    let mount = r#"<link name="world"/><joint name="world-base" type="fixed">
        <origin xyz="0.3 -0.2 0.25" rpy="0 0 0.4"/><parent link="world"/>
        <child link="base_link"/></joint>"#;
    let text = asset_text().replacen(
        "<material name=\"comau_blue\">",
        &format!("{mount}<material name=\"comau_blue\">"),
        1,
    );
    let r = Robot::from_urdf_str(&text).unwrap();
    assert_eq!(r.base_frame(), "world");
    assert_eq!(r.body_of("base_link").unwrap(), 0);
    let offset = pose_from_xyz_rpy([0.3, -0.2, 0.25], [0.0, 0.0, 0.4]);
    let q = Joints::new(0.5, 0.1, -1.1, -0.6, 0.9, 0.4);
    let (dp, dr) = pose_err(
        &r.fk(&q, "dinast").unwrap(),
        &(offset * comau().fk(&q, "dinast").unwrap()),
    );
    assert!(dp < 1e-12 && dr < 1e-12);
    let p = r.ik_parameters().unwrap();
    // d1 is measured from the root origin: pedestal 0.25 + shoulder 0.45.
    assert!((p.d1 - 0.70).abs() < 1e-12 && (p.a1 - 0.15).abs() < 1e-12);
    let target = r.fk(&q, "dinast").unwrap();
    let nearest = r.ik_nearest("dinast", &target, &Joints::zeros()).unwrap();
    let (dp, dr) = pose_err(&r.fk(&nearest.joints, "dinast").unwrap(), &target);
    assert!(dp < 1e-9 && dr < 1e-9);
    assert!(
        r.ik("dinast", &target)
            .unwrap()
            .iter()
            .any(|s| same_mod_2pi(&s.joints, &q, 1e-9))
    );
}

#[test]
fn rounded_urdf_angles_are_polished_to_exact_solutions() {
    // π/2 written as 1.5708 (a common rounding) breaks the exact structure by 4e-6 rad.
    let text = asset_text().replace("1.5707963267948966", "1.5708");
    let r = Robot::from_urdf_str(&text).unwrap();
    assert!(r.ik_parameters().is_ok());
    let q = Joints::new(-0.4, 0.5, -1.0, 1.0, -0.7, 2.0);
    let target = r.fk(&q, "dinast").unwrap();
    let all = r.ik("dinast", &target).unwrap();
    for s in &all {
        let (dp, dr) = pose_err(&r.fk(&s.joints, "dinast").unwrap(), &target);
        assert!(dp < 1e-9 && dr < 1e-9);
    }
    assert!(all.iter().any(|s| same_mod_2pi(&s.joints, &q, 1e-7)));
}

// ---------------------------------------------------------------- malformed URDF

fn joint(name: &str, kind: &str, parent: &str, child: &str, extra: &str) -> String {
    format!(
        r#"<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>{extra}</joint>"#
    )
}

const LIMIT: &str = r#"<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/>"#;

/// A six-joint chain a..g with every joint revolute about z (not ortho-parallel).
fn chain_urdf(modify: impl Fn(usize) -> Option<String>) -> String {
    let links: String = "abcdefg"
        .chars()
        .map(|c| format!(r#"<link name="{c}"/>"#))
        .collect();
    let joints: String = (0..6)
        .map(|i| {
            modify(i).unwrap_or_else(|| {
                let p = (b'a' + i as u8) as char;
                let c = (b'b' + i as u8) as char;
                joint(
                    &format!("j{i}"),
                    "revolute",
                    &p.to_string(),
                    &c.to_string(),
                    LIMIT,
                )
            })
        })
        .collect();
    format!(r#"<robot name="t">{links}{joints}</robot>"#)
}

#[test]
fn malformed_urdf_gives_typed_errors() {
    let e = Robot::from_urdf_str("<robot name='x'><link").unwrap_err();
    assert!(matches!(e, UrdfError::Parse { .. }), "{e}");

    let e = Robot::from_urdf_file("/nonexistent/arm.urdf").unwrap_err();
    assert!(matches!(e, UrdfError::Read { .. }));
    assert!(e.to_string().contains("/nonexistent/arm.urdf"));

    let e = Robot::from_urdf_str(&chain_urdf(|i| {
        (i == 2).then(|| joint("j2", "revolute", "c", "zz", LIMIT))
    }))
    .unwrap_err();
    assert!(
        matches!(&e, UrdfError::MissingLink { link, role: "child", .. } if link == "zz"),
        "{e}"
    );

    let e = Robot::from_urdf_str(&chain_urdf(|i| {
        (i == 3).then(|| joint("j3", "revolute", "d", "e", r#"<axis xyz="0 0 1"/>"#))
    }))
    .unwrap_err();
    assert!(
        matches!(&e, UrdfError::MissingLimits { joint, .. } if joint == "j3"),
        "{e}"
    );

    let e = Robot::from_urdf_str(&chain_urdf(|i| {
        (i == 1).then(|| joint("j1", "prismatic", "b", "c", LIMIT))
    }))
    .unwrap_err();
    assert!(
        matches!(&e, UrdfError::UnsupportedJointType { kind, .. } if kind == "prismatic"),
        "{e}"
    );

    let e = Robot::from_urdf_str(&chain_urdf(|i| {
        (i == 1).then(|| joint("j1", "continuous", "b", "c", LIMIT))
    }))
    .unwrap_err();
    assert!(matches!(e, UrdfError::UnsupportedJointType { .. }), "{e}");

    // Joint 5 hangs off link c instead of f: a branch.
    let e = Robot::from_urdf_str(&chain_urdf(|i| {
        (i == 5).then(|| joint("j5", "revolute", "c", "g", LIMIT))
    }))
    .unwrap_err();
    assert!(matches!(e, UrdfError::NotSerialChain { .. }), "{e}");

    // Link b with two parents.
    let e = Robot::from_urdf_str(&chain_urdf(|i| {
        (i == 1).then(|| joint("j1", "revolute", "c", "b", LIMIT))
    }))
    .unwrap_err();
    assert!(matches!(e, UrdfError::NotSerialChain { .. }), "{e}");

    // Only five revolute joints.
    let e = Robot::from_urdf_str(&chain_urdf(|i| {
        (i == 5).then(|| joint("j5", "fixed", "f", "g", ""))
    }))
    .unwrap_err();
    assert!(matches!(e, UrdfError::JointCount { found: 5, .. }), "{e}");

    let e = Robot::from_urdf_str(&chain_urdf(|i| {
        (i == 0).then(|| {
            joint(
                "j0",
                "revolute",
                "a",
                "b",
                r#"<axis xyz="0 0 0"/><limit lower="-1" upper="1" velocity="1"/>"#,
            )
        })
    }))
    .unwrap_err();
    assert!(matches!(e, UrdfError::ZeroAxis { .. }), "{e}");

    let e = Robot::from_urdf_str(&chain_urdf(|i| {
        (i == 0).then(|| {
            joint(
                "j0",
                "revolute",
                "a",
                "b",
                r#"<axis xyz="0 0 1"/><limit lower="1" upper="-1" velocity="1"/>"#,
            )
        })
    }))
    .unwrap_err();
    assert!(matches!(e, UrdfError::InvalidLimits { .. }), "{e}");

    let e = Robot::from_urdf_str(&asset_text().replace(
        r#"<box size="0.16 0.10 0.10"/>"#,
        r#"<box size="0.16 -0.10 0.10"/>"#,
    ))
    .unwrap_err();
    assert!(
        matches!(&e, UrdfError::InvalidGeometry { link, .. } if link == "lms400"),
        "{e}"
    );

    let e = Robot::from_urdf_str(&asset_text().replace(
        r#"<link name="tool0"/>"#,
        r#"<link name="tool0"/><link name="tool0"/>"#,
    ))
    .unwrap_err();
    assert!(
        matches!(e, UrdfError::Duplicate { kind: "link", .. }),
        "{e}"
    );
}

#[test]
fn a_chain_outside_the_class_still_has_fk() {
    // Six parallel z axes: loads, FK works, IK says why it does not apply.
    let r = Robot::from_urdf_str(&chain_urdf(|_| None)).unwrap();
    let q = Joints::repeat(0.1);
    assert!(r.fk(&q, "g").is_ok());
    assert!(matches!(
        r.ik_parameters(),
        Err(IkStructureError::ShoulderNotPerpendicular { .. })
    ));
    let target = r.fk(&q, "g").unwrap();
    assert!(matches!(r.ik("g", &target), Err(IkError::Unsupported(_))));
}
