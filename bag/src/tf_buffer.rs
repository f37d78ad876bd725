//! [`TfBuffer`]: an offline tf2 buffer. Transforms from `/tf` (dynamic) and `/tf_static`
//! go in; [`TfBuffer::lookup`] answers "the pose of `source` in `target` at `t`" through
//! chains of frames, the way tf2's `lookupTransform` does, but over the whole history
//! (no 10 s cache).
//!
//! Rules (tf2's `cache.cpp`): per edge, an exact stamp returns that sample; otherwise the
//! translation is interpolated linearly and the rotation by slerp between the two samples
//! that bracket `t`; if those two name different parents the older is used as is. tf2
//! never extrapolates: `t` before an edge's first sample or after its last is an error,
//! and so is a single sample whose stamp is not `t`. Static edges hold at every time.
//! Unlike tf2, `t = 0` is an ordinary time here, not "latest". Frame ids are taken with
//! any leading `/` removed, as tf2 does. A repeated stamp on an edge keeps the first
//! sample (tf2 ignores the repeat too). A frame with a static edge ignores dynamic ones.

use std::collections::{HashMap, HashSet};

use nalgebra::{Isometry3, Translation3, UnitQuaternion};

use crate::error::TfError;
use crate::messages::{TFMessage, TransformStamped};

/// tf2's limit on the length of a parent chain.
pub const MAX_DEPTH: usize = 1000;

#[derive(Debug, Clone)]
struct Sample {
    t_ns: i64,
    parent: String,
    /// The child's pose in `parent`.
    pose: Isometry3<f64>,
}

/// Every transform seen, by child frame.
///
/// ```
/// use nbv_bag::messages::{Header, TFMessage, Time, Transform, TransformStamped, Vector3};
/// use nbv_bag::TfBuffer;
/// let tf = |sec, x| TransformStamped {
///     header: Header { stamp: Time { sec, nanosec: 0 }, frame_id: "world".into() },
///     child_frame_id: "sensor".into(),
///     transform: Transform { translation: Vector3 { x, y: 0.0, z: 0.0 }, ..Default::default() },
/// };
/// let mut buf = TfBuffer::new();
/// buf.insert(&TFMessage { transforms: vec![tf(1, 0.0), tf(3, 2.0)] }, false);
/// let pose = buf.lookup("world", "sensor", 2_000_000_000).unwrap();
/// assert_eq!(pose.translation.vector.x, 1.0);
/// assert!(buf.lookup("world", "sensor", 4_000_000_000).is_err()); // no extrapolation
/// ```
#[derive(Debug, Clone, Default)]
pub struct TfBuffer {
    dynamic: HashMap<String, Vec<Sample>>,
    fixed: HashMap<String, Sample>,
    frames: HashSet<String>,
}

fn frame_name(id: &str) -> &str {
    id.trim_start_matches('/')
}

/// `a` → `b` at `ratio` in `0..=1`: linear translation, slerp rotation.
fn interpolate(a: &Isometry3<f64>, b: &Isometry3<f64>, ratio: f64) -> Isometry3<f64> {
    let t = a.translation.vector.lerp(&b.translation.vector, ratio);
    let (qa, mut qb) = (a.rotation, b.rotation);
    if qa.coords.dot(&qb.coords) < 0.0 {
        qb = UnitQuaternion::new_unchecked(-qb.into_inner());
    }
    // `try_slerp` declines only when the two are (numerically) the same rotation.
    let q = qa
        .try_slerp(&qb, ratio, 1e-12)
        .unwrap_or_else(|| qa.nlerp(&qb, ratio));
    Isometry3::from_parts(Translation3::from(t), q)
}

impl TfBuffer {
    /// An empty buffer.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds every transform of a `/tf` (`is_static` false) or `/tf_static` (true) message.
    pub fn insert(&mut self, msg: &TFMessage, is_static: bool) {
        for t in &msg.transforms {
            self.insert_transform(t, is_static);
        }
    }

