//! The C4G client against its emulator on loopback, backed by a simple arm: joints, paths,
//! joint mapping, and every injected fault ending in a clear error without a hang.
#![cfg(feature = "comau")]

use nbv_core::kinematics::{Joints, Robot};
use nbv_core::rig::{Arm, JointPath, Motion, RigError, TimedJoints};
use nbv_hw::comau::{C4gArm, C4gConfig, C4gEmulator, C4gEmulatorStats, C4gFaults};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;
use std::thread::JoinHandle;
use std::time::Duration;

/// Moves in straight joint-space lines at 1 rad/s × speed fraction, sampled at 50 Hz;
/// refuses any joint beyond ±3 rad.
struct LinearArm {
    q: Joints,
    clock: f64,
    fractions: Vec<f64>,
}

impl Arm for LinearArm {
    fn joints(&mut self) -> Result<Joints, RigError> {
        Ok(self.q)
    }

    fn execute(&mut self, path: &JointPath) -> Result<Motion, RigError> {
        self.fractions.push(path.speed_fraction);
        let mut samples = vec![TimedJoints {
            time: self.clock,
            joints: self.q,
        }];
        for target in &path.waypoints[1..] {
            if let Some(joint) = target.iter().position(|v| v.abs() > 3.0) {
                return Err(RigError::JointLimit {
                    joint,
                    value_deg: target[joint].to_degrees(),
                });
            }
            if target[1] > 2.5 {
                return Err(RigError::Collision {
                    link: "link_3".into(),
                    with: "back wall".into(),
                    time: self.clock + 0.25,
                });
            }
            let start = self.q;
            let duration = (target - start).amax() / path.speed_fraction;
            let steps = (duration * 50.0).ceil().max(1.0) as usize;
            for k in 1..=steps {
                let s = k as f64 / steps as f64;
                self.q = start + (target - start) * s;
                samples.push(TimedJoints {
                    time: self.clock + duration * s,
                    joints: self.q,
                });
            }
            self.clock += duration;
        }
        Ok(Motion { samples })
    }
}

struct Harness {
    address: String,
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<(C4gEmulatorStats, Vec<f64>)>>,
}

impl Harness {
    fn start(q: Joints, faults: C4gFaults) -> Self {
        Self::start_with(q, faults, None)
    }

    fn start_with(q: Joints, faults: C4gFaults, kinematics: Option<Robot>) -> Self {
        let stop = Arc::new(AtomicBool::new(false));
        let (tx, rx) = mpsc::channel();
        let flag = stop.clone();
        let thread = std::thread::spawn(move || {
            let mut emulator = C4gEmulator::bind("127.0.0.1:0").unwrap();
            if let Some(robot) = kinematics {
                emulator = emulator.with_kinematics(robot, "tool0");
            }
            emulator.set_faults(faults);
            tx.send(emulator.local_addr().unwrap().to_string()).unwrap();
            let mut arm = LinearArm {
                q,
                clock: 10.0,
                fractions: Vec::new(),
            };
            while !flag.load(Ordering::Relaxed) {
                if !emulator.poll(&mut arm) {
                    std::thread::sleep(Duration::from_millis(1));
                }
            }
            (emulator.stats().clone(), arm.fractions)
        });
        let address = rx.recv_timeout(Duration::from_secs(10)).unwrap();
        Self {
            address,
            stop,
            thread: Some(thread),
        }
    }

    fn config(&self, timeout_s: f64) -> C4gConfig {
        C4gConfig {
            timeout_s,
            ..C4gConfig::new(self.address.clone())
        }
    }

    fn finish(mut self) -> (C4gEmulatorStats, Vec<f64>) {
        self.stop.store(true, Ordering::Relaxed);
        self.thread.take().unwrap().join().unwrap()
    }
}

fn q(values: [f64; 6]) -> Joints {
    Joints::from_row_slice(&values)
}

#[test]
fn joints_and_a_path_cross_the_wire() {
    let start = q([0.1, -0.2, -1.5, 0.3, 0.4, -0.5]);
    let h = Harness::start(start, C4gFaults::default());
    let mut arm = C4gArm::connect(h.config(2.0)).unwrap();
    let reported = arm.joints().unwrap();
    assert!((reported - start).amax() < 1e-5, "{reported} vs {start}");

    let mid = q([0.3, -0.2, -1.4, 0.3, 0.4, -0.5]);
    let end = q([0.3, 0.1, -1.4, 0.0, 0.4, -0.5]);
    let motion = arm
        .execute(&JointPath {
            waypoints: vec![start, mid, end],
            speed_fraction: 0.25,
        })
        .unwrap();
    // 0.2 rad then 0.3 rad at 0.25 rad/s: 0.8 s + 1.2 s of 50 Hz samples (±1 per move
    // for rounding), each move's start sample, and the first reading.
    let n = motion.samples.len();
    assert!((1 + 2 + 100..=1 + 2 + 102).contains(&n), "{n} samples");
    assert!(motion.samples.windows(2).all(|w| w[1].time >= w[0].time));
    let last = motion.samples.last().unwrap();
    assert!((last.joints - end).amax() < 1e-5);
    assert!((last.time - (10.0 + 2.0)).abs() < 1e-3, "{}", last.time);
    let halfway = motion.joints_at(10.4).unwrap();
    assert!((halfway[0] - 0.2).abs() < 1e-3, "{halfway}");
    drop(arm);
    let (stats, fractions) = h.finish();
    assert_eq!(stats.motions, 2);
    assert_eq!(fractions, vec![0.25, 0.25]);
}

