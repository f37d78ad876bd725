//! [`SimRig`]: the simulated rig — a [`SimArm`], a [`SimLineScanner`] and a
//! [`SimDepthCamera`] implementing nbv-core's rig traits over one shared
//! [`TwinState`] (`Rc<RefCell<…>>`: the three devices are separate values, as on the real
//! rig, and the pipeline may hold them separately; they are not `Send`).
//!
//! - The arm is position-controlled: [`Arm::execute`] follows the path at `speed_fraction`
//!   of each joint's velocity limit with synchronised segments (see the timing law in
//!   `timed_path`), advancing the simulated clock. Every configuration along the path is
//!   checked against the *true* world (true joints = reported + offset) in steps that move
//!   no collider point more than [`CHECK_STEP`](super::CHECK_STEP); at the first contact
//!   it returns [`RigError::Collision`] and stays at the last configuration found free.
//!   Waypoints outside the joint limits are refused before moving. The reported
//!   [`Motion`] holds samples at [`MOTION_SAMPLE_RATE_HZ`](super::MOTION_SAMPLE_RATE_HZ)
//!   plus every waypoint arrival.
//! - The line scanner streams between `start` and `stop`: line `k` is due at
//!   `t_start + k / line_rate`, and every line due while the clock advances (arm motion,
//!   camera frames) is cast from the true sensor pose at its time.
//! - The depth camera captures at the current true pose; the clock advances one frame
//!   period. Its rays are cast once per standstill of the arm: the frames of a burst draw
//!   their own noise and dropouts from that cast (see [`crate::sensors::CameraModel`]).
//! - What the devices return becomes clouds as the pipeline sees them, through the reported
//!   joints and the nominal model: [`SimRig::sweep_cloud`], [`SimRig::frame_cloud`]
//!   ([`SimRig::camera_joints`] places the camera).
//!
//! ```no_run
//! use nbv_core::rig::{Arm, DepthCamera, JointPath, LineScanner};
//! let scene = nbv_scenes::builtin::load("paper-env1")?;
//! let mut rig = nbv_sim::rig::SimRig::from_scene(&scene)?;
//! let q0 = rig.arm.joints()?;
//! rig.scanner.start()?;
//! let motion = rig.arm.execute(&JointPath { waypoints: vec![q0], speed_fraction: 0.1 })?;
//! let lines = rig.scanner.stop()?;
//! let frame = rig.camera.capture()?;
//! assert_eq!(frame.width, 320);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use super::twin_state::{RigConfig, TwinState, UnknownSensorFrame};
use crate::world::{SceneWorldError, TwinWorld};
use nbv_core::cloud::PointCloud;
use nbv_core::kinematics::{IkError, Joints, Robot};
use nbv_core::math::Pose;
use nbv_core::perception::ObjectSegmentation;
use nbv_core::pipeline::{
    Exploration, ExploreConfig, ExploreObserver, PhaseOneReport, PipelineError, explore,
    run_phase_one,
};
use nbv_core::rig::{
    Arm, DepthCamera, DepthCameraSpec, DepthFrame, JointPath, LineScanner, LineScannerSpec, Motion,
    Rig, RigError, ScanLine, SensorCloudError, SweepData, depth_frame_to_cloud, lines_to_cloud,
    sensor_pose,
};
use std::cell::{Ref, RefCell};
use std::rc::Rc;

type Shared = Rc<RefCell<TwinState>>;

/// The simulated arm.
pub struct SimArm {
    state: Shared,
}

/// The simulated LMS400.
pub struct SimLineScanner {
    state: Shared,
    spec: LineScannerSpec,
}

/// The simulated Dinast camera.
pub struct SimDepthCamera {
    state: Shared,
    spec: DepthCameraSpec,
}

/// The three simulated devices and their shared state.
pub struct SimRig {
    /// The arm.
    pub arm: SimArm,
    /// The mid-range line scanner.
    pub scanner: SimLineScanner,
    /// The short-range depth camera.
    pub camera: SimDepthCamera,
    state: Shared,
}