    /// Adds one transform (its stamp is ignored when `is_static`).
    pub fn insert_transform(&mut self, tf: &TransformStamped, is_static: bool) {
        let child = frame_name(&tf.child_frame_id).to_owned();
        let sample = Sample {
            t_ns: tf.header.stamp.to_nanos(),
            parent: frame_name(&tf.header.frame_id).to_owned(),
            pose: tf.transform.to_isometry(),
        };
        self.frames.insert(child.clone());
        self.frames.insert(sample.parent.clone());
        if is_static {
            self.fixed.insert(child, sample);
            return;
        }
        let samples = self.dynamic.entry(child).or_default();
        let i = samples.partition_point(|s| s.t_ns < sample.t_ns);
        if samples.get(i).is_none_or(|s| s.t_ns != sample.t_ns) {
            samples.insert(i, sample);
        }
    }

    /// Every frame named by a transform, sorted.
    pub fn frames(&self) -> Vec<&str> {
        let mut v: Vec<&str> = self.frames.iter().map(String::as_str).collect();
        v.sort_unstable();
        v
    }

    /// Whether `frame` is known and has no parent: no transform names it as the child.
    ///
    /// ```
    /// use nbv_bag::TfBuffer;
    /// use nbv_bag::messages::{TFMessage, TransformStamped};
    /// let mut buf = TfBuffer::new();
    /// let mut t = TransformStamped::default();
    /// (t.header.frame_id, t.child_frame_id) = ("world".into(), "sensor".into());
    /// buf.insert(&TFMessage { transforms: vec![t] }, true);
    /// assert!(buf.is_root("world") && !buf.is_root("sensor") && !buf.is_root("nowhere"));
    /// ```
    pub fn is_root(&self, frame: &str) -> bool {
        let frame = frame_name(frame);
        self.frames.contains(frame)
            && !self.fixed.contains_key(frame)
            && self.dynamic.get(frame).is_none_or(Vec::is_empty)
    }

    /// `(first, last)` stamp of the dynamic samples of the edge to `child`, if any.
    pub fn time_range(&self, child: &str) -> Option<(i64, i64)> {
        let s = self.dynamic.get(frame_name(child))?;
        Some((s.first()?.t_ns, s.last()?.t_ns))
    }

    /// The parent of `child` at `t_ns` and the child's pose in it; `Ok(None)` for a root.
    fn edge(&self, child: &str, t_ns: i64) -> Result<Option<(&str, Isometry3<f64>)>, TfError> {
        if let Some(s) = self.fixed.get(child) {
            return Ok(Some((&s.parent, s.pose)));
        }
        let Some(samples) = self.dynamic.get(child).filter(|s| !s.is_empty()) else {
            return Ok(None);
        };
        let i = samples.partition_point(|s| s.t_ns < t_ns);
        if let Some(s) = samples.get(i).filter(|s| s.t_ns == t_ns) {
            return Ok(Some((&s.parent, s.pose)));
        }
        let (first, last) = (&samples[0], &samples[samples.len() - 1]);
        if i == 0 {
            return Err(TfError::ExtrapolationPast {
                parent: first.parent.clone(),
                child: child.to_owned(),
                t_ns,
                earliest_ns: first.t_ns,
            });
        }
        if i == samples.len() {
            return Err(TfError::ExtrapolationFuture {
                parent: last.parent.clone(),
                child: child.to_owned(),
                t_ns,
                latest_ns: last.t_ns,
            });
        }
        let (a, b) = (&samples[i - 1], &samples[i]);
        if a.parent != b.parent {
            return Ok(Some((&a.parent, a.pose)));
        }
        // The spans are i64 ns; as f64 they lose nothing below 2^53 ns (104 days).
        #[allow(clippy::cast_precision_loss)]
        let ratio = (t_ns - a.t_ns) as f64 / (b.t_ns - a.t_ns) as f64;
        Ok(Some((&a.parent, interpolate(&a.pose, &b.pose, ratio))))
    }

