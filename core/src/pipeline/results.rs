//! What an exploration produced: [`Exploration`] with its phase-1 summary and one
//! [`ObjectExploration`] per object.

use super::ExploreMode;
use crate::cloud::PointCloud;
use crate::kinematics::Joints;
use crate::math::Pose;
use crate::nbv::{InformationGain, StopReason};
use crate::occupancy::{OccupancyGrid, ReducedMapStats, ScanUpdate};
use crate::perception::SegmentationCounts;
use crate::planning::PlanStats;
use crate::registration::{DepthImageFreeSpace, Registration, RegistrationError};

/// Wall-clock seconds per step (Table I of the paper); not part of the results' identity.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct StepTimes {
    /// Moving and scanning (sweep, or the moves to the views).
    pub motion: f64,
    /// Sensor data to clouds.
    pub acquisition: f64,
    /// Segmentation.
    pub segmentation: f64,
    /// Grid and reduced-map updates.
    pub mapping: f64,
    /// Viewpoint generation and O_v (Algorithm 2).
    pub nbv: f64,
    /// Motion planning.
    pub planning: f64,
    /// Registration (both methods).
    pub registration: f64,
    /// The fused surface: integration and extraction.
    pub meshing: f64,
}

impl StepTimes {
    /// Sum of the steps.
    pub fn total(&self) -> f64 {
        self.motion
            + self.acquisition
            + self.segmentation
            + self.mapping
            + self.nbv
            + self.planning
            + self.registration
            + self.meshing
    }

    /// Adds `other` step by step.
    pub fn add(&mut self, other: &StepTimes) {
        self.motion += other.motion;
        self.acquisition += other.acquisition;
        self.segmentation += other.segmentation;
        self.mapping += other.mapping;
        self.nbv += other.nbv;
        self.planning += other.planning;
        self.registration += other.registration;
        self.meshing += other.meshing;
    }
}

/// Phase 1 in numbers.
#[derive(Debug, Clone, PartialEq)]
pub struct PhaseOneReport {
    /// Scan lines of the sweep (0 in short-only mode).
    pub lines: usize,
    /// Camera frames of the short-only survey (0 otherwise).
    pub survey_frames: usize,
    /// Collisions the rig reported during the survey (the sweep's stop the run).
    pub collisions: usize,
    /// The phase-1 cloud P (world frame, reported poses, with origins): the laser sweep's,
    /// or the camera survey's in short-only mode.
    pub cloud: PointCloud,
    /// Segmentation counts.
    pub segmentation: SegmentationCounts,
    /// Clusters dropped as slivers of a known obstacle's face (not objects).
    pub slivers: Vec<crate::perception::ObstacleSliver>,
    /// The grid update.
    pub scan: ScanUpdate,
    /// The grid after phase 1.
    pub grid: OccupancyGrid,
    /// Its reduced map's statistics.
    pub reduced: ReducedMapStats,
    /// The sweep's pose correction from the known workcell (hybrid and mid-only, when
    /// [`ExploreConfig::align_to_workcell`](super::ExploreConfig::align_to_workcell)):
    /// `cloud` is already corrected by it when accepted.
    pub workcell: Option<crate::perception::WorkcellAlignment>,
    /// Times.
    pub times: StepTimes,
}

/// A short-range view that was taken.
#[derive(Debug, Clone, PartialEq)]
pub struct AcquiredView {
    /// The planned viewpoint's sensor pose.
    pub viewpoint: Pose,
    /// The objective's value G(v) of the viewpoint when chosen (eq. (4) by default).
    pub score: f64,
    /// |O_v| unknown and occupied when chosen.
    pub predicted: (usize, usize),
    /// The reported joints at acquisition.
    pub joints: Joints,
    /// The reported sensor pose at acquisition.
    pub sensor_pose: Pose,
    /// Points in the whole frame.
    pub frame_points: usize,
    /// The object's points of the frame (world frame, reported pose).
    pub cloud: PointCloud,
    /// Where the camera saw empty space (world frame, reported pose).
    pub free_space: DepthImageFreeSpace,
    /// The object's points of the frame smoothed for the registration
    /// ([`REGISTRATION_SMOOTHING`](super::REGISTRATION_SMOOTHING)), cut as `cloud`; `None`
    /// where the registration uses `cloud` (a frame `[nbv] depth_smoothing` smoothed).
    pub registration_cloud: Option<PointCloud>,
    /// Eq. (5) over O_v.
    pub gain: InformationGain,
    /// What the table around the object tells about the view's pose (the
    /// self-calibration's evidence beside the registration), when it is used.
    pub table: Option<crate::calibration::TableEvidence>,
    /// The planned path's statistics.
    pub plan: PlanStats,
    /// Viewpoints tried before this one succeeded (failures since the previous view).
    pub failures_before: usize,
    /// The new surface the view added: its points farther than 1 cm from the object's
    /// points before it, as a share of those ([`new_surface_share`](crate::nbv::new_surface_share)).
    pub new_surface: f64,
}