/// Why a simulated rig could not be built from a scene.
#[derive(Debug, thiserror::Error)]
pub enum SimRigError {
    /// The twin world could not be built.
    #[error(transparent)]
    World(#[from] SceneWorldError),
    /// A sensor names a frame the robot does not have.
    #[error(transparent)]
    Frame(#[from] UnknownSensorFrame),
}

impl SimRig {
    /// A rig in `world`; the arm reports the world's current configuration.
    pub fn new(world: TwinWorld, config: RigConfig) -> Result<Self, UnknownSensorFrame> {
        let laser = config.laser.spec.clone();
        let camera = config.camera.spec.clone();
        let state = Rc::new(RefCell::new(TwinState::new(world, config)?));
        Ok(Self {
            arm: SimArm {
                state: state.clone(),
            },
            scanner: SimLineScanner {
                state: state.clone(),
                spec: laser,
            },
            camera: SimDepthCamera {
                state: state.clone(),
                spec: camera,
            },
            state,
        })
    }

    /// The rig of a (validated) scene: its twin world, sensors, error model and seed; the
    /// arm at the scene's home configuration.
    pub fn from_scene(scene: &nbv_scenes::Scene) -> Result<Self, SimRigError> {
        let world = TwinWorld::from_scene(scene)?;
        Ok(Self::new(world, RigConfig::from_scene(scene))?)
    }

    /// The shared state, for evaluation (true poses, the world). Do not hold the borrow
    /// across device calls.
    pub fn state(&self) -> Ref<'_, TwinState> {
        self.state.borrow()
    }

    /// The twin's kinematic model (the scene's URDF, loaded once with the world) and the
    /// robot base pose: what the pipeline plans with.
    pub fn robot_and_base(&self) -> (Robot, Pose) {
        let s = self.state.borrow();
        (s.world().robot().clone(), *s.world().base())
    }

    /// The rig as the pipeline takes it: the twin's robot model and base, and the three
    /// devices, borrowed.
    pub fn rig(&mut self) -> Rig<'_> {
        let (robot, base) = self.robot_and_base();
        Rig {
            robot,
            base,
            arm: &mut self.arm,
            scanner: &mut self.scanner,
            camera: &mut self.camera,
        }
    }

    /// The whole method on this rig ([`nbv_core::pipeline::explore`]).
    pub fn explore(
        &mut self,
        config: &ExploreConfig,
        observer: &mut dyn ExploreObserver,
    ) -> Result<Exploration, PipelineError> {
        explore(&mut self.rig(), config, observer)
    }

    /// A sweep's cloud as the pipeline sees it: each line cast from the sensor pose the arm
    /// reported at its time through the nominal robot model, so the points carry the
    /// scene's pose errors ([`lines_to_cloud`] with this rig's robot, base and scanner).
    pub fn sweep_cloud(&self, sweep: &SweepData) -> Result<PointCloud, SensorCloudError> {
        let state = self.state.borrow();
        let world = state.world();
        lines_to_cloud(
            &sweep.lines,
            &sweep.motion,
            world.robot(),
            world.base(),
            self.scanner.spec(),
        )
    }

    /// The reported joints, nearest the current ones, that put the depth camera at the
    /// world pose `target` (closed-form IK through the nominal model).
    pub fn camera_joints(&self, target: &Pose) -> Result<Joints, IkError> {
        let frame = &self.camera.spec().frame;
        let state = self.state.borrow();
        let world = state.world();
        Ok(world
            .robot()
            .ik_nearest(
                frame,
                &(world.base().inverse() * target),
                &state.reported_joints(),
            )?
            .joints)
    }

    /// A depth frame's cloud as the pipeline sees it: its pixels cast from the camera pose
    /// the arm reports at the joints `q` through the nominal model
    /// ([`depth_frame_to_cloud`]).
    pub fn frame_cloud(
        &self,
        frame: &DepthFrame,
        q: &Joints,
    ) -> Result<PointCloud, SensorCloudError> {
        let spec = self.camera.spec();
        let state = self.state.borrow();
        let world = state.world();
        let reported = sensor_pose(world.robot(), world.base(), q, &spec.frame)?;
        depth_frame_to_cloud(frame, spec, &reported)
    }

    /// Phase 1 only ([`nbv_core::pipeline::run_phase_one`]) on this rig.
    pub fn phase_one(
        &mut self,
        config: &ExploreConfig,
        observer: &mut dyn ExploreObserver,
    ) -> Result<(PhaseOneReport, ObjectSegmentation), PipelineError> {
        run_phase_one(&mut self.rig(), config, observer)
    }
}

impl SimArm {
    /// Places the arm at `q` (reported joints) instantly, without checking the way there;
    /// refused if `q` is outside the joint limits or in contact (the arm then stays).
    pub fn teleport(&mut self, q: Joints) -> Result<(), RigError> {
        self.state.borrow_mut().teleport(q)
    }
}

impl Arm for SimArm {
    fn joints(&mut self) -> Result<Joints, RigError> {
        Ok(self.state.borrow().reported_joints())
    }

    fn execute(&mut self, path: &JointPath) -> Result<Motion, RigError> {
        self.state.borrow_mut().execute(path)
    }
}

impl LineScanner for SimLineScanner {
    fn spec(&self) -> &LineScannerSpec {
        &self.spec
    }

    fn start(&mut self) -> Result<(), RigError> {
        self.state.borrow_mut().start_stream()
    }

    fn stop(&mut self) -> Result<Vec<ScanLine>, RigError> {
        self.state.borrow_mut().stop_stream()
    }
}

impl DepthCamera for SimDepthCamera {
    fn spec(&self) -> &DepthCameraSpec {
        &self.spec
    }

    fn capture(&mut self) -> Result<DepthFrame, RigError> {
        Ok(self.state.borrow_mut().capture())
    }
}
