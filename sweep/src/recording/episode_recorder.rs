//! [`EpisodeRecorder`]: an episode's pipeline events into `episode.rrd`, and
//! [`RecordingTee`], which hands each event to another observer first.

use super::entity;
use super::palette::{categorical, ramp, rgba};
use super::robot_links::{RobotLinks, f32x3, transform};
use crate::error::{Context, Result, SweepError};
use crate::report::ExploreReport;
use nbv_core::cloud::PointCloud;
use nbv_core::kinematics::Robot;
use nbv_core::occupancy::{OccupancyGrid, ReducedMap};
use nbv_core::pipeline::{Exploration, ExploreEvent, ExploreObserver, ObjectExploration};
use nbv_core::rig::{DepthCameraSpec, Motion, ScanLine};
use nbv_scenes::Scene;
use nbv_sim::render::{OBSTACLE_COLOR, TABLE_COLOR, UNKNOWN_OBSTACLE_COLOR, object_color};
use rerun::RecordingStream;
use std::path::{Path, PathBuf};

/// The recording's file name in an episode's output directory.
pub const FILE_NAME: &str = "episode.rrd";
/// Batches the phase-1 cloud grows in (each a separate entity that stays once logged).
const SWEEP_BATCHES: usize = 40;
/// Rig seconds between two logged robot poses of a motion (the last sample always is).
const POSE_INTERVAL: f64 = 0.05;
/// Joint-space points per planned-path segment drawn as the camera's path.
const PATH_SUBDIVISIONS: usize = 8;
/// Distance (m) of the camera frustum's image plane.
const FRUSTUM_DEPTH: f32 = 0.12;

/// Records one episode: create it before the exploration (it logs the scene and the
/// robot), let it observe the exploration ([`observe`](Self::observe)), then
/// [`finish`](Self::finish) it with the report.
///
/// ```no_run
/// # fn demo(scene: &nbv_scenes::Scene) -> nbv_sweep::Result<()> {
/// use nbv_sweep::recording::EpisodeRecorder;
/// use nbv_sweep::episode::Outputs;
/// let out = std::path::Path::new("run");
/// let mut recorder = EpisodeRecorder::create(out, scene)?;
/// let mut progress = nbv_core::pipeline::NoObserver;
/// let (config, exploration) = nbv_sweep::episode::explore_in_twin(
///     scene,
///     nbv_core::pipeline::ExploreMode::Hybrid,
///     &mut recorder.observe(&mut progress),
/// )?;
/// let report = nbv_sweep::episode::finish_episode(scene, &config, &exploration, out, false, None, Outputs::All)?;
/// let file = recorder.finish(scene, &exploration, &report)?;
/// assert!(file.ends_with("episode.rrd"));
/// # Ok(()) }
/// ```
pub struct EpisodeRecorder {
    rec: RecordingStream,
    temporary: PathBuf,
    path: PathBuf,
    robot: RobotLinks,
    camera: DepthCameraSpec,
    /// Index of the current event.
    step: i64,
    /// The rig's clock as last reported (seconds).
    now: f64,
    /// Per object: when each view was taken (rig seconds, step).
    view_times: Vec<Vec<(f64, i64)>>,
    /// Per object: when its exploration started.
    started: Vec<(f64, i64)>,
    /// Per object: the viewpoints that failed (positions).
    failed: Vec<Vec<[f32; 3]>>,
    /// The first logging error (events cannot return one).
    error: Option<SweepError>,
}

impl EpisodeRecorder {
    /// Starts `out/episode.rrd` (written to a temporary file until
    /// [`finish`](Self::finish)) with the scene's table, obstacles and objects and the
    /// robot's links at its home configuration.
    pub fn create(out: &Path, scene: &Scene) -> Result<Self> {
        std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
        let path = out.join(FILE_NAME);
        let temporary = out.join(format!(".{FILE_NAME}.partial"));
        let rec = rerun::RecordingStreamBuilder::new("nbv-twin")
            .recording_id(format!("{}-seed-{}", scene.name, scene.seed))
            .enabled(true)
            .save(&temporary)
            .with_context(|| format!("creating {}", temporary.display()))?;
        rec.set_log_time_enabled(false);
        super::layout::send(&rec).context("sending the viewer's layout")?;
        rec.log_static(entity::WORLD, &rerun::ViewCoordinates::RIGHT_HAND_Z_UP())
            .context("starting the recording")?;
        log_scene(&rec, scene)?;
        let robot = Robot::from_urdf_file(&scene.robot.urdf)
            .with_context(|| format!("reading {}", scene.robot.urdf.display()))?;
        let urdf_dir = scene
            .robot
            .urdf
            .parent()
            .map_or_else(|| PathBuf::from("."), Path::to_path_buf);
        let robot = RobotLinks::log_static(&rec, robot, scene.robot.base.to_pose(), &urdf_dir)?;
        let recorder = Self {
            rec,
            temporary,
            path,
            robot,
            camera: scene.sensors.short_range.spec(),
            step: 0,
            now: 0.0,
            view_times: Vec::new(),
            started: Vec::new(),
            failed: Vec::new(),
            error: None,
        };
        recorder.set_time();
        recorder
            .robot
            .log_joints(&recorder.rec, &nbv_sim::world::home_configuration(scene))?;
        Ok(recorder)
    }