/// A viewpoint that could not be reached.
#[derive(Debug, Clone, PartialEq)]
pub struct ViewFailure {
    /// Its sensor pose.
    pub viewpoint: Pose,
    /// Why: the planner's or the rig's message.
    pub reason: String,
    /// Whether the rig reported a collision while executing the planned path.
    pub collision: bool,
}

/// Why an object's exploration ended.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ObjectStop {
    /// The stop rule (gain below threshold, or no viewpoint left).
    Rule(StopReason),
    /// The per-object view cap.
    MaxViews,
    /// Not explored (mid-only mode).
    NotExplored,
    /// Dropped: its first short-range view found (almost) no surface where phase 1 put
    /// it — fewer points than the smallest object cluster, in its region and outside the
    /// known obstacles. A cluster made by the sweep's pose error, not an object.
    NotAnObject {
        /// Points of the first view in the object's region.
        points: usize,
    },
}

impl std::fmt::Display for ObjectStop {
    /// Why the object's exploration ended, as the report and the progress line say it.
    ///
    /// ```
    /// use nbv_core::pipeline::ObjectStop;
    /// assert_eq!(ObjectStop::MaxViews.to_string(), "view cap reached");
    /// ```
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Rule(StopReason::LowGain { gain, threshold }) => {
                write!(f, "gain {gain:.3} below threshold {threshold}")
            }
            Self::Rule(StopReason::NoViewpoint) => write!(f, "no viewpoint left"),
            Self::Rule(StopReason::NoNewSurface {
                share,
                threshold,
                views,
            }) => write!(
                f,
                "the last {views} views added less than {:.1} % new surface (last {:.2} %)",
                100.0 * threshold,
                100.0 * share
            ),
            Self::Rule(StopReason::NoUnseenHull { share, threshold }) => write!(
                f,
                "the best view would see less than {:.1} % of the hull unseen ({:.2} %)",
                100.0 * threshold,
                100.0 * share
            ),
            Self::Rule(StopReason::RelativeGain { gain, first, ratio }) => write!(
                f,
                "best candidate's gain {gain:.3} below {ratio} of the first round's {first:.3}"
            ),
            Self::MaxViews => write!(f, "view cap reached"),
            Self::NotExplored => write!(f, "not explored (mid-only)"),
            Self::NotAnObject { points } => write!(
                f,
                "dropped, not an object: its first short-range view has {points} point(s) where phase 1 put it"
            ),
        }
    }
}

/// The registrations of an object's views (view 0 is the phase-1 cluster, the
/// reference), all from the same input.
#[derive(Debug, Clone, PartialEq)]
pub struct ObjectRegistration {
    /// The views as registered (subsampled, world frame through the reported poses; the
    /// camera views' points smoothed where the registration smooths its input).
    pub views: Vec<PointCloud>,
    /// The views' points as acquired, the model's, one cloud per view of `views`: every
    /// point of the cluster and of each exploration view (not subsampled), the
    /// calibration's views empty; moved by the same poses as `views`.
    pub points: Vec<PointCloud>,
    /// What the MAP registration was told of each view: its noise and prior.
    pub models: Vec<crate::registration::ViewModel>,
    /// The MAP registration: the model's.
    pub map: Registration,
    /// The initial poses of the MAP registration (corrections of the reported poses in
    /// the world frame): the identity in the first pass, the rig's self-calibration
    /// ([`HandEyeEstimate`](crate::calibration::HandEyeEstimate)) in a calibrated pass.
    pub map_initial: Vec<crate::math::Pose>,
    /// Whether [`map`](Self::map) is a calibrated pass (its priors centred on the
    /// self-calibrated poses).
    pub calibrated: bool,
    /// The paper's p-ICP-GPA (`None` unless the baselines were asked for:
    /// [`ExploreConfig::registration_baselines`](super::ExploreConfig::registration_baselines)).
    pub gpa: Option<Registration>,
    /// Sequential ICP (view h onto view h−1; `None` as [`gpa`](Self::gpa)).
    pub icp: Option<Registration>,
    /// Whether the MAP registration was accepted (converged, objective lowered).
    pub map_accepted: bool,
    /// Whether p-ICP-GPA ran and converged within the correction bound.
    pub gpa_accepted: bool,
    /// Whether sequential ICP ran and converged within the correction bound.
    pub icp_accepted: bool,
}

