//! Views from a rosbag2 bag for `nbv register --bag` and `nbv map --bag`: each
//! `sensor_msgs/PointCloud2` message on a topic is one view, in its sensor frame
//! (`header.frame_id`), with the sensor's pose in a fixed frame at the message's stamp from
//! `/tf` and `/tf_static` (tf2's rules: chains of frames, interpolation between stamps,
//! never extrapolation; `nbv_bag::TfBuffer`), and optionally each view's pose prior from a
//! topic of the sensor's pose covariance.

use anyhow::{Context, Result, bail};
use clap::Args;
use nalgebra::{Matrix3, Matrix6};
use nbv_bag::messages::PoseWithCovarianceStamped;
use nbv_bag::{BagReader, TfBuffer};
use nbv_core::cloud::PointCloud;
use nbv_core::math::Pose;
use nbv_core::registration::PosePrior;
use std::path::{Path, PathBuf};

/// `--bag BAG --topic T [--fixed-frame F]`: the options of a command that reads its views
/// from a bag instead of files.
#[derive(Debug, Args)]
pub struct BagInput {
    /// A ROS 2 bag (rosbag2 directory or .mcap file) instead of files: every
    /// sensor_msgs/PointCloud2 on --topic is a view in its sensor frame, at that frame's
    /// pose in --fixed-frame at the message's stamp, from /tf and /tf_static.
    #[arg(long, value_name = "BAG", requires = "topic")]
    pub bag: Option<PathBuf>,
    /// The bag's point-cloud topic.
    #[arg(long, value_name = "TOPIC", requires = "bag")]
    pub topic: Option<String>,
    /// The frame the views are posed in (default: the root of their tf tree).
    #[arg(long, value_name = "FRAME", requires = "bag")]
    pub fixed_frame: Option<String>,
}

impl BagInput {
    /// The bag's views ([`read_bag_views`], with their pose priors from `pose_topic`),
    /// reported on stderr; `None` without `--bag`.
    pub fn read(&self, pose_topic: Option<&str>) -> Result<Option<BagViews>> {
        let (Some(bag), Some(topic)) = (&self.bag, &self.topic) else {
            return Ok(None);
        };
        let views = read_bag_views(bag, topic, self.fixed_frame.as_deref(), pose_topic)?;
        eprintln!(
            "{}: {} clouds on {topic}, posed in frame {:?}",
            bag.display(),
            views.clouds.len(),
            views.fixed_frame
        );
        Ok(Some(views))
    }
}

/// The clouds of one topic with their sensor poses.
pub struct BagViews {
    /// A name per view, the key of the pose files: `"<topic>#<index>"`.
    pub names: Vec<String>,
    /// Each view's finite points, in its sensor frame.
    pub clouds: Vec<PointCloud>,
    /// Each view's sensor pose in the fixed frame (`p_fixed = pose · p_sensor`).
    pub poses: Vec<Pose>,
    /// The fixed frame the poses are in.
    pub fixed_frame: String,
    /// Each view's pose prior, when read from a topic ([`pose_priors`]).
    pub priors: Option<Vec<PosePrior>>,
}

/// Reads every cloud on `topic` of the bag at `bag` (a rosbag2 directory or an `.mcap`
/// file) and looks up its sensor pose in `fixed_frame` (default: the root of the first
/// cloud's frame tree at its stamp), and with `pose_topic` each view's pose prior
/// ([`pose_priors`]). Errors name the bag, the topic and the message index.
pub fn read_bag_views(
    bag: &Path,
    topic: &str,
    fixed_frame: Option<&str>,
    pose_topic: Option<&str>,
) -> Result<BagViews> {
    let reader = BagReader::open(bag).with_context(|| format!("opening bag {}", bag.display()))?;
    let Some(info) = reader.topic(topic) else {
        let topics: Vec<String> = reader
            .topics()
            .map(|t| format!("{} ({})", t.name, t.type_name))
            .collect();
        bail!(
            "{}: no topic {topic}; the bag has: {}",
            bag.display(),
            topics.join(", ")
        );
    };
    if info.type_name != "sensor_msgs/msg/PointCloud2" {
        bail!(
            "{}: topic {topic} is {}, not sensor_msgs/msg/PointCloud2",
            bag.display(),
            info.type_name
        );
    }
    let clouds = reader.point_clouds(topic)?;
    if clouds.is_empty() {
        bail!("{}: topic {topic} has no message", bag.display());
    }
    let tf = reader.tf_buffer()?;
    let fixed_frame = match fixed_frame {
        Some(f) => f.trim_start_matches('/').to_string(),
        None => root_frame(&tf, &clouds[0].header.frame_id, stamp(&clouds[0].header))
            .with_context(|| {
                format!(
                    "{}: topic {topic} message 0: finding the fixed frame (give it with --fixed-frame)",
                    bag.display()
                )
            })?,
    };
    let mut views = BagViews {
        names: Vec::new(),
        clouds: Vec::new(),
        poses: Vec::new(),
        fixed_frame,
        priors: None,
    };
    let stamps: Vec<i64> = clouds.iter().map(|c| stamp(&c.header)).collect();
    for cloud in clouds {
        let at = format!("{}: topic {topic} message {}", bag.display(), cloud.index);
        if cloud.points.is_empty() {
            bail!("{at}: the cloud has no finite point");
        }
        let pose = tf
            .lookup(
                &views.fixed_frame,
                &cloud.header.frame_id,
                stamp(&cloud.header),
            )
            .with_context(|| {
                format!(
                    "{at}: the pose of frame {:?} in {:?}",
                    cloud.header.frame_id, views.fixed_frame
                )
            })?;
        views.names.push(format!("{topic}#{}", cloud.index));
        views.clouds.push(PointCloud::from_points(cloud.points));
        views.poses.push(pose);
    }
    if let Some(pose_topic) = pose_topic {
        let at = format!("{}: topic {pose_topic}", bag.display());
        let messages = reader
            .read::<PoseWithCovarianceStamped>(pose_topic)
            .with_context(|| at.clone())?;
        let covariances: Vec<(i64, [f64; 36])> = messages
            .iter()
            .map(|(_, m)| (stamp(&m.header), m.pose.covariance))
            .collect();
        views.priors = Some(pose_priors(&covariances, &stamps).with_context(|| at)?);
    }
    Ok(views)
}

