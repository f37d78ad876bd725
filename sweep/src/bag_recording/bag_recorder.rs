//! [`BagRecorder`]: an episode's pipeline events into `OUT/bag/`, and [`BagTee`], which
//! hands each event to another observer first.

use super::camera::CameraModel;
use super::event_json::event_json;
use super::robot_tf::RobotTf;
use super::stamps::{STAMP_OFFSET_NS, header, stamp_ns};
use super::{markers, topics};
use crate::error::{Context, Result, SweepError};
use crate::report::ExploreReport;
use nbv_bag::BagWriter;
use nbv_bag::messages::{
    CameraInfo, Image, JointState, MarkerArray, PointCloud2, RosMessage, RosString, TFMessage,
};
use nbv_bag::point_cloud::cloud_from_points_f64;
use nbv_core::cloud::PointCloud;
use nbv_core::kinematics::{Joints, Robot};
use nbv_core::pipeline::{Exploration, ExploreEvent, ExploreObserver};
use nbv_core::rig::{Motion, ScanLine};
use nbv_scenes::Scene;
use std::path::{Path, PathBuf};

/// The bag's directory name in an episode's output directory (its file is
/// `bag/bag_0.mcap`).
pub const DIR_NAME: &str = "bag";
/// Rig seconds between two recorded robot poses of a motion (the last sample always is),
/// as in the Rerun recording.
const POSE_INTERVAL: f64 = 0.05;

/// Records one episode into a bag: create it before the exploration (it writes the static
/// frames, the URDF and the robot at home), let it observe the exploration
/// ([`observe`](Self::observe)), then [`finish`](Self::finish) it with the report (which
/// names the models' topics). Nothing is on disk under `bag/` until then.
///
/// ```no_run
/// # fn demo(scene: &nbv_scenes::Scene) -> nbv_sweep::Result<()> {
/// use nbv_sweep::bag_recording::BagRecorder;
/// use nbv_sweep::episode::Outputs;
/// let out = std::path::Path::new("run");
/// let mut bag = BagRecorder::create(out, scene)?;
/// let mut progress = nbv_core::pipeline::NoObserver;
/// let (config, exploration) = nbv_sweep::episode::explore_in_twin(
///     scene,
///     nbv_core::pipeline::ExploreMode::Hybrid,
///     &mut bag.observe(&mut progress),
/// )?;
/// let report = nbv_sweep::episode::finish_episode(scene, &config, &exploration, out, false, None, Outputs::All)?;
/// let dir = bag.finish(&exploration, &report)?;
/// assert!(dir.ends_with("bag"));
/// # Ok(()) }
/// ```
pub struct BagRecorder {
    bag: BagWriter,
    /// `out/bag`.
    dir: PathBuf,
    robot: RobotTf,
    camera: CameraModel,
    /// The rig's clock as last reported (seconds).
    now: f64,
    /// The last robot sample written: its stamp and joints.
    last_sample: Option<(u64, Joints)>,
    /// The models as registered: object index, stamp, points (world frame); written at
    /// [`finish`](Self::finish) under the report's names.
    models: Vec<(usize, u64, PointCloud)>,
    /// The first writing error (events cannot return one).
    error: Option<SweepError>,
}

impl std::fmt::Debug for BagRecorder {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("BagRecorder")
            .field("bag", &self.bag)
            .field("now", &self.now)
            .finish_non_exhaustive()
    }
}

