//! The C4G client against its emulator on loopback, backed by a simple arm: joints, paths,
//! joint mapping, and every injected fault ending in a clear error without a hang.
#![cfg(feature = "comau")]

use nbv_core::kinematics::{Joints, Robot};
use nbv_core::rig::{Arm, JointPath, Motion, RigError, TimedJoints};
use nbv_hw::comau::{C4gArm, C4gConfig, C4gEmulator, C4gEmulatorStats, C4gFaults};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

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

/// Safety net of every wait whose outcome is not a timeout: generous, so that no test
/// depends on how fast this machine is; a test that hangs fails after it.
const SAFETY_S: f64 = 60.0;

struct Harness {
    address: String,
    stop: Arc<AtomicBool>,
    stats: Arc<Mutex<C4gEmulatorStats>>,
    thread: Option<JoinHandle<(C4gEmulatorStats, Vec<f64>)>>,
}

impl Harness {
    fn start(q: Joints, faults: C4gFaults) -> Self {
        Self::start_with(q, faults, None)
    }

    fn start_with(q: Joints, faults: C4gFaults, kinematics: Option<Robot>) -> Self {
        let stop = Arc::new(AtomicBool::new(false));
        let stats = Arc::new(Mutex::new(C4gEmulatorStats::default()));
        let (flag, shared) = (stop.clone(), stats.clone());
        let mut emulator = C4gEmulator::bind("127.0.0.1:0").unwrap();
        if let Some(robot) = kinematics {
            emulator = emulator.with_kinematics(robot, "tool0");
        }
        emulator.set_faults(faults);
        let address = emulator.local_addr().unwrap().to_string();
        let thread = std::thread::spawn(move || {
            let mut arm = LinearArm {
                q,
                clock: 10.0,
                fractions: Vec::new(),
            };
            while !flag.load(Ordering::SeqCst) {
                let busy = emulator.poll(&mut arm);
                *shared.lock().unwrap() = emulator.stats().clone();
                if !busy {
                    std::thread::sleep(Duration::from_millis(1));
                }
            }
            (emulator.stats().clone(), arm.fractions)
        });
        Self {
            address,
            stop,
            stats,
            thread: Some(thread),
        }
    }

    fn config(&self, timeout_s: f64) -> C4gConfig {
        C4gConfig {
            timeout_s,
            ..C4gConfig::new(self.address.clone())
        }
    }

    /// Waits until the emulator's stats satisfy `condition` (failing after [`SAFETY_S`]).
    fn wait_for(&self, what: &str, condition: impl Fn(&C4gEmulatorStats) -> bool) {
        let deadline = Instant::now() + Duration::from_secs_f64(SAFETY_S);
        loop {
            let stats = self.stats.lock().unwrap().clone();
            if condition(&stats) {
                return;
            }
            assert!(
                Instant::now() < deadline,
                "never reached: {what} ({stats:?})"
            );
            std::thread::sleep(Duration::from_millis(1));
        }
    }

    /// Waits until `n` clients are gone, then stops the emulator.
    fn finish_after(self, n: usize) -> (C4gEmulatorStats, Vec<f64>) {
        self.wait_for("clients gone", |s| s.disconnections >= n);
        self.finish()
    }