/// The pose prior of each view stamped at `stamps` (ns) from the sensor-pose covariances
/// `covariances` (stamp in ns, ROS's row-major 6 × 6: x, y, z, then rotations about x, y,
/// z): the latest covariance stamped at or before the view's (as a message filter's cache
/// answers), as an isotropic prior that covers it — σ of rotation and of translation the
/// square roots of each 3 × 3 block's largest eigenvalue. A view with no covariance before
/// it, or a covariance with no positive variance (ROS marks an unknown one by −1), is an
/// error naming its index.
///
pub fn pose_priors(covariances: &[(i64, [f64; 36])], stamps: &[i64]) -> Result<Vec<PosePrior>> {
    let mut sorted = covariances.to_vec();
    sorted.sort_by_key(|(t, _)| *t);
    stamps
        .iter()
        .enumerate()
        .map(|(k, &t)| {
            // The covariances stamped at or before `t` are a prefix of the sorted list.
            let before = sorted.partition_point(|(s, _)| *s <= t);
            let Some((_, cov)) = before.checked_sub(1).map(|i| &sorted[i]) else {
                bail!("view {k} (stamped {t} ns): no covariance stamped at or before it");
            };
            let m = Matrix6::from_row_slice(cov);
            let largest = |block: Matrix3<f64>| {
                block
                    .symmetric_eigenvalues()
                    .iter()
                    .copied()
                    .fold(f64::NAN, f64::max)
            };
            let translation = largest(m.fixed_view::<3, 3>(0, 0).into_owned());
            let rotation = largest(m.fixed_view::<3, 3>(3, 3).into_owned());
            if !(translation > 0.0 && rotation > 0.0 && m.iter().all(|v| v.is_finite())) {
                bail!(
                    "view {k} (stamped {t} ns): the covariance gives no uncertainty (largest \
                     translation variance {translation} m², rotation {rotation} rad²; ROS \
                     marks an unknown one by −1)"
                );
            }
            Ok(PosePrior {
                rotation_sigma: rotation.sqrt(),
                translation_sigma: translation.sqrt(),
            })
        })
        .collect()
}

/// A header's stamp in nanoseconds.
fn stamp(header: &nbv_bag::messages::Header) -> i64 {
    header.stamp.to_nanos()
}

/// The root of `frame`'s tree: the frame `frame` is looked up in until none has a parent
/// (the first frame of the buffer every other is expressed in).
fn root_frame(tf: &TfBuffer, frame: &str, t_ns: i64) -> Result<String> {
    let frame = frame.trim_start_matches('/');
    tf.frames()
        .into_iter()
        .filter(|&f| f != frame && tf.lookup(f, frame, t_ns).is_ok())
        .find(|&f| tf.is_root(f))
        .map(str::to_string)
        .with_context(|| {
            format!(
                "no frame of /tf or /tf_static reaches {frame:?} at {t_ns} ns (frames: {})",
                tf.frames().join(", ")
            )
        })
}

#[cfg(test)]
mod tests {
    use super::*;
    use nbv_bag::BagWriter;
    use nbv_bag::messages::{Header, TFMessage, Time, Transform, TransformStamped, Vector3};
    use nbv_bag::point_cloud::cloud_from_points;

    fn tf(parent: &str, child: &str, t_s: i32, x: f64) -> TFMessage {
        TFMessage {
            transforms: vec![TransformStamped {
                header: Header {
                    stamp: Time {
                        sec: t_s,
                        nanosec: 0,
                    },
                    frame_id: parent.into(),
                },
                child_frame_id: child.into(),
                transform: Transform {
                    translation: Vector3 { x, y: 0.0, z: 0.0 },
                    ..Default::default()
                },
            }],
        }
    }

