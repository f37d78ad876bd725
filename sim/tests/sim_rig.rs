//! The simulated rig through nbv-core's traits: device states, motions that collide or
//! leave the limits, lines streamed during motions, and reported vs true sensor poses
//! under the scene's error model.

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use nbv_core::kinematics::Joints;
use nbv_core::math::{Pose, pose_from_xyz_rpy};
use nbv_core::rig::{Arm, DepthCamera, JointPath, LineScanner, RigError, sensor_pose};
use nbv_sim::rig::{PoseErrors, RigConfig, SensorKind, SimRig};
use nbv_sim::world::TwinWorld;

fn scene() -> nbv_scenes::Scene {
    nbv_scenes::builtin::load("paper-env1").unwrap()
}

fn rig_with(errors: PoseErrors) -> SimRig {
    let scene = scene();
    let mut config = RigConfig::from_scene(&scene);
    config.errors = errors;
    config.laser.spec.resolution = 5f64.to_radians();
    SimRig::new(TwinWorld::from_scene(&scene).unwrap(), config).unwrap()
}

fn deg(q: [f64; 6]) -> Joints {
    Joints::from_iterator(q.iter().map(|d| d.to_radians()))
}

/// The camera looking straight down from `(x, y, z)`.
fn down(x: f64, y: f64, z: f64) -> Pose {
    Isometry3::from_parts(
        Translation3::new(x, y, z),
        UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::PI),
    )
}

fn joints_for(rig: &SimRig, view: &Pose) -> Joints {
    let state = rig.state();
    let robot = state.world().robot();
    let base_inv = state.world().base().inverse();
    robot
        .ik_nearest("dinast", &(base_inv * view), &state.reported_joints())
        .unwrap()
        .joints
}

#[test]
fn scanner_states_are_checked() {
    let mut rig = rig_with(PoseErrors::none());
    assert!(matches!(rig.scanner.stop(), Err(RigError::State { .. })));
    rig.scanner.start().unwrap();
    assert!(matches!(rig.scanner.start(), Err(RigError::State { .. })));
    // The line due at the start instant is cast at once.
    assert_eq!(rig.scanner.stop().unwrap().len(), 1);
}

#[test]
fn bad_paths_are_refused_and_the_arm_stays() {
    let mut rig = rig_with(PoseErrors::none());
    let home = rig.arm.joints().unwrap();
    let mut far = home;
    far[2] = 0.5; // J3 ≤ 0
    let err = rig.arm.execute(&JointPath {
        waypoints: vec![home, far],
        speed_fraction: 0.5,
    });
    assert!(matches!(err, Err(RigError::JointLimit { joint: 2, .. })));
    let mut elsewhere = home;
    elsewhere[0] = 0.1;
    let err = rig.arm.execute(&JointPath {
        waypoints: vec![elsewhere, home],
        speed_fraction: 0.5,
    });
    assert!(matches!(err, Err(RigError::InvalidPath(_))));
    let err = rig.arm.execute(&JointPath {
        waypoints: vec![home],
        speed_fraction: 0.0,
    });
    assert!(matches!(err, Err(RigError::InvalidPath(_))));
    assert_eq!(rig.arm.joints().unwrap(), home);
    assert_eq!(rig.state().time(), 0.0);
}

#[test]
fn a_path_into_the_scene_stops_at_the_last_free_configuration() {
    let mut rig = rig_with(PoseErrors::none());
    let home = rig.arm.joints().unwrap();
    // Reaching down and forward: the camera runs into the bottle.
    let into = deg([0.0, 40.0, -100.0, 0.0, 60.0, 0.0]);
    rig.scanner.start().unwrap();
    let err = rig
        .arm
        .execute(&JointPath {
            waypoints: vec![home, into],
            speed_fraction: 0.2,
        })
        .unwrap_err();
    let lines = rig.scanner.stop().unwrap();
    let RigError::Collision { link, with, time } = err else {
        panic!("{err:?}");
    };
    assert_eq!((link.as_str(), with.as_str()), ("dinast", "bottle-a"));
    assert!(time > 0.0);
    let q = rig.arm.joints().unwrap();
    assert_ne!(q, home);
    assert_ne!(q, into);
    let state = rig.state();
    assert!(state.time() < time && state.time() > time - 0.05);
    assert!(!state.world().in_collision());
    // Lines were streamed up to where the arm stopped, 190 per second.
    assert_eq!(lines.len(), (state.time() * 190.0).floor() as usize + 1);
}

