//! [`TwinState`]: the state the simulated arm, line scanner and depth camera share — the
//! true world, the rig clock, the reported joints, the scanner's stream and the record of
//! every acquisition's true sensor poses (for evaluation).

use super::joint_reach::JointReach;
use super::pose_errors::PoseErrors;
use super::timed_path::TimedPath;
use crate::sensors::{AcquisitionId, CameraModel, LaserModel, TrueFrame};
use crate::world::TwinWorld;
use nbv_core::kinematics::Joints;
use nbv_core::math::Pose;
use nbv_core::rig::{DepthFrame, JointPath, Motion, RigError, ScanLine};

/// Largest distance (m) any point of the robot's colliders moves between two collision
/// checks of an executed path.
pub const CHECK_STEP: f64 = 0.005;

/// Rate (Hz) of the joint samples the arm reports in a [`Motion`] (waypoint arrivals and
/// the end are always reported too, so interpolating the samples reproduces the path).
pub const MOTION_SAMPLE_RATE_HZ: f64 = 100.0;

/// Largest difference (rad, any joint) between a path's first waypoint and the arm's
/// configuration.
pub const START_TOLERANCE: f64 = 1e-6;

/// Which sensor made an acquisition.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SensorKind {
    /// The line scanner (one acquisition per start/stop stream).
    LineScanner,
    /// The depth camera (one acquisition per frame).
    DepthCamera,
}

/// The truth of one acquisition: which one, its view error, and the true world pose of the
/// sensor at each line (laser) or at the frame (camera).
#[derive(Debug, Clone, PartialEq)]
pub struct AcquisitionTruth {
    /// The sensor.
    pub sensor: SensorKind,
    /// The acquisition (its noise streams).
    pub id: AcquisitionId,
    /// The view error drawn for it (sensor frame).
    pub view_error: Pose,
    /// `(rig time, true sensor pose in the world)` per line or frame.
    pub poses: Vec<(f64, Pose)>,
}

/// Everything a simulated rig needs to know besides its world.
#[derive(Debug, Clone, PartialEq)]
pub struct RigConfig {
    /// The line scanner.
    pub laser: LaserModel,
    /// The depth camera.
    pub camera: CameraModel,
    /// The error model.
    pub errors: PoseErrors,
    /// The scene seed all noise derives from.
    pub seed: u64,
}

impl RigConfig {
    /// The configuration of a scene: its sensors, `[errors]` and seed.
    pub fn from_scene(scene: &nbv_scenes::Scene) -> Self {
        Self {
            laser: LaserModel::from_scene(&scene.sensors.mid_range),
            camera: CameraModel::from_scene(&scene.sensors.short_range),
            errors: PoseErrors::from_scene(&scene.errors),
            seed: scene.seed,
        }
    }
}

/// A scan stream between `start` and `stop`.
#[derive(Debug)]
struct LineStream {
    id: AcquisitionId,
    start: f64,
    next: u64,
    view_error: Pose,
    lines: Vec<ScanLine>,
    record: usize,
}

/// The shared state of a simulated rig. Read it through [`super::SimRig::state`] for
/// evaluation; the devices change it.
pub struct TwinState {
    world: TwinWorld,
    config: RigConfig,
    laser_frame: usize,
    camera_frame: usize,
    reach: JointReach,
    time: f64,
    q: Joints,
    acquisitions: u64,
    stream: Option<LineStream>,
    log: Vec<AcquisitionTruth>,
    /// The view error of the depth frames taken since the arm last moved: a burst at one
    /// standstill shares it (the arm, not the frame, carries the pose error).
    stand_error: Option<Pose>,
    /// The noise-free depth frame cast at this standstill (same lifetime as `stand_error`):
    /// the frames of a burst draw their noise from it instead of casting again.
    stand_frame: Option<TrueFrame>,
}

/// Why a rig could not be assembled.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
#[error("sensor frame `{frame}` is not a link of the robot model")]
pub struct UnknownSensorFrame {
    /// The frame named by a sensor spec.
    pub frame: String,
}

impl TwinState {
    /// A rig in `world`, the arm at the world's configuration taken as the *reported* one
    /// (the world is moved to the true configuration).
    pub(crate) fn new(mut world: TwinWorld, config: RigConfig) -> Result<Self, UnknownSensorFrame> {
        let index = |frame: &str| {
            world
                .robot()
                .frame_index(frame)
                .ok_or_else(|| UnknownSensorFrame {
                    frame: frame.to_owned(),
                })
        };
        let laser_frame = index(&config.laser.spec.frame)?;
        let camera_frame = index(&config.camera.spec.frame)?;
        let q = world.configuration();
        let reach = JointReach::of(&world);
        world.set_configuration(q + config.errors.joint_offset);
        Ok(Self {
            world,
            config,
            laser_frame,
            camera_frame,
            reach,
            time: 0.0,
            q,
            acquisitions: 0,
            stream: None,
            log: Vec::new(),
            stand_error: None,
            stand_frame: None,
        })
    }