#[test]
fn the_controller_pose_is_the_flange_by_forward_kinematics() {
    let urdf = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../assets/urdf/comau_smart_six.urdf"
    );
    let robot = Robot::from_urdf_file(urdf).unwrap();
    let at = q([0.3, 0.2, -1.3, 0.4, 0.7, -0.2]);
    let expected = robot.fk(&at, "tool0").unwrap();
    let h = Harness::start_with(at, C4gFaults::default(), Some(robot));
    let mut arm = C4gArm::connect(h.config(2.0)).unwrap();
    let pose = arm.reported_pose().unwrap();
    assert!((pose.translation.vector - expected.translation.vector).norm() < 1e-6);
    assert!(pose.rotation.angle_to(&expected.rotation) < 1e-5);
    drop(arm);
    // Without kinematics the emulator refuses, as a clear error.
    let h2 = Harness::start(at, C4gFaults::default());
    let mut arm = C4gArm::connect(h2.config(2.0)).unwrap();
    let err = arm.reported_pose().unwrap_err();
    assert!(err.to_string().contains("with_kinematics"), "{err}");
    drop(arm);
    h.finish();
    h2.finish();
}

#[test]
fn joint_signs_and_offsets_map_the_model_onto_the_controller() {
    let controller = q([0.5, 0.0, -1.0, 0.0, 0.2, 0.0]);
    let h = Harness::start(controller, C4gFaults::default());
    let mut config = h.config(2.0);
    config.joint_sign[0] = -1.0;
    config.joint_offset_deg[2] = -90.0;
    let mut arm = C4gArm::connect(config).unwrap();
    let model = arm.joints().unwrap();
    assert!((model[0] + 0.5).abs() < 1e-6);
    assert!((model[2] - (-1.0 + std::f64::consts::FRAC_PI_2)).abs() < 1e-6);
    // A move in model joints lands on the mapped controller joints.
    let mut target = model;
    target[0] = -0.4;
    let motion = arm
        .execute(&JointPath {
            waypoints: vec![model, target],
            speed_fraction: 1.0,
        })
        .unwrap();
    assert!((motion.samples.last().unwrap().joints[0] + 0.4).abs() < 1e-6);
    drop(arm);
    h.finish();
}

#[test]
fn a_target_beyond_the_strokes_is_refused_as_an_invalid_path() {
    let start = Joints::zeros();
    let h = Harness::start(start, C4gFaults::default());
    let mut arm = C4gArm::connect(h.config(2.0)).unwrap();
    let err = arm
        .execute(&JointPath {
            waypoints: vec![start, q([3.1, 0.0, 0.0, 0.0, 0.0, 0.0])],
            speed_fraction: 0.5,
        })
        .unwrap_err();
    assert!(
        matches!(&err, RigError::InvalidPath(d) if d.contains("joint 1")),
        "{err}"
    );
    // The session goes on.
    assert!(arm.joints().unwrap().amax() < 1e-9);
    drop(arm);
    h.finish();
}

#[test]
fn a_collision_crosses_the_wire_as_a_collision() {
    let start = Joints::zeros();
    let h = Harness::start(start, C4gFaults::default());
    let mut arm = C4gArm::connect(h.config(2.0)).unwrap();
    let err = arm
        .execute(&JointPath {
            waypoints: vec![start, q([0.0, 2.6, 0.0, 0.0, 0.0, 0.0])],
            speed_fraction: 0.5,
        })
        .unwrap_err();
    match err {
        RigError::Collision { link, with, time } => {
            assert_eq!(link, "link_3");
            assert_eq!(with, "back wall");
            assert!((time - 10.25).abs() < 1e-9, "{time}");
        }
        other => panic!("expected a collision, got {other}"),
    }
    drop(arm);
    h.finish();
}

