//! [`PoseErrors`]: the error model that separates where the twin's sensors really are from
//! where the rig reports them (the scene's `[errors]`).
//!
//! The arm reports the joints it was commanded (`q`). The twin's true state is
//! - true joints `q + joint_offset` (kinematic calibration error; the robot's colliders
//!   sit there, and collisions are checked there);
//! - true sensor pose `base · FK(q + joint_offset, frame) · mount_error · view_error`,
//!   where `mount_error` is the hand-eye error for the depth camera and the identity for
//!   the laser (the laser is the calibrated reference), and `view_error` is drawn once per
//!   laser sweep and once per standstill of the arm for the depth camera (every frame of
//!   a burst at one viewpoint shares it: the arm's pose, not the frame, is off), from the
//!   seed of the sweep or of the standstill's first frame.
//!
//! The pipeline computes `base · FK(q, frame)` with the nominal model, so its points are
//! off by exactly this model.

use crate::seeds::{self, Stream};
use crate::sensors::AcquisitionId;
use nalgebra::{Unit, UnitQuaternion, Vector3};
use nbv_core::kinematics::Joints;
use nbv_core::math::Pose;
use nbv_scenes::schema::ErrorModel;
use rand_distr::{Distribution, StandardNormal};

/// The error model in radians and metres.
#[derive(Debug, Clone, PartialEq)]
pub struct PoseErrors {
    /// True minus reported joint angles (rad).
    pub joint_offset: Joints,
    /// True depth-camera mount relative to the nominal one (`T_nominal_true`).
    pub hand_eye: Pose,
    /// σ of each translation component of a view's error (m).
    pub translation_sigma: f64,
    /// σ of the rotation angle of a view's error, about a uniformly random axis (rad).
    pub rotation_sigma: f64,
}

impl PoseErrors {
    /// No error at all: the reported poses are the true ones.
    pub fn none() -> Self {
        Self {
            joint_offset: Joints::zeros(),
            hand_eye: Pose::identity(),
            translation_sigma: 0.0,
            rotation_sigma: 0.0,
        }
    }

    /// The model of a scene's `[errors]` (its `scale` applied).
    pub fn from_scene(e: &ErrorModel) -> Self {
        let (xyz, rpy) = e.scaled_hand_eye();
        let (translation_sigma, rotation_sigma) = e.scaled_pose_noise();
        Self {
            joint_offset: Joints::from(e.scaled_joint_offsets()),
            hand_eye: nbv_core::math::pose_from_xyz_rpy(xyz, rpy),
            translation_sigma,
            rotation_sigma,
        }
    }

    /// The view error of acquisition `id` (in the sensor frame): translation with
    /// independent N(0, σ_t) components, rotation by an N(0, σ_r) angle about a uniformly
    /// random axis.
    ///
    /// ```
    /// use nbv_sim::rig::PoseErrors;
    /// use nbv_sim::sensors::AcquisitionId;
    /// let e = PoseErrors { translation_sigma: 0.002, ..PoseErrors::none() };
    /// let id = AcquisitionId { seed: 1, index: 0 };
    /// assert_eq!(e.view_error(id), e.view_error(id));
    /// assert!(e.view_error(id).translation.vector.norm() > 0.0);
    /// assert_eq!(PoseErrors::none().view_error(id), nbv_core::math::Pose::identity());
    /// ```
    pub fn view_error(&self, id: AcquisitionId) -> Pose {
        let mut rng = seeds::rng(id.seed, Stream::ViewError, id.index, 0);
        let mut normal = || -> f64 { StandardNormal.sample(&mut rng) };
        let t = Vector3::new(normal(), normal(), normal()) * self.translation_sigma;
        let axis = Vector3::new(normal(), normal(), normal());
        let angle = normal() * self.rotation_sigma;
        let rotation = match Unit::try_new(axis, 1e-12) {
            Some(axis) => UnitQuaternion::from_axis_angle(&axis, angle),
            None => UnitQuaternion::identity(),
        };
        Pose::from_parts(t.into(), rotation)
    }
}