    /// The true world, the robot at its true configuration.
    pub fn world(&self) -> &TwinWorld {
        &self.world
    }

    /// The rig's configuration.
    pub fn config(&self) -> &RigConfig {
        &self.config
    }

    /// Rig time (s).
    pub fn time(&self) -> f64 {
        self.time
    }

    /// The joints the arm reports.
    pub fn reported_joints(&self) -> Joints {
        self.q
    }

    /// The arm's true joints (reported + offset).
    pub fn true_joints(&self) -> Joints {
        self.q + self.config.errors.joint_offset
    }

    /// Every acquisition so far, in order.
    pub fn acquisitions(&self) -> &[AcquisitionTruth] {
        &self.log
    }

    /// The true world pose of the line scanner (`laser = true`) or of the depth camera at
    /// reported joints `q` with view error `view_error` (see [`PoseErrors`]).
    pub fn true_sensor_pose(&self, laser: bool, q: &Joints, view_error: &Pose) -> Pose {
        let (frame, mount) = if laser {
            (self.laser_frame, Pose::identity())
        } else {
            (self.camera_frame, self.config.errors.hand_eye)
        };
        let qt = q + self.config.errors.joint_offset;
        let link = self.world.robot().link_poses(&qt)[frame];
        self.world.base() * link * mount * view_error
    }

    fn next_acquisition(&mut self) -> AcquisitionId {
        let id = AcquisitionId {
            seed: self.config.seed,
            index: self.acquisitions,
        };
        self.acquisitions += 1;
        id
    }

    /// Casts every line of the open stream due up to rig time `until`, the arm at the
    /// reported joints `q_at(t)`. Leaves the world's robot wherever the last line put it.
    fn emit_lines(&mut self, until: f64, q_at: &dyn Fn(f64) -> Joints) {
        let Some(mut stream) = self.stream.take() else {
            return;
        };
        let rate = self.config.laser.spec.line_rate_hz;
        loop {
            let t = stream.start + stream.next as f64 / rate;
            if t > until + 1e-12 {
                break;
            }
            let q = q_at(t);
            let pose = self.true_sensor_pose(true, &q, &stream.view_error);
            self.world
                .set_configuration(q + self.config.errors.joint_offset);
            let line = self.config.laser.cast_line(
                &self.world,
                &pose,
                Some(self.laser_frame),
                t,
                stream.id,
                stream.next,
            );
            stream.lines.push(line);
            self.log[stream.record].poses.push((t, pose));
            stream.next += 1;
        }
        self.stream = Some(stream);
    }

    /// Moves the arm (reported joints) to `q` and the world to the matching true joints.
    fn settle(&mut self, q: Joints, time: f64) {
        self.q = q;
        self.time = time;
        self.world
            .set_configuration(q + self.config.errors.joint_offset);
    }

    /// The first contact at true configuration `qt`, if any.
    fn contact_at(&mut self, q: &Joints) -> Option<crate::world::Contact> {
        self.world
            .set_configuration(q + self.config.errors.joint_offset);
        if self.world.in_collision() {
            self.world.contacts().into_iter().next()
        } else {
            None
        }
    }

