//! [`Arm`]: a position-controlled manipulator that follows joint paths and reports where it
//! went.

use super::RigError;
use crate::kinematics::Joints;

/// A piecewise-linear path in joint space, executed at a fraction of each joint's maximum
/// speed; on every segment all joints start and stop together (synchronised motion).
#[derive(Debug, Clone, PartialEq)]
pub struct JointPath {
    /// Waypoints, the first being the configuration the arm starts from.
    pub waypoints: Vec<Joints>,
    /// Fraction (0, 1] of the joint speed limits used on every segment.
    pub speed_fraction: f64,
}

/// A joint configuration the controller reported at a time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TimedJoints {
    /// Rig time, seconds.
    pub time: f64,
    /// Reported joint angles, radians.
    pub joints: Joints,
}

/// What an arm reports about a completed motion.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Motion {
    /// Joint samples reported during the motion, in time order, first and last included.
    pub samples: Vec<TimedJoints>,
}

impl Motion {
    /// The reported configuration at `time`, linearly interpolated between samples (clamped
    /// to the first/last sample), or `None` for a motion without samples.
    pub fn joints_at(&self, time: f64) -> Option<Joints> {
        let first = self.samples.first()?;
        let last = self.samples.last()?;
        if time <= first.time {
            return Some(first.joints);
        }
        if time >= last.time {
            return Some(last.joints);
        }
        let k = self.samples.partition_point(|s| s.time <= time);
        let (a, b) = (&self.samples[k - 1], &self.samples[k]);
        let span = b.time - a.time;
        let s = if span > 0.0 {
            (time - a.time) / span
        } else {
            0.0
        };
        Some(a.joints + (b.joints - a.joints) * s)
    }
}

/// A manipulator driven by joint paths.
pub trait Arm {
    /// The configuration the controller reports now.
    fn joints(&mut self) -> Result<Joints, RigError>;

    /// Executes `path` and blocks until the motion completes (or fails: a collision, a
    /// limit, a lost connection are errors, and the arm is stopped).
    fn execute(&mut self, path: &JointPath) -> Result<Motion, RigError>;
}