    /// The pose of `source` in `target` at `t_ns` (`p_target = T · p_source`), composed
    /// through the frames' nearest common ancestor.
    ///
    /// # Errors
    /// [`TfError::UnknownFrame`], [`TfError::NotConnected`],
    /// [`TfError::ExtrapolationPast`]/[`TfError::ExtrapolationFuture`] for an edge on the
    /// path that has no data bracketing `t_ns`, [`TfError::TooDeep`] for a parent loop.
    pub fn lookup(&self, target: &str, source: &str, t_ns: i64) -> Result<Isometry3<f64>, TfError> {
        let (target, source) = (frame_name(target), frame_name(source));
        for frame in [target, source] {
            if !self.frames.contains(frame) {
                return Err(TfError::UnknownFrame {
                    frame: frame.to_owned(),
                    target: target.to_owned(),
                    source_frame: source.to_owned(),
                    t_ns,
                });
            }
        }
        // Source up to its root (or the first edge with no data at t): each ancestor's
        // pose of the source.
        let mut up: HashMap<&str, Isometry3<f64>> = HashMap::new();
        let (mut frame, mut pose) = (source, Isometry3::identity());
        up.insert(frame, pose);
        let mut source_error = None;
        for depth in 0.. {
            if depth > MAX_DEPTH {
                return Err(TfError::TooDeep {
                    frame: source.to_owned(),
                    limit: MAX_DEPTH,
                    t_ns,
                });
            }
            match self.edge(frame, t_ns) {
                Ok(Some((parent, p))) => {
                    pose = p * pose;
                    frame = parent;
                    if up.insert(frame, pose).is_some() {
                        return Err(TfError::TooDeep {
                            frame: source.to_owned(),
                            limit: MAX_DEPTH,
                            t_ns,
                        });
                    }
                }
                Ok(None) => break,
                Err(e) => {
                    source_error = Some(e);
                    break;
                }
            }
        }
        // Target up until it meets the source's chain.
        let (mut frame, mut pose) = (target, Isometry3::identity());
        for _ in 0..=MAX_DEPTH {
            if let Some(source_in_frame) = up.get(frame) {
                return Ok(pose.inverse() * source_in_frame);
            }
            match self.edge(frame, t_ns)? {
                Some((parent, p)) => {
                    pose = p * pose;
                    frame = parent;
                }
                None => {
                    return Err(source_error.unwrap_or_else(|| TfError::NotConnected {
                        target: target.to_owned(),
                        source_frame: source.to_owned(),
                        t_ns,
                    }));
                }
            }
        }
        Err(TfError::TooDeep {
            frame: target.to_owned(),
            limit: MAX_DEPTH,
            t_ns,
        })
    }
}

#[cfg(test)]
mod tests {
    use std::f64::consts::FRAC_PI_2;

    use nalgebra::{Point3, Vector3 as NaVector3};

    use super::*;
    use crate::messages::{Header, Time, Transform};

    const S: i64 = 1_000_000_000;

    fn tf(parent: &str, child: &str, t_ns: i64, iso: Isometry3<f64>) -> TransformStamped {
        TransformStamped {
            header: Header {
                stamp: Time::from_nanos(t_ns),
                frame_id: parent.into(),
            },
            child_frame_id: child.into(),
            transform: Transform::from_isometry(&iso),
        }
    }

    fn iso(x: f64, y: f64, z: f64, yaw: f64) -> Isometry3<f64> {
        Isometry3::new(NaVector3::new(x, y, z), NaVector3::z() * yaw)
    }

    #[test]
    fn halfway_is_midpoint_and_slerp() {
        let mut b = TfBuffer::new();
        b.insert_transform(&tf("world", "s", S, iso(0.0, 0.0, 0.0, 0.0)), false);
        b.insert_transform(
            &tf("world", "s", 3 * S, iso(2.0, 4.0, -6.0, FRAC_PI_2)),
            false,
        );
        let p = b.lookup("world", "s", 2 * S).unwrap();
        assert!((p.translation.vector - NaVector3::new(1.0, 2.0, -3.0)).norm() < 1e-12);
        assert!((p.rotation.angle() - FRAC_PI_2 / 2.0).abs() < 1e-12);
        assert!((p.rotation.axis().unwrap().z - 1.0).abs() < 1e-12);
        // A quarter of the way.
        let p = b.lookup("world", "s", S + S / 2).unwrap();
        assert!((p.translation.vector.x - 0.5).abs() < 1e-12);
        assert!((p.rotation.angle() - FRAC_PI_2 / 4.0).abs() < 1e-12);
        // Exact stamps return the samples.
        let p = b.lookup("world", "s", 3 * S).unwrap();
        assert_eq!(p.translation.vector, NaVector3::new(2.0, 4.0, -6.0));
    }

