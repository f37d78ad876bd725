//! [`Robot`]: a six-axis arm loaded from URDF, with forward kinematics to every link, the
//! links' collision and visual primitives, and closed-form inverse kinematics for any frame
//! rigidly attached to the flange.

use super::ik_error::{IkError, Unreachable};
use super::ik_solution::IkSolution;
use super::joints::{DOF, JointLimit, Joints};
use super::link_geometry::LinkGeometry;
use super::newton_refine::refine;
use super::ortho_parallel::{IkStructureError, OrthoParallel, OrthoParallelParams};
use super::serial_chain::{FrameError, SerialChain};
use super::urdf_error::UrdfError;
use super::urdf_loader::chain_from_urdf;
use crate::math::Pose;
use nalgebra::{Matrix6, Point3, Vector3};
use std::path::Path;

/// Slack on joint limits for solutions that land on a limit up to rounding (rad); such
/// solutions are clamped onto the limit.
const LIMIT_TOLERANCE: f64 = 1e-10;

/// Largest position (m) and rotation (Frobenius norm of the rotation difference) error of a
/// returned IK solution.
const POSE_TOLERANCE: f64 = 1e-10;

/// A six-axis arm read from URDF.
///
/// All poses are expressed in the URDF's root link frame (for the Comau model: `base_link`,
/// on the floor, x forward, z up). Frames are the URDF links, addressed by name.
///
/// ```
/// use nbv_core::kinematics::{Joints, Robot};
/// let path = nbv_core::kinematics::COMAU_URDF;
/// let robot = Robot::from_urdf_file(path)?;
/// // Comau calibration pose: J3 = -90°, forearm horizontal.
/// let q = Joints::new(0.0, 0.0, -std::f64::consts::FRAC_PI_2, 0.0, 0.0, 0.0);
/// let wrist = robot.fk(&q, "link_5")?.translation.vector;
/// assert!((wrist - nalgebra::Vector3::new(0.79707, 0.0, 1.17)).norm() < 1e-9);
///
/// // Every way to put the depth camera where it is at q, and the one nearest to q.
/// let q = Joints::new(0.3, 0.4, -1.6, 0.5, 0.9, -0.7);
/// let camera = robot.fk(&q, "dinast")?;
/// for s in robot.ik("dinast", &camera)? {
///     let reached = robot.fk(&s.joints, "dinast")?;
///     assert!((reached.translation.vector - camera.translation.vector).norm() < 1e-9);
/// }
/// let nearest = robot.ik_nearest("dinast", &camera, &q)?;
/// assert!((nearest.joints - q).norm() < 1e-9);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone)]
pub struct Robot {
    chain: SerialChain,
    solver: Result<OrthoParallel, IkStructureError>,
}