impl BagRecorder {
    /// Starts `out/bag/` (replaced at [`finish`](Self::finish) if it exists) with
    /// `/robot_description`, `/tf_static` and the robot at the scene's home configuration,
    /// all at rig time 0.
    pub fn create(out: &Path, scene: &Scene) -> Result<Self> {
        let dir = out.join(DIR_NAME);
        let mut bag = BagWriter::create_overwrite(&dir)
            .with_context(|| format!("creating {}", dir.display()))?;
        let urdf = std::fs::read_to_string(&scene.robot.urdf)
            .with_context(|| format!("reading {}", scene.robot.urdf.display()))?;
        let model = Robot::from_urdf_str(&urdf)
            .with_context(|| format!("reading {}", scene.robot.urdf.display()))?;
        let robot = RobotTf::new(scene, &urdf, model)?;
        register::<TFMessage>(&mut bag, topics::TF_STATIC, true)?;
        register::<RosString>(&mut bag, topics::ROBOT_DESCRIPTION, true)?;
        register::<TFMessage>(&mut bag, topics::TF, false)?;
        register::<JointState>(&mut bag, topics::JOINT_STATES, false)?;
        for topic in [topics::SWEEP_POINTS, topics::CAMERA_POINTS] {
            register::<PointCloud2>(&mut bag, topic, false)?;
        }
        register::<Image>(&mut bag, topics::CAMERA_DEPTH, false)?;
        register::<CameraInfo>(&mut bag, topics::CAMERA_INFO, false)?;
        for topic in [
            topics::GRID_OCCUPIED,
            topics::GRID_UNKNOWN,
            topics::CANDIDATES,
        ] {
            register::<MarkerArray>(&mut bag, topic, false)?;
        }
        register::<RosString>(&mut bag, topics::EVENTS, false)?;
        let mut recorder = Self {
            bag,
            dir,
            camera: CameraModel::new(&scene.sensors.short_range.spec()),
            robot,
            now: 0.0,
            last_sample: None,
            models: Vec::new(),
            error: None,
        };
        let t0 = STAMP_OFFSET_NS;
        recorder.write(topics::ROBOT_DESCRIPTION, t0, &RosString { data: urdf })?;
        let statics = recorder.robot.static_transforms(t0);
        recorder.write(topics::TF_STATIC, t0, &statics)?;
        recorder.write_joints(&nbv_sim::world::home_configuration(scene), t0)?;
        Ok(recorder)
    }

    /// An observer that gives each event to `inner` (the progress bars), then records it.
    pub fn observe<'a>(&'a mut self, inner: &'a mut dyn ExploreObserver) -> BagTee<'a> {
        BagTee {
            recorder: self,
            inner,
        }
    }

    /// Writes each object's registered model on `/nbv/models/<name>` (the report's name of
    /// the object, made a topic name: [`topics::model_topic`]) at the time it was
    /// registered, then closes the bag and moves it to `out/bag`. Returns its path.
    pub fn finish(mut self, exploration: &Exploration, report: &ExploreReport) -> Result<PathBuf> {
        if let Some(e) = self.error.take() {
            return Err(e);
        }
        let mut used: Vec<String> = Vec::new();
        for (j, ns, model) in std::mem::take(&mut self.models) {
            let name = exploration
                .objects
                .iter()
                .zip(&report.objects)
                .find(|(o, _)| o.index == j)
                .map_or("", |(_, entry)| entry.name.as_str());
            let mut topic = topics::model_topic(name, j);
            if used.contains(&topic) {
                topic = format!("{topic}_{j}");
            }
            used.push(topic.clone());
            let cloud = cloud_from_points_f64(header(topics::WORLD, ns), &model.points);
            self.write(&topic, ns, &cloud)?;
        }
        let Self { bag, dir, .. } = self;
        bag.finish()
            .with_context(|| format!("writing {}", dir.display()))
    }

    fn write<M: RosMessage>(&mut self, topic: &str, ns: u64, msg: &M) -> Result<()> {
        self.bag
            .write(topic, ns, msg)
            .with_context(|| format!("writing {topic} into the bag"))
    }

    /// `/tf` (the moving joints) and `/joint_states` at `q`, stamp `ns`, unless that very
    /// sample was the last one written.
    fn write_joints(&mut self, q: &Joints, ns: u64) -> Result<()> {
        if self.last_sample == Some((ns, *q)) {
            return Ok(());
        }
        self.last_sample = Some((ns, *q));
        let tf = self.robot.moving_transforms(q, ns);
        self.write(topics::TF, ns, &tf)?;
        let joints = self.robot.joint_state(q, ns);
        self.write(topics::JOINT_STATES, ns, &joints)
    }