    /// An observer that gives each event to `inner` (the progress bars), then records it.
    pub fn observe<'a>(&'a mut self, inner: &'a mut dyn ExploreObserver) -> RecordingTee<'a> {
        RecordingTee {
            recorder: self,
            inner,
        }
    }

    /// Logs the report's coverage of each object after each view (the views as acquired),
    /// each object's fused surface (`world/models/<j>/mesh`) and the report's summary, then closes the file and moves it to `episode.rrd`. Returns its
    /// path.
    pub fn finish(
        mut self,
        scene: &Scene,
        exploration: &Exploration,
        report: &ExploreReport,
    ) -> Result<PathBuf> {
        if let Some(e) = self.error.take() {
            return Err(e);
        }
        let meshes = scene.object_meshes()?;
        for (object, entry) in exploration.objects.iter().zip(&report.objects) {
            let Some(i) = scene.objects.iter().position(|o| o.name == entry.name) else {
                continue;
            };
            let j = object.index;
            let mut seen = object.cluster.clone();
            let mut points = self.started.get(j).copied().into_iter().collect::<Vec<_>>();
            points.extend(self.view_times.get(j).into_iter().flatten().copied());
            for (k, (time, step)) in points.into_iter().enumerate() {
                if k > 0 {
                    let Some(view) = object.views.get(k - 1) else {
                        break;
                    };
                    seen.extend(&view.cloud);
                }
                self.rec.set_duration_secs(entity::SIM_TIME, time);
                self.rec.set_time_sequence(entity::STEP, step);
                let share = crate::report::coverage(scene, &meshes[i], &seen);
                self.rec
                    .log(entity::plot("coverage", j), &rerun::Scalars::single(share))
                    .context("logging the coverage")?;
            }
        }
        self.step += 1;
        self.set_time();
        // Each object's fused surface beside its point model.
        for object in &exploration.objects {
            if let Some(surface) = &object.surface {
                let m = &surface.mesh;
                self.rec
                    .log(
                        entity::model(object.index, "mesh"),
                        &rerun::Mesh3D::new(m.vertices.iter().map(|p| f32x3(p.coords)))
                            .with_vertex_normals(surface.normals.iter().map(|n| f32x3(*n)))
                            .with_triangle_indices(m.triangles.iter().copied())
                            .with_albedo_factor(categorical(0)),
                    )
                    .context("logging a fused surface")?;
            }
        }
        self.rec
            .log(
                "report",
                &rerun::TextDocument::from_markdown(summary(report)),
            )
            .context("logging the report")?;
        self.text(rerun::TextLogLevel::INFO, "episode finished")?;
        self.rec
            .flush_blocking()
            .context("flushing the recording")?;
        let Self {
            rec,
            temporary,
            path,
            ..
        } = self;
        // The footer is written when the last handle of the stream is dropped.
        drop(rec);
        std::fs::rename(&temporary, &path)
            .with_context(|| format!("moving {} to {}", temporary.display(), path.display()))?;
        Ok(path)
    }

    fn set_time(&self) {
        self.rec.set_duration_secs(entity::SIM_TIME, self.now);
        self.rec.set_time_sequence(entity::STEP, self.step);
    }

    fn text(&self, level: &str, text: impl Into<String>) -> Result<()> {
        self.rec
            .log(
                entity::LOG,
                &rerun::TextLog::new(text.into()).with_level(level),
            )
            .context("logging a decision")
    }