#[test]
fn a_connection_lost_mid_motion_is_reported_and_the_next_call_reconnects() {
    let start = Joints::zeros();
    let faults = C4gFaults {
        disconnect_after_samples: Some(5),
        ..C4gFaults::default()
    };
    let h = Harness::start(start, faults);
    let mut arm = C4gArm::connect(h.config(2.0)).unwrap();
    let err = arm
        .execute(&JointPath {
            waypoints: vec![start, q([1.0, 0.0, 0.0, 0.0, 0.0, 0.0])],
            speed_fraction: 1.0,
        })
        .unwrap_err();
    match &err {
        RigError::Disconnected { device, detail } => {
            assert_eq!(device, "c4g");
            assert!(detail.contains("during a motion"), "{detail}");
        }
        other => panic!("expected a disconnection, got {other}"),
    }
    // Reconnects; the arm is wherever the controller left it.
    let now = arm.joints().unwrap();
    assert!((now[0] - 1.0).abs() < 1e-6);
    drop(arm);
    let (stats, _) = h.finish();
    assert_eq!(stats.connections, 2);
    assert_eq!(stats.stops, 1);
}

#[test]
fn a_silent_controller_times_out_during_a_motion() {
    let start = Joints::zeros();
    let faults = C4gFaults {
        silent_after_samples: Some(3),
        ..C4gFaults::default()
    };
    let h = Harness::start(start, faults);
    let mut arm = C4gArm::connect(h.config(0.2)).unwrap();
    let err = arm
        .execute(&JointPath {
            waypoints: vec![start, q([0.5, 0.0, 0.0, 0.0, 0.0, 0.0])],
            speed_fraction: 1.0,
        })
        .unwrap_err();
    assert!(
        matches!(&err, RigError::Timeout { device, seconds } if device == "c4g" && (*seconds - 0.2).abs() < 1e-9),
        "{err}"
    );
    drop(arm);
    h.finish();
}

#[test]
fn garbage_is_a_protocol_error_and_the_session_recovers() {
    let h = Harness::start(
        Joints::zeros(),
        C4gFaults {
            garbage_reply: true,
            ..C4gFaults::default()
        },
    );
    // The greeting itself gets the garbage: connecting fails cleanly, then succeeds.
    let err = C4gArm::connect(C4gConfig {
        connect_attempts: 1,
        ..h.config(1.0)
    })
    .unwrap_err();
    assert!(
        matches!(&err, RigError::Protocol { detail, .. } if detail.contains("garbage")),
        "{err}"
    );
    let mut arm = C4gArm::connect(h.config(1.0)).unwrap();
    assert!(arm.joints().unwrap().amax() < 1e-9);
    drop(arm);
    h.finish();
}

#[test]
fn a_slow_controller_times_out() {
    let h = Harness::start(
        Joints::zeros(),
        C4gFaults {
            reply_delay: Some(Duration::from_millis(600)),
            ..C4gFaults::default()
        },
    );
    let err = C4gArm::connect(C4gConfig {
        connect_attempts: 1,
        ..h.config(0.1)
    })
    .unwrap_err();
    assert!(matches!(err, RigError::Timeout { .. }), "{err}");
    h.finish();
}

#[test]
fn nobody_listening_is_a_clear_disconnection() {
    let port = {
        let l = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
        l.local_addr().unwrap().port()
    };
    let err = C4gArm::connect(C4gConfig {
        connect_attempts: 2,
        ..C4gConfig::new(format!("127.0.0.1:{port}"))
    })
    .unwrap_err();
    assert!(
        matches!(&err, RigError::Disconnected { detail, .. } if detail.contains("connecting to")),
        "{err}"
    );
    let err = C4gArm::connect(C4gConfig::new("no-such-host.invalid:1")).unwrap_err();
    assert!(matches!(err, RigError::Disconnected { .. }), "{err}");
}

#[test]
fn bad_paths_never_reach_the_controller() {
    let h = Harness::start(Joints::zeros(), C4gFaults::default());
    let mut arm = C4gArm::connect(h.config(1.0)).unwrap();
    for (path, what) in [
        (
            JointPath {
                waypoints: vec![],
                speed_fraction: 0.5,
            },
            "no waypoint",
        ),
        (
            JointPath {
                waypoints: vec![Joints::zeros()],
                speed_fraction: 0.0,
            },
            "speed fraction",
        ),
        (
            JointPath {
                waypoints: vec![Joints::zeros(), q([f64::NAN, 0.0, 0.0, 0.0, 0.0, 0.0])],
                speed_fraction: 0.5,
            },
            "not finite",
        ),
    ] {
        let err = arm.execute(&path).unwrap_err();
        assert!(
            matches!(&err, RigError::InvalidPath(d) if d.contains(what)),
            "{err}"
        );
    }
    drop(arm);
    let (stats, _) = h.finish();
    assert_eq!(stats.motions, 0);
}