    fn finish(mut self) -> (C4gEmulatorStats, Vec<f64>) {
        self.stop.store(true, Ordering::SeqCst);
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
    let mut arm = C4gArm::connect(h.config(SAFETY_S)).unwrap();
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
    let (stats, fractions) = h.finish_after(1);
    assert_eq!(stats.motions, 2);
    assert_eq!(stats.stops, 0);
    assert_eq!(fractions, vec![0.25, 0.25]);
}

#[test]
fn a_normal_bye_is_not_a_stop() {
    let start = Joints::zeros();
    let h = Harness::start(start, C4gFaults::default());
    let mut arm = C4gArm::connect(h.config(SAFETY_S)).unwrap();
    arm.execute(&JointPath {
        waypoints: vec![start, q([0.2, 0.0, 0.0, 0.0, 0.0, 0.0])],
        speed_fraction: 1.0,
    })
    .unwrap();
    drop(arm); // says BYE between motions
    let (stats, _) = h.finish_after(1);
    assert_eq!(
        stats,
        C4gEmulatorStats {
            connections: 1,
            // HELLO, OVR, JNT, MOVE, BYE: the BYE was read before the hang-up.
            commands: 5,
            motions: 1,
            stops: 0,
            stop_requests: 0,
            disconnections: 1,
        }
    );
}

#[test]
fn the_controller_pose_is_the_flange_by_forward_kinematics() {
    let robot = nbv_core::kinematics::comau_smart_six().unwrap();
    let at = q([0.3, 0.2, -1.3, 0.4, 0.7, -0.2]);
    let expected = robot.fk(&at, "tool0").unwrap();
    let h = Harness::start_with(at, C4gFaults::default(), Some(robot));
    let mut arm = C4gArm::connect(h.config(SAFETY_S)).unwrap();
    let pose = arm.reported_pose().unwrap();
    assert!((pose.translation.vector - expected.translation.vector).norm() < 1e-6);
    assert!(pose.rotation.angle_to(&expected.rotation) < 1e-5);
    drop(arm);
    // Without kinematics the emulator refuses, as a clear error.
    let h2 = Harness::start(at, C4gFaults::default());
    let mut arm = C4gArm::connect(h2.config(SAFETY_S)).unwrap();
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
    let mut config = h.config(SAFETY_S);
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
    let mut arm = C4gArm::connect(h.config(SAFETY_S)).unwrap();
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
    let mut arm = C4gArm::connect(h.config(SAFETY_S)).unwrap();
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
fn the_server_answers_bye_and_hangs_up_without_a_stop() {
    // A raw client that waits for the hang-up itself, so the emulator always takes the
    // path of a BYE read and answered (not of a client that vanished first).
    use std::io::{BufRead, BufReader, Write};
    let h = Harness::start(Joints::zeros(), C4gFaults::default());
    let mut stream = std::net::TcpStream::connect(&h.address).unwrap();
    stream
        .set_read_timeout(Some(Duration::from_secs_f64(SAFETY_S)))
        .unwrap();
    let mut lines = BufReader::new(stream.try_clone().unwrap());
    let mut line = String::new();
    let mut exchange = |stream: &mut std::net::TcpStream, command: &str| -> Vec<String> {
        stream.write_all(command.as_bytes()).unwrap();
        let mut got = Vec::new();
        loop {
            line.clear();
            if lines.read_line(&mut line).unwrap() == 0 {
                got.push("<hang-up>".to_owned());
                return got;
            }
            got.push(line.trim_end().to_owned());
            if !(got.len() == 1 && command.starts_with("MOVE") || line.starts_with("S ")) {
                return got;
            }
        }
    };
    assert_eq!(exchange(&mut stream, "HELLO\n"), ["OK NBV-C4G 1"]);
    let motion = exchange(&mut stream, "MOVE 2.0 0 0 0 0 0\n");
    assert_eq!(motion[0], "OK");
    assert!(motion.last().unwrap().starts_with("DONE "), "{motion:?}");
    assert_eq!(exchange(&mut stream, "BYE\n"), ["OK"]);
    line.clear();
    assert_eq!(lines.read_line(&mut line).unwrap(), 0, "no hang-up: {line}");
    let (stats, _) = h.finish_after(1);
    assert_eq!(stats.motions, 1);
    assert_eq!(stats.stops, 0, "a BYE between motions is no stop");
}

#[test]
fn a_client_lost_during_a_motion_is_a_stop() {
    // The motion's samples are held an hour, so the client is certainly gone while the
    // motion is still streaming, however the threads are scheduled.
    use std::io::Write;
    let faults = C4gFaults {
        reply_delay: Some(Duration::from_secs(3600)),
        ..C4gFaults::default()
    };
    let h = Harness::start(Joints::zeros(), faults);
    let mut stream = std::net::TcpStream::connect(&h.address).unwrap();
    stream.write_all(b"MOVE 10 0 0 0 0 0\n").unwrap();
    drop(stream);
    let (stats, _) = h.finish_after(1);
    assert_eq!(stats.motions, 1);
    assert_eq!(
        stats.stops, 1,
        "the PDL2 server cancels the motion of a lost client"
    );
}

#[test]
fn a_connection_lost_mid_motion_is_reported_and_the_next_call_reconnects() {
    let start = Joints::zeros();
    let faults = C4gFaults {
        disconnect_after_samples: Some(5),
        ..C4gFaults::default()
    };
    let h = Harness::start(start, faults);
    let mut arm = C4gArm::connect(h.config(SAFETY_S)).unwrap();
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
    // Both sessions are over (the second one with BYE) before the counts are read.
    let (stats, _) = h.finish_after(2);
    assert_eq!(stats.connections, 2);
    assert_eq!(stats.disconnections, 2);
    // The motion cut by the fault is the one stop; the BYE that closed the second session
    // (HELLO, JNT, BYE: read whatever the timing) is none.
    assert_eq!(stats.stops, 1);
    assert_eq!(stats.commands, 4 + 3);
}

#[test]
fn a_silent_controller_times_out_during_a_motion() {
    let start = Joints::zeros();
    let faults = C4gFaults {
        silent_after_samples: Some(3),
        ..C4gFaults::default()
    };
    let h = Harness::start(start, faults);
    // Every reply up to the accepted MOVE has the safety net; only the gap between samples
    // is short, and it is a silence that never ends.
    let config = C4gConfig {
        sample_timeout_s: Some(0.2),
        ..h.config(SAFETY_S)
    };
    let mut arm = C4gArm::connect(config).unwrap();
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
    // The client sends STOP only when it times out waiting for samples, i.e. after the
    // server accepted the MOVE: the timeout happened during the motion.
    h.wait_for("the client's STOP", |s| s.stop_requests == 1);
    drop(arm);
    let (stats, _) = h.finish_after(1);
    assert_eq!(stats.motions, 1);
    assert_eq!(stats.stop_requests, 1);
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
        ..h.config(SAFETY_S)
    })
    .unwrap_err();
    assert!(
        matches!(&err, RigError::Protocol { detail, .. } if detail.contains("garbage")),
        "{err}"
    );
    let mut arm = C4gArm::connect(h.config(SAFETY_S)).unwrap();
    assert!(arm.joints().unwrap().amax() < 1e-9);
    drop(arm);
    h.finish();
}