    fn record(&mut self, event: &ExploreEvent<'_>) -> Result<()> {
        use rerun::TextLogLevel as L;
        self.step += 1;
        self.set_time();
        match event {
            ExploreEvent::SweepStarted { waypoints } => {
                self.text(
                    L::INFO,
                    format!("phase 1: sweep through {waypoints} waypoints"),
                )?;
            }
            ExploreEvent::Moved { motion } => self.log_motion(motion)?,
            ExploreEvent::SweepCloud { lines, cloud } => self.log_sweep(lines, cloud)?,
            ExploreEvent::SweepDone { lines, points } => {
                self.text(
                    L::INFO,
                    format!("phase 1: {lines} scan lines, {points} points"),
                )?;
            }
            ExploreEvent::Segmented { objects } => {
                self.text(L::INFO, format!("phase 1: {objects} object cluster(s)"))?;
            }
            ExploreEvent::GridUpdated { grid } => self.log_grid(grid)?,
            ExploreEvent::ObjectStarted { object, cluster } => {
                let j = *object;
                grow(&mut self.started, j, (0.0, 0));
                self.started[j] = (self.now, self.step);
                self.rec
                    .log(
                        format!("{}/{j}", entity::CLUSTERS),
                        &points(cluster).with_colors([categorical(j)]),
                    )
                    .context("logging a cluster")?;
                self.text(L::INFO, format!("object {j}: exploring"))?;
            }
            ExploreEvent::Candidates {
                object,
                candidates,
                list,
            } => {
                let scores: Vec<f64> = list.candidates.iter().map(|c| c.score).collect();
                let (lo, hi) = scores
                    .iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), s| {
                        (a.min(*s), b.max(*s))
                    });
                let span = if hi > lo { hi - lo } else { 1.0 };
                let positions: Vec<[f32; 3]> = list
                    .candidates
                    .iter()
                    .map(|c| f32x3(c.viewpoint.pose.translation.vector))
                    .collect();
                let labels: Vec<String> = scores.iter().map(|s| format!("{s:.1}")).collect();
                self.rec
                    .log(
                        entity::object(*object, "candidates"),
                        &rerun::Points3D::new(positions)
                            .with_colors(scores.iter().map(|s| ramp((s - lo) / span)))
                            .with_radii([0.008f32])
                            .with_labels(labels)
                            .with_show_labels(false),
                    )
                    .context("logging the candidates")?;
                let best = scores
                    .first()
                    .map_or(String::new(), |s| format!(", best score {s:.1} (eq. 4)"));
                self.text(
                    L::INFO,
                    format!("object {object}: {candidates} candidate viewpoints{best}"),
                )?;
            }
            ExploreEvent::ViewFailed {
                object,
                reason,
                viewpoint,
            } => {
                grow(&mut self.failed, *object, Vec::new());
                self.failed[*object].push(f32x3(viewpoint.translation.vector));
                self.rec
                    .log(
                        entity::object(*object, "failed"),
                        &rerun::Points3D::new(self.failed[*object].iter().copied())
                            .with_colors([[200u8, 0, 0, 255]])
                            .with_radii([0.012f32]),
                    )
                    .context("logging a failed viewpoint")?;
                self.text(
                    L::WARN,
                    format!("object {object}: viewpoint failed: {reason}"),
                )?;
            }
            ExploreEvent::ViewTaken { .. } => self.log_view(event)?,
            ExploreEvent::Retreated { object } => {
                self.text(
                    L::WARN,
                    format!(
                        "object {object}: no viewpoint reachable; retreating along the executed paths"
                    ),
                )?;
            }
            ExploreEvent::ObjectDone { object, stop, .. } => {
                self.text(L::INFO, format!("object {object}: stopped: {stop:?}"))?;
            }
            ExploreEvent::Registered {
                object,
                exploration,
            } => self.log_models(*object, exploration)?,
        }
        Ok(())
    }

    fn log_motion(&mut self, motion: &Motion) -> Result<()> {
        let mut last_logged = f64::NEG_INFINITY;
        for (k, s) in motion.samples.iter().enumerate() {
            let is_last = k + 1 == motion.samples.len();
            if s.time - last_logged < POSE_INTERVAL && !is_last {
                continue;
            }
            last_logged = s.time;
            self.rec.set_duration_secs(entity::SIM_TIME, s.time);
            self.robot.log_joints(&self.rec, &s.joints)?;
        }
        if let Some(s) = motion.samples.last() {
            self.now = s.time;
        }
        self.set_time();
        Ok(())
    }

    fn log_sweep(&mut self, lines: &[ScanLine], cloud: &PointCloud) -> Result<()> {
        let counts: Vec<usize> = lines
            .iter()
            .map(|l| {
                (0..l.ranges.len())
                    .filter(|i| l.point(*i).is_some())
                    .count()
            })
            .collect();
        if counts.iter().sum::<usize>() != cloud.len() {
            // Not line by line: the cloud at once.
            return self
                .rec
                .log(entity::sweep_cloud(0), &points(cloud).with_colors([SWEEP]))
                .context("logging the sweep");
        }
        let per_batch = lines.len().div_ceil(SWEEP_BATCHES).max(1);
        let mut start = 0;
        let mut batch_start = 0;
        for (k, (line, n)) in lines.iter().zip(&counts).enumerate() {
            let these = &cloud.points[start..start + n];
            start += n;
            self.rec.set_duration_secs(entity::SIM_TIME, line.time);
            self.rec
                .log(
                    entity::SWEEP_LINE,
                    &rerun::Points3D::new(these.iter().map(|p| f32x3(p.coords)))
                        .with_colors([[255u8, 40, 40, 255]])
                        .with_radii([0.004f32]),
                )
                .context("logging a scan line")?;
            if (k + 1) % per_batch == 0 || k + 1 == lines.len() {
                let batch = &cloud.points[batch_start..start];
                self.rec
                    .log(
                        entity::sweep_cloud(k / per_batch),
                        &rerun::Points3D::new(batch.iter().map(|p| f32x3(p.coords)))
                            .with_colors([SWEEP])
                            .with_radii([0.002f32]),
                    )
                    .context("logging the sweep")?;
                batch_start = start;
            }
        }
        self.set_time();
        Ok(())
    }

    fn log_grid(&mut self, grid: &OccupancyGrid) -> Result<()> {
        let reduced = ReducedMap::from_grid(grid);
        let g = reduced.geometry();
        let half = 0.5 * g.resolution() as f32;
        let centres = |indices: &[usize]| -> Vec<[f32; 3]> {
            indices
                .iter()
                .filter_map(|i| g.unlinear(*i))
                .map(|v| g.center(v))
                .map(|c| f32x3(c.coords))
                .collect()
        };
        self.rec
            .log(
                entity::GRID_OCCUPIED,
                &rerun::Boxes3D::from_centers_and_half_sizes(
                    centres(reduced.occupied()),
                    [[half; 3]],
                )
                .with_colors([[90u8, 90, 100, 255]])
                .with_fill_mode(rerun::FillMode::Solid),
            )
            .context("logging the grid")?;
        self.rec
            .log(
                entity::GRID_UNKNOWN,
                &rerun::Boxes3D::from_centers_and_half_sizes(
                    centres(reduced.unknown()),
                    [[half; 3]],
                )
                .with_colors([[250u8, 160, 40, 90]])
                .with_fill_mode(rerun::FillMode::Solid),
            )
            .context("logging the grid")
    }

    /// A [`ExploreEvent::ViewTaken`]: the path, the camera, the frame, the view's points,
    /// the gain and the step times.
    fn log_view(&mut self, event: &ExploreEvent<'_>) -> Result<()> {
        let &ExploreEvent::ViewTaken {
            object: j,
            views: k,
            gain,
            view,
            path,
            frame,
            times,
        } = event
        else {
            return Ok(());
        };
        grow(&mut self.view_times, j, Vec::new());
        self.view_times[j].push((self.now, self.step));
        let robot = self.robot.robot();
        let camera_frame = self.camera.frame.as_str();
        let mut strip = Vec::new();
        for pair in path.waypoints.windows(2) {
            for s in 0..PATH_SUBDIVISIONS {
                let q = pair[0] + (pair[1] - pair[0]) * (s as f64 / PATH_SUBDIVISIONS as f64);
                if let Ok(p) = robot.fk(&q, camera_frame) {
                    strip.push(f32x3((self.robot.base() * p).translation.vector));
                }
            }
        }
        if let Some(q) = path.waypoints.last()
            && let Ok(p) = robot.fk(q, camera_frame)
        {
            strip.push(f32x3((self.robot.base() * p).translation.vector));
        }
        let log = |path: String, what: &dyn rerun::AsComponents| {
            self.rec.log(path, what).context("logging a view")
        };
        log(
            entity::object(j, "path"),
            &rerun::LineStrips3D::new([strip])
                .with_colors([categorical(k)])
                .with_radii([0.003f32]),
        )?;
        let cam = entity::object(j, "camera");
        log(cam.clone(), &transform(&view.sensor_pose))?;
        let focal = self.camera.focal() as f32;
        log(
            cam,
            &rerun::Pinhole::from_focal_length_and_resolution(
                [focal, focal],
                [self.camera.width as f32, self.camera.height as f32],
            )
            .with_image_plane_distance(FRUSTUM_DEPTH)
            .with_color(categorical(k)),
        )?;
        log(
            entity::object(j, "frame"),
            &points(frame).with_colors([[120u8, 170, 220, 255]]),
        )?;
        log(
            entity::view(j, k),
            &points(&view.cloud).with_colors([categorical(k)]),
        )?;
        log(entity::plot("gain", j), &rerun::Scalars::single(gain))?;
        for (name, seconds) in [
            ("motion", times.motion),
            ("acquisition", times.acquisition),
            ("mapping", times.mapping),
            ("nbv", times.nbv),
            ("planning", times.planning),
        ] {
            log(
                entity::plot(&format!("times/{name}"), j),
                &rerun::Scalars::single(seconds),
            )?;
        }
        self.text(
            rerun::TextLogLevel::INFO,
            format!(
                "object {j}: view {k} taken (score {:.1}, predicted unknown {} / occupied {}), gain {gain:.2}",
                view.score, view.predicted.0, view.predicted.1
            ),
        )
    }

    fn log_models(&mut self, j: usize, object: &ObjectExploration) -> Result<()> {
        for (which, model) in [
            ("before", object.unregistered_model()),
            ("after", object.model()?),
        ] {
            let colors: Vec<[u8; 4]> = match &model.views {
                Some(v) => v.iter().map(|k| categorical(*k as usize)).collect(),
                None => vec![categorical(0); model.len()],
            };
            self.rec
                .log(entity::model(j, which), &points(&model).with_colors(colors))
                .context("logging a model")?;
        }
        let outcome = match (&object.registration, &object.registration_error) {
            (Some(r), _) if r.map_accepted => "registered (MAP accepted)".to_owned(),
            (Some(_), _) => "registration rejected: the views as acquired".to_owned(),
            (None, Some(e)) => format!("registration failed: {e}"),
            (None, None) => "nothing to register".to_owned(),
        };
        self.text(rerun::TextLogLevel::INFO, format!("object {j}: {outcome}"))
    }
}