    /// Executes a path (see [`super::SimArm`]).
    pub(crate) fn execute(&mut self, path: &JointPath) -> Result<Motion, RigError> {
        let timed = TimedPath::new(path, self.world.robot().limits(), self.time)?;
        self.end_standstill();
        let gap = (timed.waypoints[0] - self.q).amax();
        if gap > START_TOLERANCE {
            return Err(RigError::InvalidPath(format!(
                "the path starts {:.4}° away from the arm's configuration",
                gap.to_degrees()
            )));
        }
        // Walk the path in steps no collider point moves more than CHECK_STEP.
        let mut last_free = (timed.start(), self.q);
        let mut contact = self.contact_at(&self.q.clone()).map(|c| (timed.start(), c));
        'segments: for k in 0..timed.waypoints.len().saturating_sub(1) {
            if contact.is_some() {
                break;
            }
            let (a, b) = (timed.waypoints[k], timed.waypoints[k + 1]);
            let (ta, tb) = (timed.times[k], timed.times[k + 1]);
            let n = (self.reach.displacement(&(b - a)) / CHECK_STEP)
                .ceil()
                .max(1.0) as usize;
            for i in 1..=n {
                let s = i as f64 / n as f64;
                let q = a + (b - a) * s;
                let t = ta + (tb - ta) * s;
                if let Some(c) = self.contact_at(&q) {
                    contact = Some((t, c));
                    break 'segments;
                }
                last_free = (t, q);
            }
        }
        let (t_end, q_end) = last_free;
        self.emit_lines(t_end, &|t| timed.at(t));
        self.settle(q_end, t_end);
        match contact {
            Some((time, c)) => Err(RigError::Collision {
                link: c.link,
                with: c.with.to_string(),
                time,
            }),
            None => Ok(Motion {
                samples: timed.samples(t_end, MOTION_SAMPLE_RATE_HZ),
            }),
        }
    }

    /// Places the arm at `q` without moving through the space between (refused, arm
    /// unmoved, if `q` is outside the limits or in contact).
    pub(crate) fn teleport(&mut self, q: Joints) -> Result<(), RigError> {
        self.end_standstill();
        let path = JointPath {
            waypoints: vec![q],
            speed_fraction: 1.0,
        };
        TimedPath::new(&path, self.world.robot().limits(), self.time)?;
        if let Some(c) = self.contact_at(&q) {
            let q0 = self.q;
            self.settle(q0, self.time);
            return Err(RigError::Collision {
                link: c.link,
                with: c.with.to_string(),
                time: self.time,
            });
        }
        self.settle(q, self.time);
        Ok(())
    }

    /// Opens a scan stream (one acquisition).
    pub(crate) fn start_stream(&mut self) -> Result<(), RigError> {
        if self.stream.is_some() {
            return Err(RigError::State {
                device: self.config.laser.spec.frame.clone(),
                detail: "already streaming".into(),
            });
        }
        let id = self.next_acquisition();
        let view_error = self.config.errors.view_error(id);
        self.log.push(AcquisitionTruth {
            sensor: SensorKind::LineScanner,
            id,
            view_error,
            poses: Vec::new(),
        });
        self.stream = Some(LineStream {
            id,
            start: self.time,
            next: 0,
            view_error,
            lines: Vec::new(),
            record: self.log.len() - 1,
        });
        // The line due at the start instant.
        let q = self.q;
        self.emit_lines(self.time, &|_| q);
        self.settle(q, self.time);
        Ok(())
    }

    /// Closes the stream and returns its lines.
    pub(crate) fn stop_stream(&mut self) -> Result<Vec<ScanLine>, RigError> {
        match self.stream.take() {
            Some(s) => Ok(s.lines),
            None => Err(RigError::State {
                device: self.config.laser.spec.frame.clone(),
                detail: "stop without start".into(),
            }),
        }
    }

    /// Forgets what was shared by the frames of the current standstill (view error, cast
    /// frame): called before every motion or teleport, successful or not.
    fn end_standstill(&mut self) {
        self.stand_error = None;
        self.stand_frame = None;
    }

    /// The noise-free frame cast since the arm last moved, if any (for tests and tools).
    pub fn standstill_frame(&self) -> Option<&TrueFrame> {
        self.stand_frame.as_ref()
    }

    /// Captures a depth frame at the current true pose; the clock advances one frame
    /// period. The rays are cast at the first frame of a standstill only; later frames
    /// draw their noise from that cast (see [`CameraModel`]).
    pub(crate) fn capture(&mut self) -> DepthFrame {
        let id = self.next_acquisition();
        let errors = &self.config.errors;
        let view_error = *self
            .stand_error
            .get_or_insert_with(|| errors.view_error(id));
        let q = self.q;
        let pose = self.true_sensor_pose(false, &q, &view_error);
        self.world
            .set_configuration(q + self.config.errors.joint_offset);
        let camera = &self.config.camera;
        let truth = match self.stand_frame.take() {
            // The arm has not moved: same pose, same world. (The pose check is a guard.)
            Some(cast) if cast.pose == pose => cast,
            _ => camera.cast(&self.world, &pose, Some(self.camera_frame)),
        };
        let frame = camera.draw(&truth, self.time, id);
        self.stand_frame = Some(truth);
        self.log.push(AcquisitionTruth {
            sensor: SensorKind::DepthCamera,
            id,
            view_error,
            poses: vec![(self.time, pose)],
        });
        let t = self.time + 1.0 / self.config.camera.frame_rate_hz;
        self.emit_lines(t, &|_| q);
        self.settle(q, t);
        frame
    }
}
