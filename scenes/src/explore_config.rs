//! The scene as the pipeline's whole configuration: [`Scene::explore_config`] gathers
//! phase 1, the sweep, `[nbv]`, `[planner]`, `[registration]`, the table and the known
//! obstacles (as the planner's obstacles) and the seed into an [`ExploreConfig`].

use crate::error::{Problem, SceneError};
use crate::scene::Scene;
use nbv_core::calibration::PoseUncertainty;
use nbv_core::kinematics::Joints;
use nbv_core::nbv::VisitedViews;
use nbv_core::perception::TableFilter;
use nbv_core::pipeline::{ExploreConfig, ExploreMode, ObjectRegion, SURVEY_HEIGHT, SURVEY_SPACING};
use nbv_core::planning::{Obstacle, ObstacleShape, PlannerConfig};
use nbv_core::registration::{MapParams, PosePrior, RangeNoise, RegistrationParams};

/// Distance (m) from each joint's axis to the sensors, roughly, over the arm's working
/// poses: a joint offset of δ rad moves the sensors by about δ times this.
pub const JOINT_LEVERS: [f64; 6] = [1.2, 1.0, 0.7, 0.2, 0.2, 0.1];

impl Scene {
    /// The short-only survey: the camera looking straight down from [`SURVEY_HEIGHT`] above
    /// the table top, over a grid of cells at most [`SURVEY_SPACING`] wide covering the part
    /// of the table inside the workspace, row by row (x, then y, boustrophedon).
    ///
    /// ```
    /// let scene = nbv_scenes::builtin::load("paper-env1").unwrap();
    /// let survey = scene.survey_poses();
    /// assert_eq!(survey.len(), 12); // 3 x 4 cells over the 1.0 x 1.4 m table
    /// assert!(survey.iter().all(|p| (p.translation.z - 0.70).abs() < 1e-9));
    /// ```
    pub fn survey_poses(&self) -> Vec<nbv_core::math::Pose> {
        let (w, t) = (&self.workspace, &self.table);
        let lo = [t.min[0].max(w.min[0]), t.min[1].max(w.min[1])];
        let hi = [t.max[0].min(w.max[0]), t.max[1].min(w.max[1])];
        let cells = |k: usize| ((hi[k] - lo[k]) / SURVEY_SPACING).ceil().max(1.0) as usize;
        let (nx, ny) = (cells(0), cells(1));
        let mut poses = Vec::with_capacity(nx * ny);
        for i in 0..nx {
            for jj in 0..ny {
                let j = if i % 2 == 0 { jj } else { ny - 1 - jj };
                let x = lo[0] + (hi[0] - lo[0]) * (i as f64 + 0.5) / nx as f64;
                let y = lo[1] + (hi[1] - lo[1]) * (j as f64 + 0.5) / ny as f64;
                let below = nalgebra::Point3::new(x, y, t.top());
                poses.push(nbv_core::nbv::view_pose(&below, SURVEY_HEIGHT, 0.0, 0.0));
            }
        }
        poses
    }

    /// The rig's sensor noise and pose uncertainty as the scene's `[sensors]` and
    /// `[errors]` state them (its `scale` applied), for the MAP registration.
    ///
    /// Per component: the hand-eye error's components are taken as σ (σ² = |xyz|²/3 and
    /// |rpy|²/3), the reported pose's noise as stated (its rotation, an angle about a random
    /// axis, spread over three components; one draw per standstill, so the frames of a
    /// burst do not average it); each joint offset turns the sensor by itself and moves it
    /// by itself times the joint's lever to the sensor ([`JOINT_LEVERS`]); every joint's
    /// σ is the RMS of the stated offsets. A floor of 0.1 mm and 0.006° keeps a scene
    /// without errors well posed.
    pub fn pose_uncertainty(&self) -> PoseUncertainty {
        let e = &self.errors;
        let sq = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>();
        let (xyz, rpy) = e.scaled_hand_eye();
        let (noise_t, noise_r) = e.scaled_pose_noise();
        let joints = e.scaled_joint_offsets();
        let joint_r = sq(&joints) / 3.0;
        let joint_t = joints
            .iter()
            .zip(JOINT_LEVERS)
            .map(|(q, l)| (q * l).powi(2))
            .sum::<f64>()
            / 3.0;
        let prior = |r2: f64, t2: f64| PosePrior {
            rotation_sigma: r2.sqrt().max(1e-4),
            translation_sigma: t2.sqrt().max(1e-4),
        };
        let n = &self.sensors.short_range.noise;
        PoseUncertainty {
            laser_noise: RangeNoise::constant(self.sensors.mid_range.noise.range_sigma.max(1e-5)),
            camera_noise: RangeNoise {
                sigma_at_1m: n.range_sigma_at_1m.max(1e-5),
                exponent: n.range_sigma_exponent,
            },
            laser_pose: prior(
                noise_r * noise_r / 3.0 + joint_r,
                noise_t * noise_t + joint_t,
            ),
            camera_pose: prior(
                sq(&rpy) / 3.0 + noise_r * noise_r / 3.0 + joint_r,
                sq(&xyz) / 3.0 + noise_t * noise_t + joint_t,
            ),
            hand_eye: prior(sq(&rpy) / 3.0, sq(&xyz) / 3.0),
            joint_offset_sigma: (sq(&joints) / joints.len().max(1) as f64).sqrt().max(1e-5),
            view_noise: prior(noise_r * noise_r / 3.0, noise_t * noise_t),
        }
    }