    #[test]
    fn chain_of_three_frames_and_inverse() {
        let mut b = TfBuffer::new();
        b.insert_transform(&tf("world", "base", S, iso(1.0, 0.0, 0.0, FRAC_PI_2)), true);
        b.insert_transform(&tf("base", "arm", S, iso(0.0, 2.0, 0.0, 0.0)), false);
        b.insert_transform(&tf("arm", "sensor", S, iso(0.0, 0.0, 3.0, 0.0)), false);
        let p = b.lookup("world", "sensor", S).unwrap();
        // base is rotated 90° about z: its +y is world −x.
        let o = p * Point3::origin();
        assert!((o - Point3::new(1.0 - 2.0, 0.0, 3.0)).norm() < 1e-12, "{o}");
        let back = b.lookup("sensor", "world", S).unwrap();
        assert!(((back * p).translation.vector).norm() < 1e-12);
        // Siblings through a common ancestor: arm in sensor is −3 z.
        let q = b.lookup("sensor", "arm", S).unwrap();
        assert!((q.translation.vector - NaVector3::new(0.0, 0.0, -3.0)).norm() < 1e-12);
        assert_eq!(
            b.lookup("arm", "arm", 5 * S).unwrap(),
            Isometry3::identity()
        );
    }

    #[test]
    fn extrapolation_is_an_error() {
        let mut b = TfBuffer::new();
        b.insert_transform(&tf("world", "s", 2 * S, iso(0.0, 0.0, 0.0, 0.0)), false);
        b.insert_transform(&tf("world", "s", 4 * S, iso(1.0, 0.0, 0.0, 0.0)), false);
        let e = b.lookup("world", "s", S).unwrap_err();
        assert_eq!(
            e,
            TfError::ExtrapolationPast {
                parent: "world".into(),
                child: "s".into(),
                t_ns: S,
                earliest_ns: 2 * S
            }
        );
        assert!(e.to_string().contains("extrapolation into the past"), "{e}");
        let e = b.lookup("world", "s", 5 * S).unwrap_err();
        assert!(matches!(e, TfError::ExtrapolationFuture { latest_ns, .. } if latest_ns == 4 * S));
        assert!(e.to_string().contains("into the future"));
        // One sample: only its own stamp.
        b.insert_transform(&tf("world", "t", 2 * S, iso(0.0, 0.0, 0.0, 0.0)), false);
        assert!(b.lookup("world", "t", 2 * S).is_ok());
        assert!(b.lookup("world", "t", 2 * S + 1).is_err());
    }

    #[test]
    fn static_frames_at_any_time_and_errors() {
        let mut b = TfBuffer::new();
        b.insert(
            &TFMessage {
                transforms: vec![tf("/world", "/cam", 7 * S, iso(0.0, 0.0, 1.5, 0.0))],
            },
            true,
        );
        for t in [-S, 0, 7 * S, 1_000 * S] {
            let p = b.lookup("world", "cam", t).unwrap();
            assert_eq!(p.translation.vector.z, 1.5);
        }
        b.insert_transform(&tf("other", "x", S, iso(0.0, 0.0, 0.0, 0.0)), false);
        assert!(matches!(
            b.lookup("world", "nowhere", 0),
            Err(TfError::UnknownFrame { frame, .. }) if frame == "nowhere"
        ));
        let e = b.lookup("world", "x", S).unwrap_err();
        assert!(matches!(e, TfError::NotConnected { .. }), "{e}");
        assert_eq!(b.frames(), vec!["cam", "other", "world", "x"]);
    }

    #[test]
    fn parent_loop_is_refused() {
        let mut b = TfBuffer::new();
        b.insert_transform(&tf("a", "b", 0, iso(0.0, 0.0, 0.0, 0.0)), true);
        b.insert_transform(&tf("b", "a", 0, iso(0.0, 0.0, 0.0, 0.0)), true);
        b.insert_transform(&tf("c", "d", 0, iso(0.0, 0.0, 0.0, 0.0)), true);
        assert!(matches!(
            b.lookup("d", "a", 0),
            Err(TfError::TooDeep { .. })
        ));
    }
}