#[test]
fn reported_and_true_poses_differ_by_the_error_model() {
    let scene = scene();
    let view = down(0.8, 0.1, 0.7);

    // Hand-eye only: the true camera pose is the nominal one times the hand-eye error,
    // exactly, whatever the view.
    let hand_eye = pose_from_xyz_rpy([0.004, -0.003, 0.002], [0.4f64.to_radians(), 0.0, 0.0]);
    let mut rig = rig_with(PoseErrors {
        hand_eye,
        ..PoseErrors::none()
    });
    for v in [view, down(0.7, -0.1, 0.6)] {
        let q = joints_for(&rig, &v);
        rig.arm.teleport(q).unwrap();
        rig.camera.capture().unwrap();
    }
    {
        let state = rig.state();
        let robot = state.world().robot();
        for acq in state.acquisitions() {
            assert_eq!(acq.sensor, SensorKind::DepthCamera);
            assert_eq!(acq.view_error, Pose::identity());
        }
        let q = state.reported_joints();
        let nominal = sensor_pose(robot, state.world().base(), &q, "dinast").unwrap();
        let truth = state.acquisitions()[1].poses[0].1;
        let diff = nominal.inverse() * truth;
        assert!((diff.translation.vector - hand_eye.translation.vector).norm() < 1e-12);
        assert!(diff.rotation.angle_to(&hand_eye.rotation) < 1e-12);
    }

    // The scene's full model: the true pose is off by millimetres and tenths of a degree;
    // the frames of one standstill share their view error, the next standstill draws
    // another, and all of it repeats with the seed.
    let full = PoseErrors::from_scene(&scene.errors);
    let run = || {
        let mut rig = rig_with(full.clone());
        let q = joints_for(&rig, &view);
        rig.arm.teleport(q).unwrap();
        rig.camera.capture().unwrap();
        rig.camera.capture().unwrap();
        rig.arm.teleport(q).unwrap();
        rig.camera.capture().unwrap();
        let state = rig.state();
        let robot = state.world().robot();
        let nominal = sensor_pose(
            robot,
            state.world().base(),
            &state.reported_joints(),
            "dinast",
        )
        .unwrap();
        let acq = state.acquisitions().to_vec();
        (nominal, acq)
    };
    let (nominal, acq) = run();
    assert_eq!(acq, run().1);
    assert_eq!(acq[0].view_error, acq[1].view_error);
    assert_ne!(acq[1].view_error, acq[2].view_error);
    for a in &acq {
        let truth = a.poses[0].1;
        let dt = (truth.translation.vector - nominal.translation.vector).norm();
        let da = truth.rotation.angle_to(&nominal.rotation).to_degrees();
        assert!(dt > 0.001 && dt < 0.03, "{dt}");
        assert!(da > 0.05 && da < 2.0, "{da}");
    }
    // The view error is what separates the two captures at the same joints.
    let (p0, p1) = (acq[0].poses[0].1, acq[1].poses[0].1);
    let expected = acq[0].view_error.inverse() * acq[1].view_error;
    let got = p0.inverse() * p1;
    assert!((got.translation.vector - expected.translation.vector).norm() < 1e-9);
}

#[test]
fn capture_advances_the_clock_by_a_frame() {
    let mut rig = rig_with(PoseErrors::none());
    let view = down(0.8, 0.0, 0.7);
    let q = joints_for(&rig, &view);
    rig.arm.teleport(q).unwrap();
    let frame = rig.camera.capture().unwrap();
    assert_eq!(frame.time, 0.0);
    let frame = rig.camera.capture().unwrap();
    assert!((frame.time - 1.0 / 30.0).abs() < 1e-12);
    assert!(frame.depth.iter().any(|d| d.is_finite()));
}

#[test]
fn teleport_into_a_collision_is_refused() {
    let mut rig = rig_with(PoseErrors::none());
    let home = rig.arm.joints().unwrap();
    let into = deg([0.0, 40.0, -100.0, 0.0, 60.0, 0.0]);
    assert!(matches!(
        rig.arm.teleport(into),
        Err(RigError::Collision { .. })
    ));
    assert_eq!(rig.arm.joints().unwrap(), home);
}