/// One object of the exploration.
#[derive(Debug, Clone, PartialEq)]
pub struct ObjectExploration {
    /// Index of the phase-1 cluster.
    pub index: usize,
    /// The phase-1 cluster P_j^0.
    pub cluster: PointCloud,
    /// The short-range views taken, in order.
    pub views: Vec<AcquiredView>,
    /// Viewpoints of `views` visited again for the self-calibration alone (each visit a
    /// standstill error of its own; `[registration] calibration_views`). They join the
    /// registration after `views` and are no part of the exploration's choice of views.
    pub calibration_views: Vec<AcquiredView>,
    /// Viewpoints that failed.
    pub failures: Vec<ViewFailure>,
    /// Candidate viewpoints evaluated (summed over the NBV rounds).
    pub candidates_evaluated: usize,
    /// Times the arm went back to the pose after the sweep because no viewpoint was
    /// reachable from where it was.
    pub retreats: usize,
    /// Why it ended.
    pub stop: ObjectStop,
    /// The registrations (`None` with no short-range view, or when registration failed).
    pub registration: Option<ObjectRegistration>,
    /// Why registration failed, if it did.
    pub registration_error: Option<String>,
    /// The fused surface of its registered camera views (`None` without a camera view,
    /// or when the scene's `[model] mesh` is off).
    pub surface: Option<crate::surface::SurfaceMesh>,
    /// Times.
    pub times: StepTimes,
}

impl ObjectExploration {
    /// The camera views the registration takes (those with points), in order — the
    /// exploration's, then the calibration's: registration view `k ≥ 1` is the `k`-th of
    /// them (view 0 is the cluster).
    pub fn registered_views(&self) -> impl Iterator<Item = &AcquiredView> {
        self.explored_views().chain(
            self.calibration_views
                .iter()
                .filter(|v| !v.cloud.is_empty()),
        )
    }

    /// The exploration's camera views with points, in order: the first of
    /// [`registered_views`](Self::registered_views), the model's.
    pub fn explored_views(&self) -> impl Iterator<Item = &AcquiredView> {
        self.views.iter().filter(|v| !v.cloud.is_empty())
    }

    /// The exploration's camera views as depth images of their points, each at its
    /// registered camera pose (the MAP registration's, where it was accepted; else as
    /// reported), in the order of [`explored_views`](Self::explored_views).
    pub fn depth_views(
        &self,
        intrinsics: crate::surface::PinholeIntrinsics,
    ) -> Vec<crate::surface::DepthView> {
        let poses = self
            .registration
            .as_ref()
            .filter(|r| r.map_accepted && r.map.poses.len() == r.points.len());
        self.explored_views()
            .enumerate()
            .map(|(k, v)| {
                let mut view = crate::surface::DepthView::from_points(
                    intrinsics,
                    v.sensor_pose,
                    &v.cloud.points,
                );
                if let Some(r) = poses {
                    view.pose = r.map.poses[k + 1] * v.sensor_pose;
                }
                view
            })
            .collect()
    }

    /// The object's model: its views merged through the MAP registration's poses, with a
    /// `views` column; the views as acquired when the registration was rejected
    /// ([`ObjectRegistration::map_accepted`]); the cluster alone when there was nothing
    /// to register. An error when the registration holds a pose count other than its
    /// views' ([`Registration::merged`]).
    pub fn model(&self) -> Result<PointCloud, RegistrationError> {
        match &self.registration {
            Some(r) if !r.map_accepted => Ok(self.unregistered_model()),
            Some(r) => r.map.merged(&r.points),
            None => Ok(self.cluster.clone()),
        }
    }