    fn record(&mut self, event: &ExploreEvent<'_>) -> Result<()> {
        match event {
            ExploreEvent::Moved { motion } => self.motion(motion)?,
            ExploreEvent::SweepCloud { lines, cloud } => self.sweep(lines, cloud)?,
            ExploreEvent::GridUpdated { grid } => {
                let ns = stamp_ns(self.now);
                let (occupied, unknown) = markers::grid(grid, ns);
                self.write(topics::GRID_OCCUPIED, ns, &occupied)?;
                self.write(topics::GRID_UNKNOWN, ns, &unknown)?;
            }
            ExploreEvent::Candidates { object, list, .. } => {
                let ns = stamp_ns(self.now);
                let frame = self.robot.robot().base_frame().to_owned();
                let msg = markers::candidates(*object, list, &frame, ns);
                self.write(topics::CANDIDATES, ns, &msg)?;
            }
            ExploreEvent::ViewTaken { view, frame, .. } => {
                let ns = stamp_ns(self.now);
                // The robot where the view was taken (already there when the motion's last
                // sample is this very one).
                self.write_joints(&view.joints, ns)?;
                let points = self.camera.points(&view.sensor_pose, &view.cloud, ns);
                self.write(topics::CAMERA_POINTS, ns, &points)?;
                let depth = self.camera.depth(&view.sensor_pose, frame, ns);
                self.write(topics::CAMERA_DEPTH, ns, &depth)?;
                let info = self.camera.info(ns);
                self.write(topics::CAMERA_INFO, ns, &info)?;
            }
            ExploreEvent::Registered {
                object,
                exploration,
            } => {
                let model = exploration.model()?;
                self.models.push((*object, stamp_ns(self.now), model));
            }
            _ => {}
        }
        let json = RosString {
            data: event_json(event).to_string(),
        };
        self.write(topics::EVENTS, stamp_ns(self.now), &json)
    }

    /// The motion's joint samples, one every [`POSE_INTERVAL`] and the last; the clock
    /// moves to its end.
    fn motion(&mut self, motion: &Motion) -> Result<()> {
        let mut last_written = f64::NEG_INFINITY;
        for (k, s) in motion.samples.iter().enumerate() {
            let is_last = k + 1 == motion.samples.len();
            if s.time - last_written < POSE_INTERVAL && !is_last {
                continue;
            }
            last_written = s.time;
            self.write_joints(&s.joints, stamp_ns(s.time))?;
        }
        if let Some(s) = motion.samples.last() {
            self.now = s.time;
        }
        Ok(())
    }

    /// `/nbv/sweep/points`: the whole sweep cloud (world frame) at the last line's time.
    fn sweep(&mut self, lines: &[ScanLine], cloud: &PointCloud) -> Result<()> {
        let t = lines.last().map_or(self.now, |l| l.time.max(self.now));
        let ns = stamp_ns(t);
        let msg = cloud_from_points_f64(header(topics::WORLD, ns), &cloud.points);
        self.write(topics::SWEEP_POINTS, ns, &msg)
    }
}

/// Registers `topic` as type `M`.
fn register<M: RosMessage>(bag: &mut BagWriter, topic: &str, latched: bool) -> Result<()> {
    bag.add_topic::<M>(topic, latched)
        .with_context(|| format!("adding {topic} to the bag"))
}

/// An observer that gives each event to another observer, then to a [`BagRecorder`]
/// ([`BagRecorder::observe`]).
pub struct BagTee<'a> {
    recorder: &'a mut BagRecorder,
    inner: &'a mut dyn ExploreObserver,
}

impl ExploreObserver for BagTee<'_> {
    fn event(&mut self, event: &ExploreEvent<'_>) {
        self.inner.event(event);
        if self.recorder.error.is_none()
            && let Err(e) = self.recorder.record(event)
        {
            self.recorder.error = Some(e);
        }
    }
}
