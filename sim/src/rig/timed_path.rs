//! [`TimedPath`]: a [`JointPath`] with a time law — piecewise linear in joint space, each
//! segment at constant speed, all joints starting and stopping together, the slowest joint
//! at `speed_fraction` of its velocity limit. No acceleration phases: the Comau's
//! acceleration limits are not published, and the twin is kinematic.

use nbv_core::kinematics::{DOF, JointLimit, Joints};
use nbv_core::rig::{JointPath, RigError, TimedJoints};

/// A validated joint path with the arrival time of every waypoint.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct TimedPath {
    /// Waypoints (reported/commanded joints).
    pub(crate) waypoints: Vec<Joints>,
    /// Arrival time of each waypoint (rig time, s); `times[0]` is the start.
    pub(crate) times: Vec<f64>,
}

impl TimedPath {
    /// Times `path` from `start` (rig time). Checks the speed fraction, finiteness and
    /// the joint limits of every waypoint (segments between in-limit waypoints stay in
    /// the limits: the limits form a box).
    pub(crate) fn new(
        path: &JointPath,
        limits: &[JointLimit; DOF],
        start: f64,
    ) -> Result<Self, RigError> {
        let f = path.speed_fraction;
        if !(f.is_finite() && f > 0.0 && f <= 1.0) {
            return Err(RigError::InvalidPath(format!(
                "speed fraction {f} is not in (0, 1]"
            )));
        }
        if path.waypoints.is_empty() {
            return Err(RigError::InvalidPath("no waypoint".into()));
        }
        for (i, q) in path.waypoints.iter().enumerate() {
            if q.iter().any(|v| !v.is_finite()) {
                return Err(RigError::InvalidPath(format!("waypoint {i} is not finite")));
            }
            if let Some((joint, value)) = q
                .iter()
                .zip(limits)
                .enumerate()
                .find(|(_, (v, l))| !l.contains(**v))
                .map(|(k, (v, _))| (k, *v))
            {
                return Err(RigError::JointLimit {
                    joint,
                    value_deg: value.to_degrees(),
                });
            }
        }
        let mut times = Vec::with_capacity(path.waypoints.len());
        times.push(start);
        for pair in path.waypoints.windows(2) {
            let duration = (0..DOF)
                .map(|k| (pair[1][k] - pair[0][k]).abs() / (f * limits[k].velocity))
                .fold(0.0, f64::max);
            if !duration.is_finite() {
                return Err(RigError::InvalidPath(
                    "a joint velocity limit is zero".into(),
                ));
            }
            times.push(times[times.len() - 1] + duration);
        }
        Ok(Self {
            waypoints: path.waypoints.clone(),
            times,
        })
    }

    /// Start time.
    pub(crate) fn start(&self) -> f64 {
        self.times[0]
    }

    /// Arrival time at the last waypoint.
    pub(crate) fn end(&self) -> f64 {
        self.times[self.times.len() - 1]
    }

    /// The configuration at time `t` (clamped to the path's time span).
    pub(crate) fn at(&self, t: f64) -> Joints {
        if t <= self.start() {
            return self.waypoints[0];
        }
        if t >= self.end() {
            return self.waypoints[self.waypoints.len() - 1];
        }
        let k = self.times.partition_point(|&x| x <= t).max(1);
        let (t0, t1) = (self.times[k - 1], self.times[k]);
        let s = if t1 > t0 { (t - t0) / (t1 - t0) } else { 1.0 };
        self.waypoints[k - 1] + (self.waypoints[k] - self.waypoints[k - 1]) * s
    }

    /// Reported samples from the start up to `until`: every `1/rate` s, at every waypoint
    /// reached and at `until` itself, so linear interpolation between samples reproduces
    /// the path exactly.
    pub(crate) fn samples(&self, until: f64, rate_hz: f64) -> Vec<TimedJoints> {
        let mut times: Vec<f64> = self.times.iter().copied().filter(|&t| t < until).collect();
        let period = 1.0 / rate_hz;
        let mut k = 1u64;
        loop {
            let t = self.start() + k as f64 * period;
            if t >= until {
                break;
            }
            times.push(t);
            k += 1;
        }
        times.push(until);
        times.sort_by(f64::total_cmp);
        times.dedup_by(|a, b| (*a - *b).abs() < 1e-9);
        times
            .into_iter()
            .map(|time| TimedJoints {
                time,
                joints: self.at(time),
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn limits() -> [JointLimit; DOF] {
        [1.0, 2.0, 1.0, 4.0, 4.0, 4.0].map(|velocity| JointLimit {
            lower: -3.0,
            upper: 3.0,
            velocity,
            effort: 0.0,
        })
    }

    #[test]
    fn segments_are_synchronised_at_the_slowest_joint() {
        let path = JointPath {
            waypoints: vec![
                Joints::zeros(),
                Joints::new(0.5, 1.0, 0.0, 0.0, 0.0, 0.0),
                Joints::new(0.5, 1.0, 0.0, 0.0, 2.0, 0.0),
            ],
            speed_fraction: 0.5,
        };
        let t = TimedPath::new(&path, &limits(), 10.0).unwrap();
        // Segment 1: J1 0.5/(0.5·1) = 1 s, J2 1/(0.5·2) = 1 s. Segment 2: 2/(0.5·4) = 1 s.
        assert_eq!(t.times, vec![10.0, 11.0, 12.0]);
        assert!((t.at(10.5) - Joints::new(0.25, 0.5, 0.0, 0.0, 0.0, 0.0)).norm() < 1e-12);
        assert_eq!(t.at(99.0), path.waypoints[2]);
        let s = t.samples(t.end(), 4.0);
        assert_eq!(s.len(), 9); // 10, 10.25, …, 12
        assert_eq!(s.last().unwrap().joints, path.waypoints[2]);
        let partial = t.samples(10.6, 100.0);
        assert_eq!(partial.last().unwrap().time, 10.6);
    }

    #[test]
    fn bad_paths_are_refused() {
        let ok = JointPath {
            waypoints: vec![Joints::zeros()],
            speed_fraction: 1.0,
        };
        assert!(TimedPath::new(&ok, &limits(), 0.0).is_ok());
        for f in [0.0, -1.0, 1.5, f64::NAN] {
            let p = JointPath {
                speed_fraction: f,
                ..ok.clone()
            };
            assert!(matches!(
                TimedPath::new(&p, &limits(), 0.0),
                Err(RigError::InvalidPath(_))
            ));
        }
        let empty = JointPath {
            waypoints: vec![],
            speed_fraction: 1.0,
        };
        assert!(TimedPath::new(&empty, &limits(), 0.0).is_err());
        let far = JointPath {
            waypoints: vec![Joints::zeros(), Joints::new(0.0, 0.0, 3.5, 0.0, 0.0, 0.0)],
            speed_fraction: 1.0,
        };
        match TimedPath::new(&far, &limits(), 0.0) {
            Err(RigError::JointLimit { joint, value_deg }) => {
                assert_eq!(joint, 2);
                assert!((value_deg - 3.5f64.to_degrees()).abs() < 1e-9);
            }
            other => panic!("{other:?}"),
        }
    }
}
