//! Turning what the sensors return into world-frame point clouds with a sensor origin per
//! point: [`lines_to_cloud`] (a streamed laser sweep stamped with the arm's reported
//! motion) and [`depth_frame_to_cloud`] (one depth frame at a reported sensor pose).
//!
//! These use the *nominal* robot model and the *reported* joints, exactly as the pipeline
//! sees the rig: on the twin, the points differ from the truth by the injected error model.
//! When every valid return carries ground truth, the clouds get `labels`
//! ([`TruthLabel::code`](super::TruthLabel::code)) and `truth` (noise-free world points)
//! columns; otherwise neither.

use super::{DepthCameraSpec, DepthFrame, LineScannerSpec, Motion, ScanLine, TruthHit};
use crate::cloud::PointCloud;
use crate::kinematics::{FrameError, Joints, Robot};
use crate::math::Pose;
use nalgebra::Point3;
use thiserror::Error;

/// Why sensor data could not become a cloud.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum SensorCloudError {
    /// The sensor frame is not a frame of the robot model.
    #[error("sensor frame `{}` is not in the robot model", .0.name)]
    UnknownFrame(FrameError),
    /// Scan lines were given with a motion that has no joint sample.
    #[error("{lines} scan line(s) but the motion has no joint sample to pose them")]
    EmptyMotion {
        /// Number of lines.
        lines: usize,
    },
    /// The frame does not have the size the camera spec says, or its columns disagree.
    #[error(
        "depth frame is {width}×{height} with {depth} depths, the camera spec says {spec_width}×{spec_height}"
    )]
    FrameSize {
        /// Frame width.
        width: usize,
        /// Frame height.
        height: usize,
        /// Number of depth values.
        depth: usize,
        /// Spec width.
        spec_width: usize,
        /// Spec height.
        spec_height: usize,
    },
}

/// World pose of a sensor `frame` at reported joints `q`, for a robot mounted at `base`
/// (`base · FK(q, frame)` with the nominal model).
///
/// ```
/// use nbv_core::kinematics::{Joints, Robot};
/// use nbv_core::rig::sensor_pose;
/// let path = nbv_core::kinematics::COMAU_URDF;
/// let robot = Robot::from_urdf_file(path)?;
/// let q = Joints::new(0.0, 0.0, -std::f64::consts::FRAC_PI_2, 0.0, 0.0, 0.0);
/// let base = nalgebra::Isometry3::translation(0.0, 0.0, 0.1);
/// let p = sensor_pose(&robot, &base, &q, "lms400")?;
/// assert!((p.translation.z - (1.17 + 0.1 + 0.08)).abs() < 1e-9);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn sensor_pose(
    robot: &Robot,
    base: &Pose,
    q: &Joints,
    frame: &str,
) -> Result<Pose, SensorCloudError> {
    robot
        .fk(q, frame)
        .map(|p| base * p)
        .map_err(SensorCloudError::UnknownFrame)
}

/// Accumulates the columns of a cloud as returns are appended.
struct CloudBuilder {
    cloud: PointCloud,
    labels: Vec<u32>,
    truth: Vec<Point3<f64>>,
    complete_truth: bool,
}

impl CloudBuilder {
    fn new(capacity: usize) -> Self {
        Self {
            cloud: PointCloud {
                points: Vec::with_capacity(capacity),
                origins: Some(Vec::with_capacity(capacity)),
                ..PointCloud::default()
            },
            labels: Vec::with_capacity(capacity),
            truth: Vec::with_capacity(capacity),
            complete_truth: true,
        }
    }

    fn push(&mut self, point: Point3<f64>, origin: Point3<f64>, truth: Option<TruthHit>) {
        self.cloud.points.push(point);
        if let Some(o) = self.cloud.origins.as_mut() {
            o.push(origin);
        }
        match truth {
            Some(t) if self.complete_truth => {
                self.labels.push(t.label.code());
                self.truth.push(t.point);
            }
            _ => self.complete_truth = false,
        }
    }

    fn finish(self) -> PointCloud {
        let mut cloud = self.cloud;
        if self.complete_truth {
            cloud.labels = Some(self.labels);
            cloud.truth = Some(self.truth);
        }
        cloud
    }
}