/// The colour of the phase-1 cloud.
const SWEEP: [u8; 4] = [150, 150, 150, 255];

/// A cloud's points, small.
fn points(cloud: &PointCloud) -> rerun::Points3D {
    rerun::Points3D::new(cloud.points.iter().map(|p| f32x3(p.coords))).with_radii([0.002f32])
}

/// Makes `v[i]` exist.
fn grow<T: Clone>(v: &mut Vec<T>, i: usize, fill: T) {
    if v.len() <= i {
        v.resize(i + 1, fill);
    }
}

/// The scene's table, obstacles and objects, static.
fn log_scene(rec: &RecordingStream, scene: &Scene) -> Result<()> {
    let mesh = |path: String, m: &nbv_core::mesh::TriMesh, color: [u8; 4]| {
        rec.log_static(
            path,
            &rerun::Mesh3D::new(m.vertices.iter().map(|p| f32x3(p.coords)))
                .with_triangle_indices(m.triangles.iter().copied())
                .with_albedo_factor(color),
        )
        .context("logging the scene")
    };
    mesh(
        "world/scene/table".into(),
        &nbv_scenes::placed::table_mesh(&scene.table),
        rgba(TABLE_COLOR),
    )?;
    for (i, (o, m)) in scene
        .obstacles
        .iter()
        .zip(scene.obstacle_meshes()?)
        .enumerate()
    {
        let color = if o.known {
            OBSTACLE_COLOR
        } else {
            UNKNOWN_OBSTACLE_COLOR
        };
        mesh(format!("world/scene/obstacles/{i}"), &m, rgba(color))?;
    }
    for (i, (o, m)) in scene.objects.iter().zip(scene.object_meshes()?).enumerate() {
        let mut c = rgba(object_color(i));
        c[3] = 80;
        mesh(format!("world/scene/objects/{}", o.name), &m, c)?;
    }
    Ok(())
}

/// The report in a few lines of Markdown.
fn summary(report: &ExploreReport) -> String {
    let mut s =
        String::from("| object | views | failed | coverage | stop |\n|---|---|---|---|---|\n");
    for o in &report.objects {
        s.push_str(&format!(
            "| {} | {} | {} | {} | {} |\n",
            o.name,
            o.views.len(),
            o.viewpoints_failed.len(),
            o.coverage
                .map_or("–".to_owned(), |c| format!("{:.0} %", 100.0 * c)),
            o.stop
        ));
    }
    s
}

/// An observer that gives each event to another observer, then to an
/// [`EpisodeRecorder`] ([`EpisodeRecorder::observe`]).
pub struct RecordingTee<'a> {
    recorder: &'a mut EpisodeRecorder,
    inner: &'a mut dyn ExploreObserver,
}

impl ExploreObserver for RecordingTee<'_> {
    fn event(&mut self, event: &ExploreEvent<'_>) {
        self.inner.event(event);
        if self.recorder.error.is_none()
            && let Err(e) = self.recorder.record(event)
        {
            self.recorder.error = Some(e);
        }
    }
}