    /// A diagonal covariance: translation variances 4, 1, 1 mm², rotation 1, 1, 4 ·10⁻⁴
    /// rad² (each block's largest: 2 mm, 0.02 rad).
    fn covariance(scale: f64) -> [f64; 36] {
        let mut cov = [0.0; 36];
        for (i, v) in [
            (0, 4e-6),
            (7, 1e-6),
            (14, 1e-6),
            (21, 1e-4),
            (28, 1e-4),
            (35, 4e-4),
        ] {
            cov[i] = v * scale;
        }
        cov
    }

    /// Each view takes the latest covariance at or before its stamp; none before it, or
    /// one ROS marks unknown, is an error naming the view.
    #[test]
    fn pose_priors_take_the_latest_covariance_and_name_what_is_missing() {
        let covs = [(20, covariance(4.0)), (10, covariance(1.0))];
        let p = pose_priors(&covs, &[10, 15, 20, 30]).unwrap();
        let sigmas: Vec<(f64, f64)> = p
            .iter()
            .map(|p| (p.translation_sigma, p.rotation_sigma))
            .collect();
        for (k, (t, r)) in sigmas.iter().enumerate() {
            let scale = if k < 2 { 1.0 } else { 2.0 };
            assert!((t - 0.002 * scale).abs() < 1e-12, "{sigmas:?}");
            assert!((r - 0.02 * scale).abs() < 1e-12, "{sigmas:?}");
        }
        let err = format!("{:#}", pose_priors(&covs, &[5]).unwrap_err());
        assert!(
            err.contains("view 0") && err.contains("no covariance"),
            "{err}"
        );
        let mut unknown = [0.0; 36];
        unknown[0] = -1.0;
        let err = format!("{:#}", pose_priors(&[(0, unknown)], &[1]).unwrap_err());
        assert!(
            err.contains("view 0") && err.contains("no uncertainty"),
            "{err}"
        );
    }

    /// Two clouds at 1.5 s and 2.5 s between /tf samples at 1, 2, 3 s (x = 1, 2, 3): the
    /// poses are x = 1.5 and 2.5 in `world`, the root found without --fixed-frame through
    /// a static `world → odom`; a cloud after the last sample is an error naming it.
    #[test]
    fn poses_interpolated_in_the_root_frame_and_extrapolation_named() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("scans");
        let mut w = BagWriter::create(&path).unwrap();
        w.write("/tf_static", 1, &tf("world", "odom", 0, 10.0))
            .unwrap();
        for t in 1..=3 {
            w.write(
                "/tf",
                u64::try_from(t).unwrap() * 1_000_000_000,
                &tf("odom", "sensor", t, f64::from(t)),
            )
            .unwrap();
        }
        for (k, ns) in [(0, 500_000_000u32), (1, 500_000_000)] {
            let header = Header {
                stamp: Time {
                    sec: 1 + k,
                    nanosec: ns,
                },
                frame_id: "sensor".into(),
            };
            let cloud = cloud_from_points(header, &[[0.0, 0.0, 1.0], [0.1, 0.0, 1.0]]);
            w.write("/points", 2_000_000_000, &cloud).unwrap();
        }
        w.finish().unwrap();
        let views = read_bag_views(&path, "/points", None, None).unwrap();
        assert_eq!(views.fixed_frame, "world");
        assert_eq!(views.names, ["/points#0", "/points#1"]);
        let xs: Vec<f64> = views.poses.iter().map(|p| p.translation.vector.x).collect();
        assert!(
            (xs[0] - 11.5).abs() < 1e-12 && (xs[1] - 12.5).abs() < 1e-12,
            "{xs:?}"
        );
        assert_eq!(views.clouds[1].len(), 2);

        let path2 = dir.path().join("late");
        let mut w = BagWriter::create(&path2).unwrap();
        w.write("/tf", 1, &tf("odom", "sensor", 1, 1.0)).unwrap();
        w.write("/tf", 2, &tf("odom", "sensor", 2, 2.0)).unwrap();
        let header = Header {
            stamp: Time { sec: 5, nanosec: 0 },
            frame_id: "sensor".into(),
        };
        w.write("/points", 3, &cloud_from_points(header, &[[0.0, 0.0, 1.0]]))
            .unwrap();
        w.finish().unwrap();
        let err = format!(
            "{:#}",
            read_bag_views(&path2, "/points", Some("odom"), None)
                .err()
                .unwrap()
        );
        assert!(err.contains("topic /points message 0"), "{err}");
        assert!(err.contains("future"), "{err}");
        let err = format!(
            "{:#}",
            read_bag_views(&path2, "/nothing", None, None)
                .err()
                .unwrap()
        );
        assert!(
            err.contains("no topic /nothing") && err.contains("/points"),
            "{err}"
        );
    }
}