#[test]
fn a_slow_controller_times_out() {
    let h = Harness::start(
        Joints::zeros(),
        C4gFaults {
            // Held far beyond the client's timeout: the reply cannot come in time however
            // the threads are scheduled.
            reply_delay: Some(Duration::from_secs(3600)),
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
    // The port is held (listening on 127.0.0.1) for the whole test, so no other test's
    // emulator can take it; nobody listens at 127.0.0.2 on it: connecting is refused.
    let held = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let port = held.local_addr().unwrap().port();
    let err = C4gArm::connect(C4gConfig {
        connect_attempts: 2,
        timeout_s: SAFETY_S,
        ..C4gConfig::new(format!("127.0.0.2:{port}"))
    })
    .unwrap_err();
    assert!(
        matches!(&err, RigError::Disconnected { detail, .. } if detail.contains("connecting to")),
        "{err}"
    );
    let err = C4gArm::connect(C4gConfig::new("no-such-host.invalid:1")).unwrap_err();
    assert!(matches!(err, RigError::Disconnected { .. }), "{err}");
    drop(held);
}

#[test]
fn bad_paths_never_reach_the_controller() {
    let h = Harness::start(Joints::zeros(), C4gFaults::default());
    let mut arm = C4gArm::connect(h.config(SAFETY_S)).unwrap();
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