/// The world-frame cloud of a laser sweep: each line is posed at its time with the
/// reported joints of `motion` (linearly interpolated, see [`Motion::joints_at`]) through
/// the nominal `robot` mounted at `base`; every point's origin is the sensor origin of its
/// line. Lines are taken in order, beams in order; invalid (NaN) ranges are skipped.
///
/// ```
/// use nbv_core::kinematics::{Joints, Robot};
/// use nbv_core::rig::{lines_to_cloud, LineScannerSpec, Motion, ScanLine, TimedJoints};
/// let path = nbv_core::kinematics::COMAU_URDF;
/// let robot = Robot::from_urdf_file(path)?;
/// let q = Joints::new(0.0, 0.0, -std::f64::consts::FRAC_PI_2, 0.0, std::f64::consts::FRAC_PI_2, 0.0);
/// let motion = Motion { samples: vec![TimedJoints { time: 0.0, joints: q }] };
/// let spec = LineScannerSpec {
///     frame: "lms400".into(), range: [0.7, 3.0], fov: 1.2, resolution: 0.6, line_rate_hz: 190.0,
/// };
/// let line = ScanLine {
///     time: 0.0, start_angle: -0.6, angle_step: 0.6,
///     ranges: vec![f32::NAN, 1.0, 1.5], truth: None,
/// };
/// let cloud = lines_to_cloud(&[line], &motion, &robot, &nalgebra::Isometry3::identity(), &spec)?;
/// assert_eq!(cloud.len(), 2);
/// // The wrist points down: the centre beam ends 1 m below the sensor.
/// let o = cloud.origins.as_ref().unwrap()[0];
/// assert!((o.z - cloud.points[0].z - 1.0).abs() < 1e-9);
/// assert!(cloud.labels.is_none());
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn lines_to_cloud(
    lines: &[ScanLine],
    motion: &Motion,
    robot: &Robot,
    base: &Pose,
    spec: &LineScannerSpec,
) -> Result<PointCloud, SensorCloudError> {
    let capacity = lines.iter().map(|l| l.ranges.len()).sum();
    let mut out = CloudBuilder::new(capacity);
    for line in lines {
        let q = motion
            .joints_at(line.time)
            .ok_or(SensorCloudError::EmptyMotion { lines: lines.len() })?;
        let pose = sensor_pose(robot, base, &q, &spec.frame)?;
        let origin = Point3::from(pose.translation.vector);
        for i in 0..line.ranges.len() {
            if let Some(p) = line.point(i) {
                let truth = line
                    .truth
                    .as_ref()
                    .and_then(|t| t.get(i).copied().flatten());
                out.push(pose * p, origin, truth);
            }
        }
    }
    Ok(out.finish())
}

