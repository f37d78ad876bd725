//! [`Rig`]: everything the pipeline drives, in one value — the robot's kinematic model and
//! base, the arm, the line scanner and the depth camera. The twin's `SimRig` and the real
//! drivers' `HwRig` both lend one; the pipeline never knows which.

use super::{Arm, DepthCamera, LineScanner};
use crate::kinematics::Robot;
use crate::math::Pose;

/// A rig as the pipeline sees it: the kinematic model it plans with (sensor frames
/// mounted), the robot base in the world, and its three devices, borrowed.
///
/// ```no_run
/// # fn rig_of(
/// #     robot: nbv_core::kinematics::Robot,
/// #     arm: &mut dyn nbv_core::rig::Arm,
/// #     scanner: &mut dyn nbv_core::rig::LineScanner,
/// #     camera: &mut dyn nbv_core::rig::DepthCamera,
/// # ) {
/// use nbv_core::math::Pose;
/// use nbv_core::rig::Rig;
/// let rig = Rig { robot, base: Pose::identity(), arm, scanner, camera };
/// assert_eq!(rig.camera.spec().width, 320);
/// # }
/// ```
pub struct Rig<'a> {
    /// The kinematic model the pipeline plans with.
    pub robot: Robot,
    /// The robot base in the world (the pipeline requires the identity).
    pub base: Pose,
    /// The arm.
    pub arm: &'a mut dyn Arm,
    /// The mid-range line scanner.
    pub scanner: &'a mut dyn LineScanner,
    /// The short-range depth camera.
    pub camera: &'a mut dyn DepthCamera,
}

impl std::fmt::Debug for Rig<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Rig")
            .field("base", &self.base)
            .field("scanner", self.scanner.spec())
            .field("camera", self.camera.spec())
            .finish_non_exhaustive()
    }
}