impl Robot {
    /// Loads a URDF file. Errors name the file and what is wrong with it.
    pub fn from_urdf_file(path: impl AsRef<Path>) -> Result<Self, UrdfError> {
        let path = path.as_ref();
        let file = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|source| UrdfError::Read {
            file: file.clone(),
            source,
        })?;
        Self::from_urdf_named(&text, &file)
    }

    /// Loads URDF text (errors name it `<string>`).
    ///
    /// ```
    /// use nbv_core::kinematics::{Robot, UrdfError};
    /// let err = Robot::from_urdf_str("<robot name='r'><link name='a'/></robot>").unwrap_err();
    /// assert!(matches!(err, UrdfError::JointCount { found: 0, .. }));
    /// ```
    pub fn from_urdf_str(xml: &str) -> Result<Self, UrdfError> {
        Self::from_urdf_named(xml, "<string>")
    }

    fn from_urdf_named(xml: &str, file: &str) -> Result<Self, UrdfError> {
        let urdf = urdf_rs::read_from_string(xml).map_err(|e| UrdfError::Parse {
            file: file.to_owned(),
            message: e.to_string(),
        })?;
        let chain = chain_from_urdf(&urdf, file)?;
        let solver = OrthoParallel::from_chain(&chain);
        Ok(Self { chain, solver })
    }

    /// The URDF's robot name.
    pub fn name(&self) -> &str {
        &self.chain.name
    }

    /// The root link (the frame every pose is expressed in).
    pub fn base_frame(&self) -> &str {
        &self.chain.frame_names[self.chain.root]
    }

    /// The tip link: the child of the last revolute joint.
    pub fn tip_frame(&self) -> &str {
        &self.chain.frame_names[self.chain.tip]
    }

    /// Names of the six revolute joints, base to tip.
    pub fn joint_names(&self) -> [&str; DOF] {
        std::array::from_fn(|k| self.chain.joints[k].name.as_str())
    }

    /// Limits of the six joints, base to tip.
    pub fn limits(&self) -> &[JointLimit; DOF] {
        &self.chain.limits
    }

    /// Whether every joint is within its limits.
    pub fn within_limits(&self, q: &Joints) -> bool {
        q.iter()
            .zip(self.chain.limits.iter())
            .all(|(v, l)| l.contains(*v))
    }

    /// Names of all frames (the URDF links, in document order). [`Robot::link_poses`]
    /// returns poses in this order.
    pub fn frame_names(&self) -> &[String] {
        &self.chain.frame_names
    }

    /// Index of a frame in [`Robot::frame_names`].
    pub fn frame_index(&self, frame: &str) -> Option<usize> {
        self.chain.frame_index.get(frame).copied()
    }

    /// Pose of `frame` in the base frame at joint angles `q` (`T_base_frame`).
    /// ```
    /// # use nbv_core::kinematics::{Joints, Robot};
    /// # let path = nbv_core::kinematics::COMAU_URDF;
    /// let robot = Robot::from_urdf_file(path)?;
    /// let q = Joints::new(0.0, 0.0, -std::f64::consts::FRAC_PI_2, 0.0, 0.0, 0.0);
    /// let tool0 = robot.fk(&q, "tool0")?;
    /// // Calibration pose: the flange 0.095 m beyond the wrist centre, z out of the flange.
    /// assert!((tool0.translation.x - 0.89207).abs() < 1e-12);
    /// assert!((tool0.rotation * nalgebra::Vector3::z() - nalgebra::Vector3::x()).norm() < 1e-12);
    /// assert!(robot.fk(&q, "no_such_link").is_err());
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn fk(&self, q: &Joints, frame: &str) -> Result<Pose, FrameError> {
        let index = self.chain.find(frame)?;
        self.chain.frame_pose(q, index).ok_or_else(|| FrameError {
            name: frame.to_owned(),
            known: self.chain.frame_names.clone(),
        })
    }

    /// Poses of every frame at `q`, in [`Robot::frame_names`] order.
    /// ```
    /// # use nbv_core::kinematics::{Joints, Robot};
    /// # let path = nbv_core::kinematics::COMAU_URDF;
    /// let robot = Robot::from_urdf_file(path)?;
    /// let poses = robot.link_poses(&Joints::zeros());
    /// let i = robot.frame_index("link_2").unwrap();
    /// assert!((poses[i].translation.z - 0.45).abs() < 1e-12);
    /// // Collision primitives sit at poses[g.frame] * g.origin.
    /// for g in robot.collision_geometry() {
    ///     let _world = poses[g.frame] * g.origin;
    /// }
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn link_poses(&self, q: &Joints) -> Vec<Pose> {
        self.chain.all_frame_poses(q)
    }

    /// The rigid body `frame` moves with, as the number of joints that move it: 0 for frames
    /// fixed to the base, k for frames carried by joint k (6 for the flange and everything
    /// mounted on it). Frames with equal numbers move as one body; bodies whose numbers
    /// differ by one are adjacent (joined by a joint), which is what self-collision checks
    /// usually skip.
    ///
    /// ```
    /// # use nbv_core::kinematics::Robot;
    /// # let path = nbv_core::kinematics::COMAU_URDF;
    /// let robot = Robot::from_urdf_file(path)?;
    /// assert_eq!(robot.body_of("link_2")?, 2);
    /// assert_eq!(robot.body_of("lms400")?, 6);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn body_of(&self, frame: &str) -> Result<usize, FrameError> {
        let index = self.chain.find(frame)?;
        Ok(self.chain.frames[index].attach)
    }

    /// The six joint axes at `q`, base to tip: the unit direction of each axis and a point
    /// on it (the joint frame's origin, which lies on the axis and is fixed both in the
    /// body before the joint and in the body after it), in the base frame.
    ///
    /// ```
    /// # use nbv_core::kinematics::{Joints, Robot};
    /// # let path = nbv_core::kinematics::COMAU_URDF;
    /// let robot = Robot::from_urdf_file(path)?;
    /// let axes = robot.joint_axes(&Joints::zeros());
    /// // J1 about -z through the origin; J2 about +y through (0.15, 0, 0.45).
    /// assert!((axes[0].0 + nalgebra::Vector3::z()).norm() < 1e-12);
    /// assert!((axes[1].1 - nalgebra::Point3::new(0.15, 0.0, 0.45)).norm() < 1e-12);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn joint_axes(&self, q: &Joints) -> [(Vector3<f64>, Point3<f64>); DOF] {
        self.chain
            .joint_axes(q)
            .map(|(axis, point)| (axis, Point3::from(point)))
    }

    /// How a small offset of each joint moves `frame` at `q`, in the frame itself: column
    /// `j` is the twist `(ω, v)` (rotation first) of `T(q)⁻¹·T(q + ε·e_j)` per radian, so a
    /// joint offset `δq` turns the frame by `ω = J_ω·δq` and moves it by `v = J_v·δq` (both
    /// in the frame's own axes). The rig's self-calibration maps joint offsets to each
    /// view's sensor-frame pose error with it.
    ///
    /// ```
    /// # use nbv_core::kinematics::Joints;
    /// let robot = nbv_core::kinematics::comau_smart_six()?;
    /// let q = Joints::from([0.3, -0.2, 0.4, 0.1, 0.5, -0.3]);
    /// let j = robot.frame_jacobian(&q, "dinast")?;
    /// // Against a finite difference of the forward kinematics, joint 2.
    /// let eps = 1e-7;
    /// let mut qe = q;
    /// qe[1] += eps;
    /// let d = robot.fk(&q, "dinast")?.inverse() * robot.fk(&qe, "dinast")?;
    /// let w = d.rotation.scaled_axis() / eps;
    /// let v = d.translation.vector / eps;
    /// for k in 0..3 {
    ///     assert!((j[(k, 1)] - w[k]).abs() < 1e-6);
    ///     assert!((j[(k + 3, 1)] - v[k]).abs() < 1e-6);
    /// }
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn frame_jacobian(&self, q: &Joints, frame: &str) -> Result<Matrix6<f64>, FrameError> {
        let pose = self.fk(q, frame)?;
        let to_frame = pose.rotation.inverse();
        let origin = Point3::from(pose.translation.vector);
        let mut j = Matrix6::zeros();
        for (k, (axis, point)) in self.joint_axes(q).iter().enumerate() {
            let w = to_frame * axis;
            let v = to_frame * axis.cross(&(origin - point));
            j.fixed_view_mut::<3, 1>(0, k).copy_from(&w);
            j.fixed_view_mut::<3, 1>(3, k).copy_from(&v);
        }
        Ok(j)
    }

    /// Pose of `frame` relative to the tip link (`T_tip_frame`), for frames rigidly
    /// attached to it (for the Comau: `tool0`, `ee_bracket`, `lms400`, `dinast`).
    pub fn frame_in_tip(&self, frame: &str) -> Result<Pose, IkError> {
        let index = self.chain.find(frame)?;
        let f = &self.chain.frames[index];
        if f.attach != DOF {
            return Err(IkError::NotOnTip {
                frame: frame.to_owned(),
                tip: self.tip_frame().to_owned(),
            });
        }
        Ok(f.offset)
    }

    /// Re-attaches `frame`, a frame rigidly attached to the tip link, at `in_tip`
    /// (`T_tip_frame`): how a hand-eye calibration replaces the nominal sensor mount of the
    /// URDF. The frame's collision and visual primitives move with it.
    ///
    /// ```
    /// # use nbv_core::kinematics::{Joints, Robot};
    /// # let path = nbv_core::kinematics::COMAU_URDF;
    /// let mut robot = Robot::from_urdf_file(path)?;
    /// let nominal = robot.frame_in_tip("dinast")?;
    /// let calibrated = nominal * nalgebra::Isometry3::translation(0.002, 0.0, -0.001);
    /// robot.set_frame_in_tip("dinast", calibrated)?;
    /// assert_eq!(robot.frame_in_tip("dinast")?, calibrated);
    /// assert!(robot.set_frame_in_tip("link_3", calibrated).is_err());
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn set_frame_in_tip(&mut self, frame: &str, in_tip: Pose) -> Result<(), IkError> {
        self.frame_in_tip(frame)?;
        let index = self.chain.find(frame)?;
        self.chain.frames[index].offset = in_tip;
        Ok(())
    }

    /// Collision primitives of all links (poses relative to their link).
    pub fn collision_geometry(&self) -> &[LinkGeometry] {
        &self.chain.collisions
    }

    /// Visual primitives of all links (poses relative to their link).
    pub fn visual_geometry(&self) -> &[LinkGeometry] {
        &self.chain.visuals
    }

    /// The geometric parameters the closed-form IK measured on the chain, or why the chain
    /// is not of the ortho-parallel class (FK works either way).
    pub fn ik_parameters(&self) -> Result<OrthoParallelParams, IkStructureError> {
        self.solver.as_ref().map(|s| s.params).map_err(Clone::clone)
    }

    /// Every joint configuration within the limits that puts `frame` at `pose`: up to eight
    /// branches (shoulder front/back × elbow up/down × wrist ±), sorted in that order.
    ///
    /// For joints whose range exceeds 2π (J4, J6 of the Comau) the angle of each branch is
    /// the representative nearest the middle of the range. At an exact singularity the free
    /// angle (J1 at the shoulder, J4 at the wrist) is the middle of its range, and the
    /// solution is flagged. Every solution reproduces `pose` within 1e-10 (m, and Frobenius
    /// norm of the rotation difference).
    ///
    /// Errors: unknown frame, frame not rigidly attached to the tip, a robot outside the
    /// ortho-parallel class, a non-finite pose, or [`Unreachable`] with the reason (out of
    /// reach, or every solution outside the limits). Never returns an empty list.
    /// ```
    /// # use nbv_core::kinematics::{Joints, Robot};
    /// # let path = nbv_core::kinematics::COMAU_URDF;
    /// let robot = Robot::from_urdf_file(path)?;
    /// use nbv_core::kinematics::{IkError, Unreachable};
    /// let q = Joints::new(0.2, 0.3, -1.3, 0.4, 0.7, -0.2);
    /// let target = robot.fk(&q, "tool0")?;
    /// let solutions = robot.ik("tool0", &target)?;
    /// assert!(solutions.iter().all(|s| robot.within_limits(&s.joints)));
    /// let far = nbv_core::math::pose_from_xyz_rpy([3.0, 0.0, 1.0], [0.0; 3]);
    /// assert!(matches!(
    ///     robot.ik("tool0", &far),
    ///     Err(IkError::Unreachable(Unreachable::TooFar { .. }))
    /// ));
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn ik(&self, frame: &str, pose: &Pose) -> Result<Vec<IkSolution>, IkError> {
        let middle = Joints::from_fn(|k, _| self.chain.limits[k].centre());
        self.solve(frame, pose, &middle)
    }

    /// The solution of [`Robot::ik`] nearest to `reference` (Euclidean distance in joint
    /// space), considering every 2π-equivalent of joints with ranges wider than 2π; free
    /// angles at singularities are taken from `reference`. So `ik_nearest(fk(q), q)` is `q`.
    pub fn ik_nearest(
        &self,
        frame: &str,
        pose: &Pose,
        reference: &Joints,
    ) -> Result<IkSolution, IkError> {
        if reference.iter().any(|v| !v.is_finite()) {
            return Err(IkError::NonFinite("reference configuration"));
        }
        let solutions = self.solve(frame, pose, reference)?;
        let distance = |s: &IkSolution| (s.joints - reference).norm();
        solutions
            .into_iter()
            .min_by(|a, b| distance(a).total_cmp(&distance(b)))
            .ok_or(IkError::Unreachable(Unreachable::JointLimits {
                solutions: 0,
            }))
    }

    /// Whether some configuration within the limits puts `frame` at `pose`. Errors only for
    /// queries that cannot be answered (unknown frame, unsupported robot, non-finite pose).
    /// ```
    /// # use nbv_core::kinematics::{Joints, Robot};
    /// # let path = nbv_core::kinematics::COMAU_URDF;
    /// let robot = Robot::from_urdf_file(path)?;
    /// // The depth camera 0.35 m above the floor, 0.8 m in front, looking straight down.
    /// let down = nbv_core::math::pose_from_xyz_rpy([0.8, 0.0, 0.35], [std::f64::consts::PI, 0.0, 0.0]);
    /// assert!(robot.reachable("dinast", &down)?);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn reachable(&self, frame: &str, pose: &Pose) -> Result<bool, IkError> {
        match self.ik(frame, pose) {
            Ok(solutions) => Ok(!solutions.is_empty()),
            Err(IkError::Unreachable(_)) => Ok(false),
            Err(e) => Err(e),
        }
    }

    /// "Can the arm put `frame` at this world pose?" for the robot mounted at `base`: the
    /// closed-form IK of the frame ([`reachable`](Self::reachable)) with the pose brought
    /// into the base frame; a query that cannot be answered is a no.
    /// ```
    /// # use nbv_core::kinematics::Robot;
    /// let robot = Robot::from_urdf_file(nbv_core::kinematics::COMAU_URDF)?;
    /// let reach = robot.reachability(nbv_core::math::Pose::translation(0.0, 0.0, 0.1), "dinast");
    /// // The depth camera 0.45 m above the floor, 0.8 m in front, looking straight down.
    /// let down = nbv_core::math::pose_from_xyz_rpy([0.8, 0.0, 0.45], [std::f64::consts::PI, 0.0, 0.0]);
    /// assert!(reach(&down));
    /// assert!(!reach(&nbv_core::math::Pose::translation(9.0, 0.0, 0.0)));
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn reachability<'a>(&'a self, base: Pose, frame: &'a str) -> impl Fn(&Pose) -> bool + 'a {
        let base_inv = base.inverse();
        move |pose| self.reachable(frame, &(base_inv * pose)).unwrap_or(false)
    }

    /// Solutions with representatives (and free angles) nearest to `reference`.
    fn solve(
        &self,
        frame: &str,
        pose: &Pose,
        reference: &Joints,
    ) -> Result<Vec<IkSolution>, IkError> {
        let solver = self
            .solver
            .as_ref()
            .map_err(|e| IkError::Unsupported(e.clone()))?;
        let finite = pose.translation.vector.iter().all(|v| v.is_finite())
            && pose.rotation.coords.iter().all(|v| v.is_finite());
        if !finite {
            return Err(IkError::NonFinite("target pose"));
        }
        let tip_target = pose * self.frame_in_tip(frame)?.inverse();
        let raw = solver.solve(&tip_target, reference)?;
        let limits = &self.chain.limits;
        let mut out = Vec::with_capacity(raw.len());
        let mut not_converged = 0;
        for r in &raw {
            let mut q = Joints::zeros();
            let mut inside = true;
            for k in 0..DOF {
                match limits[k].representative_near(r.q[k], reference[k], LIMIT_TOLERANCE) {
                    Some(v) => q[k] = v,
                    None => inside = false,
                }
            }
            if !inside {
                continue;
            }
            let Some(q) = refine(&self.chain, q, &tip_target, POSE_TOLERANCE) else {
                not_converged += 1;
                continue;
            };
            let inside = q
                .iter()
                .zip(limits.iter())
                .all(|(v, l)| *v >= l.lower - LIMIT_TOLERANCE && *v <= l.upper + LIMIT_TOLERANCE);
            if inside {
                out.push(IkSolution {
                    joints: Joints::from_fn(|k, _| q[k].clamp(limits[k].lower, limits[k].upper)),
                    branch: r.branch,
                    singularity: r.singularity,
                });
            }
        }
        out.sort_by_key(|s| s.branch);
        if out.is_empty() && not_converged > 0 {
            return Err(IkError::NotConverged {
                solutions: not_converged,
            });
        }
        if out.is_empty() {
            return Err(Unreachable::JointLimits {
                solutions: raw.len(),
            }
            .into());
        }
        Ok(out)
    }
}