/// The world-frame cloud of one depth frame taken at `sensor_pose` (the pose the pipeline
/// believes, e.g. [`sensor_pose`] of the reported joints): valid pixels only, row by row;
/// every origin is the sensor origin.
///
/// ```
/// use nbv_core::rig::{depth_frame_to_cloud, DepthCameraSpec, DepthFrame};
/// let spec = DepthCameraSpec {
///     frame: "dinast".into(), range: [0.1, 0.8], width: 2, height: 1, hfov: 1.0,
/// };
/// let frame = DepthFrame {
///     time: 0.0, width: 2, height: 1, depth: vec![0.5, f32::NAN], truth: None,
/// };
/// let pose = nalgebra::Isometry3::translation(0.0, 0.0, 1.0);
/// let cloud = depth_frame_to_cloud(&frame, &spec, &pose)?;
/// assert_eq!(cloud.len(), 1);
/// assert!((cloud.points[0].z - 1.5).abs() < 1e-6);
/// # Ok::<(), nbv_core::rig::SensorCloudError>(())
/// ```
pub fn depth_frame_to_cloud(
    frame: &DepthFrame,
    spec: &DepthCameraSpec,
    sensor_pose: &Pose,
) -> Result<PointCloud, SensorCloudError> {
    let n = frame.width * frame.height;
    let truth_ok = frame.truth.as_ref().is_none_or(|t| t.len() == n);
    if frame.width != spec.width
        || frame.height != spec.height
        || frame.depth.len() != n
        || !truth_ok
    {
        return Err(SensorCloudError::FrameSize {
            width: frame.width,
            height: frame.height,
            depth: frame.depth.len(),
            spec_width: spec.width,
            spec_height: spec.height,
        });
    }
    let origin = Point3::from(sensor_pose.translation.vector);
    let mut out = CloudBuilder::new(n);
    for v in 0..frame.height {
        for u in 0..frame.width {
            if let Some(p) = frame.point(spec, u, v) {
                let i = v * frame.width + u;
                let truth = frame.truth.as_ref().and_then(|t| t[i]);
                out.push(sensor_pose * p, origin, truth);
            }
        }
    }
    Ok(out.finish())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rig::{TimedJoints, TruthLabel};
    use nalgebra::Isometry3;

    fn robot() -> Robot {
        crate::kinematics::comau_smart_six().unwrap()
    }

    fn spec() -> LineScannerSpec {
        LineScannerSpec {
            frame: "lms400".into(),
            range: [0.7, 3.0],
            fov: 70f64.to_radians(),
            resolution: 35f64.to_radians(),
            line_rate_hz: 190.0,
        }
    }

    #[test]
    fn lines_are_posed_at_their_time_and_carry_truth() {
        let robot = robot();
        let q0 = Joints::new(0.0, 0.0, -1.5, 0.0, 1.2, 0.0);
        let q1 = Joints::new(0.2, 0.0, -1.5, 0.0, 1.4, 0.0);
        let motion = Motion {
            samples: vec![
                TimedJoints {
                    time: 1.0,
                    joints: q0,
                },
                TimedJoints {
                    time: 2.0,
                    joints: q1,
                },
            ],
        };
        let base = Isometry3::translation(0.1, 0.2, 0.0);
        let hit = |x: f64| {
            Some(TruthHit {
                label: TruthLabel::Object(3),
                point: Point3::new(x, 0.0, 0.0),
            })
        };
        let lines: Vec<ScanLine> = [1.0, 1.5, 2.0]
            .iter()
            .map(|&t| ScanLine {
                time: t,
                start_angle: -0.5 * spec().fov,
                angle_step: spec().resolution,
                ranges: vec![1.0, f32::NAN, 1.2],
                truth: Some(vec![hit(t), None, hit(-t)]),
            })
            .collect();
        let cloud = lines_to_cloud(&lines, &motion, &robot, &base, &spec()).unwrap();
        assert_eq!(cloud.len(), 6);
        assert_eq!(cloud.labels.as_deref(), Some(&[2003; 6][..]));
        assert_eq!(cloud.truth.as_ref().unwrap()[1].x, -1.0);
        // The middle line is posed at the midpoint configuration.
        let mid = sensor_pose(&robot, &base, &(0.5 * (q0 + q1)), "lms400").unwrap();
        let o = cloud.origins.as_ref().unwrap()[2];
        assert!((o.coords - mid.translation.vector).norm() < 1e-12);
        let beam0 = mid * Point3::new(-(35f64.to_radians().sin()), 0.0, 35f64.to_radians().cos());
        assert!((cloud.points[2] - beam0).norm() < 1e-9);
        for (p, o) in cloud.points.iter().zip(cloud.origins.as_ref().unwrap()) {
            let r = (p - o).norm();
            assert!((r - 1.0).abs() < 1e-6 || (r - 1.2).abs() < 1e-6, "{r}");
        }
        assert_eq!(cloud.validate(), Ok(()));
    }

    #[test]
    fn missing_truth_drops_both_truth_columns_and_bad_input_is_an_error() {
        let robot = robot();
        let q = Joints::new(0.0, 0.0, -1.5, 0.0, 1.2, 0.0);
        let motion = Motion {
            samples: vec![TimedJoints {
                time: 0.0,
                joints: q,
            }],
        };
        let line = ScanLine {
            time: 0.0,
            start_angle: 0.0,
            angle_step: 0.1,
            ranges: vec![1.0, 1.0],
            truth: Some(vec![
                Some(TruthHit {
                    label: TruthLabel::Table,
                    point: Point3::origin(),
                }),
                None,
            ]),
        };
        let base = Isometry3::identity();
        let cloud =
            lines_to_cloud(std::slice::from_ref(&line), &motion, &robot, &base, &spec()).unwrap();
        assert_eq!(cloud.len(), 2);
        assert!(cloud.labels.is_none() && cloud.truth.is_none());
        let err = lines_to_cloud(
            std::slice::from_ref(&line),
            &Motion::default(),
            &robot,
            &base,
            &spec(),
        );
        assert_eq!(err, Err(SensorCloudError::EmptyMotion { lines: 1 }));
        let mut bad = spec();
        bad.frame = "nope".into();
        assert!(matches!(
            lines_to_cloud(&[line], &motion, &robot, &base, &bad),
            Err(SensorCloudError::UnknownFrame(_))
        ));
    }

    #[test]
    fn depth_frames_unproject_along_pixel_rays() {
        let spec = DepthCameraSpec {
            width: 4,
            height: 3,
            ..DepthCameraSpec::ipa1110()
        };
        let mut depth = vec![f32::NAN; 12];
        depth[5] = 0.4; // (u, v) = (1, 1)
        let frame = DepthFrame {
            time: 0.0,
            width: 4,
            height: 3,
            depth: depth.clone(),
            truth: Some(
                (0..12)
                    .map(|i| {
                        (i == 5).then_some(TruthHit {
                            label: TruthLabel::Obstacle(2),
                            point: Point3::new(1.0, 2.0, 3.0),
                        })
                    })
                    .collect(),
            ),
        };
        let pose = Isometry3::rotation(nalgebra::Vector3::new(0.3, 0.0, 0.0));
        let cloud = depth_frame_to_cloud(&frame, &spec, &pose).unwrap();
        assert_eq!(cloud.len(), 1);
        assert_eq!(cloud.labels.as_deref(), Some(&[1002][..]));
        let local = pose.inverse() * cloud.points[0];
        assert!((local.z - 0.4).abs() < 1e-6);
        assert!((local.coords.normalize() - spec.pixel_ray(1, 1).normalize()).norm() < 1e-6);
        let small = DepthFrame {
            depth: vec![0.0; 11],
            ..frame
        };
        assert!(matches!(
            depth_frame_to_cloud(&small, &spec, &pose),
            Err(SensorCloudError::FrameSize { depth: 11, .. })
        ));
    }
}