    /// The camera's noise model, averaged over `[nbv] frames_per_view` frames, as the
    /// pipeline's [`TableFilter`] of the short-range views.
    pub fn table_filter(&self) -> TableFilter {
        let n = &self.sensors.short_range.noise;
        TableFilter::for_camera(
            n.range_sigma_at_1m / f64::from(self.nbv.frames_per_view.max(1)).sqrt(),
            n.range_sigma_exponent,
        )
    }

    /// The pipeline's configuration for this scene in `mode`.
    ///
    /// ```
    /// use nbv_core::pipeline::ExploreMode;
    /// let scene = nbv_scenes::builtin::load("paper-env1").unwrap();
    /// let c = scene.explore_config(ExploreMode::Hybrid).unwrap();
    /// assert_eq!(c.phase_one.grid.len(), 126_000);
    /// assert_eq!(c.obstacles.len(), 3); // the table, the back panel and the crate
    /// assert_eq!(c.seed, scene.seed);
    /// ```
    pub fn explore_config(&self, mode: ExploreMode) -> Result<ExploreConfig, SceneError> {
        let mut phase_one = self.phase_one_config()?;
        if mode == ExploreMode::ShortOnly {
            // The survey's cloud is the camera's: the table plane and the clusters are
            // found at its noise (2σ at the survey height), on a 1 cm voxel filter.
            let n = &self.sensors.short_range.noise;
            let sigma = n.range_sigma_at_1m * SURVEY_HEIGHT.powf(n.range_sigma_exponent);
            let seg = &mut phase_one.segmentation;
            seg.plane_distance = seg.plane_distance.max(2.0 * sigma);
            seg.voxel = seg.voxel.max(0.01);
        }
        let mut obstacles = Vec::new();
        let t = &self.table;
        let centre = [
            (t.min[0] + t.max[0]) / 2.0,
            (t.min[1] + t.max[1]) / 2.0,
            (t.min[2] + t.max[2]) / 2.0,
        ];
        let half = [
            (t.max[0] - t.min[0]) / 2.0,
            (t.max[1] - t.min[1]) / 2.0,
            (t.max[2] - t.min[2]) / 2.0,
        ];
        obstacles.push(Obstacle::cuboid("table", centre, half));
        // The planner gets each known obstacle's box: a link can never end up inside it.
        for (name, pose, half) in self.known_obstacle_boxes()? {
            obstacles.push(Obstacle {
                name,
                shape: ObstacleShape::Cuboid {
                    half_extents: [half.x, half.y, half.z],
                },
                pose,
            });
        }
        let planner = PlannerConfig {
            max_iterations: self.planner.max_iterations as usize,
            step: self.planner.step_rad,
            shortcut_iterations: self.planner.shortcut_iterations as usize,
            // No point of the robot moves more than half a voxel between two checks.
            max_link_displacement: self.workspace.resolution / 2.0,
            ..PlannerConfig::default()
        };
        planner.validate().map_err(|e| SceneError::Invalid {
            file: self.file(),
            key: "planner".into(),
            problem: Box::new(Problem::OutOfRange {
                value: format!("{:?}", self.planner),
                expected: e.to_string(),
            }),
        })?;
        let sweep = self
            .sweep
            .waypoints_deg
            .iter()
            .map(|w| Joints::from_iterator(w.iter().map(|d| d.to_radians())))
            .collect();
        Ok(ExploreConfig {
            mode,
            survey: self.survey_poses(),
            sweep,
            sweep_speed: self.sweep.joint_speed_fraction,
            phase_one,
            nbv: self.nbv.params(),
            stop: self.nbv.stop_rule(),
            visited: (self.nbv.visited_min_distance, VisitedViews::default().angle),
            max_views_per_object: self.nbv.max_views_per_object as usize,
            frames_per_view: self.nbv.frames_per_view as usize,
            return_share: self.nbv.return_share,
            depth_smoothing: self.nbv.depth_smoothing as usize,
            no_return_clearing: self.mapping.no_return_clearing,
            planner,
            obstacles,
            registration: RegistrationParams {
                max_correspondence_distance: self.registration.d_max,
                max_iterations: self.registration.max_iterations as usize,
                tolerance: self.registration.tolerance,
                // The camera views go into the laser cluster only: at the Dinast's
                // centimetre noise, view-to-view terms pull them off (`MapParams`).
                map: MapParams {
                    view_to_view: false,
                    ..MapParams::default()
                },
                ..RegistrationParams::default()
            },
            uncertainty: self.pose_uncertainty(),
            align_to_workcell: self.registration.align_to_workcell,
            calibrate_hand_eye: self.registration.calibrate_hand_eye,
            calibration_views: self.registration.calibration_views as usize,
            registration_baselines: self.registration.baselines,
            registration_points: self.registration.points_per_view as usize,
            max_correction: (
                self.registration.max_correction_deg.to_radians(),
                self.registration.max_correction_m,
            ),
            object_margin: ObjectRegion::MARGIN,
            table_filter: Some(self.table_filter()),
            surface: self.model.params(),
            seed: self.seed,
        })
    }
}