    /// The model by the paper's p-ICP-GPA (as acquired when it was rejected; `None` when
    /// it did not run); errors as [`model`](Self::model).
    pub fn gpa_model(&self) -> Result<Option<PointCloud>, RegistrationError> {
        self.baseline_model(|r| r.gpa.as_ref().map(|g| (g, r.gpa_accepted)))
    }

    /// The model by the sequential ICP baseline (as acquired when it was rejected; `None`
    /// when it did not run); errors as [`model`](Self::model).
    pub fn icp_model(&self) -> Result<Option<PointCloud>, RegistrationError> {
        self.baseline_model(|r| r.icp.as_ref().map(|g| (g, r.icp_accepted)))
    }

    fn baseline_model(
        &self,
        pick: impl Fn(&ObjectRegistration) -> Option<(&Registration, bool)>,
    ) -> Result<Option<PointCloud>, RegistrationError> {
        let Some(r) = &self.registration else {
            return Ok(Some(self.cluster.clone()));
        };
        match pick(r) {
            None => Ok(None),
            Some((registration, true)) => registration.merged(&r.points).map(Some),
            Some((_, false)) => Ok(Some(self.unregistered_model())),
        }
    }

    /// The views as acquired, before registration, with a `views` column.
    pub fn unregistered_model(&self) -> PointCloud {
        match &self.registration {
            Some(r) => {
                let mut out = PointCloud::default();
                for (k, v) in r.points.iter().enumerate() {
                    let mut v = v.clone();
                    v.views = Some(vec![k as u32; v.len()]);
                    out.extend(&v);
                }
                out
            }
            None => self.cluster.clone(),
        }
    }
}

/// The whole exploration.
#[derive(Debug, Clone, PartialEq)]
pub struct Exploration {
    /// The mode it ran in.
    pub mode: ExploreMode,
    /// Phase 1.
    pub phase_one: PhaseOneReport,
    /// The objects, in cluster order.
    pub objects: Vec<ObjectExploration>,
    /// The grid at the end.
    pub grid: OccupancyGrid,
    /// Collisions the rig reported while executing planned paths.
    pub collisions: usize,
    /// The depth camera's hand-eye correction estimated from all objects' registrations.
    pub hand_eye: Option<crate::calibration::HandEyeEstimate>,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::registration::{MethodReport, SequentialIcpReport};
    use nalgebra::Point3;

    fn registration(poses: usize) -> Registration {
        Registration {
            poses: vec![Pose::identity(); poses],
            converged: true,
            rms: None,
            report: MethodReport::SequentialIcp(SequentialIcpReport { pairs: Vec::new() }),
        }
    }

    fn object(map_poses: usize) -> ObjectExploration {
        let view = PointCloud::from_points(vec![Point3::new(0.0, 0.0, 0.1)]);
        ObjectExploration {
            index: 0,
            cluster: view.clone(),
            views: Vec::new(),
            calibration_views: Vec::new(),
            failures: Vec::new(),
            candidates_evaluated: 0,
            retreats: 0,
            stop: ObjectStop::NotExplored,
            registration: Some(ObjectRegistration {
                views: vec![view.clone(); 2],
                points: vec![view; 2],
                models: Vec::new(),
                map: registration(map_poses),
                map_initial: Vec::new(),
                calibrated: false,
                gpa: Some(registration(1)),
                icp: None,
                map_accepted: true,
                gpa_accepted: true,
                icp_accepted: false,
            }),
            registration_error: None,
            surface: None,
            times: StepTimes::default(),
        }
    }

    #[test]
    fn a_registration_without_a_pose_per_view_is_an_error_not_the_cluster() {
        let whole = object(2);
        assert_eq!(whole.model().unwrap().len(), 2);
        assert_eq!(whole.icp_model().unwrap(), None);
        // p-ICP-GPA holds one pose for two views.
        assert!(matches!(
            whole.gpa_model(),
            Err(RegistrationError::PoseCountMismatch { views: 2, poses: 1 })
        ));
        assert!(matches!(
            object(3).model(),
            Err(RegistrationError::PoseCountMismatch { views: 2, poses: 3 })
        ));
    }
}
