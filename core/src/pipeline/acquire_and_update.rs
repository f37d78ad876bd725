//! Acquire and update (Algorithm 1): a burst of depth frames at the viewpoint reached,
//! the frame into the grid (eq. (1)–(2)), the information gain over the voxels the view
//! was predicted to see (eq. (5)), the frame smoothed for the registration
//! ([`REGISTRATION_SMOOTHING`]) and where the camera saw empty space; and
//! [`object_points`], the object's points of a frame — cropped to its region, the table
//! and the known obstacles taken out.

use super::episode_state::Episode;
use super::step_timer::timed;
use super::{AcquiredView, ExplorationMap, ExploreConfig, ObjectRegion, PipelineError, StepTimes};
use crate::calibration::TableEvidence;
use crate::cloud::{PlaneFit, PointCloud};
use crate::kinematics::Joints;
use crate::math::Pose;
use crate::nbv::{Candidate, InformationGain};
use crate::occupancy::FreeRay;
use crate::perception::{OrientedBox, TableFilter};
use crate::planning::PlanStats;
use crate::registration::{DepthImageFreeSpace, RangeNoise};
use crate::rig::{
    DepthCamera, DepthCameraSpec, DepthFrame, Rig, RigError, average_frames, depth_frame_to_cloud,
    no_return_pixels, sensor_pose, smooth_frame,
};
use nalgebra::Point3;

/// Half-width (pixels) of the edge-gated plane fit ([`smooth_frame`]) that smooths each
/// view's averaged frame for the registration alone: the camera's noise along its rays
/// leaves registered views 1–3 mm too deep on curved objects, and the fit over 5 × 5
/// pixels takes most of it out (docs/registration.md). The grid and the model keep the
/// averaged frame's points; a frame already smoothed by `[nbv] depth_smoothing` is
/// registered as it is.
pub const REGISTRATION_SMOOTHING: usize = 2;

/// What one view added.
#[derive(Debug, Clone)]
pub(super) struct Observation {
    /// The reported joints at acquisition.
    pub joints: Joints,
    /// The reported sensor pose at acquisition.
    pub sensor_pose: Pose,
    /// Points in the whole frame.
    pub frame_points: usize,
    /// The whole frame (world frame).
    pub frame: PointCloud,
    /// Where the camera saw empty space (world frame at the reported pose).
    pub free_space: DepthImageFreeSpace,
    /// The whole frame smoothed for the registration (`None`: the registration uses the
    /// frame's points).
    pub smoothed: Option<PointCloud>,
    /// Eq. (5) over the predicted voxels.
    pub gain: InformationGain,
}

/// Acquires at the arm's pose and updates `map`; `predicted` are the voxels the view was
/// chosen for (the gain's domain).
pub(super) fn acquire_and_update(
    rig: &mut Rig<'_>,
    config: &ExploreConfig,
    map: &mut ExplorationMap,
    predicted: &[usize],
    times: &mut StepTimes,
) -> Result<Observation, PipelineError> {
    let (mut seen, free) = acquire(rig, config, times)?;
    seen.gain = timed(&mut times.mapping, || -> Result<_, PipelineError> {
        let before = map.grid.clone();
        map.insert(&seen.frame, rig.camera.spec().range[1], &free)?;
        Ok(InformationGain::between(&before, &map.grid, predicted)?)
    })?;
    Ok(seen)
}

/// Acquires at the arm's pose (timed as acquisition), the map left as it is: the view
/// (its gain zero) and the rays along which its pixels returned nothing.
pub(super) fn acquire(
    rig: &mut Rig<'_>,
    config: &ExploreConfig,
    times: &mut StepTimes,
) -> Result<(Observation, Vec<FreeRay>), PipelineError> {
    timed(&mut times.acquisition, || -> Result<_, PipelineError> {
        let (frame, no_return) = capture_burst(rig.camera, config)?;
        let joints = rig.arm.joints()?;
        let spec = rig.camera.spec();
        let pose = sensor_pose(&rig.robot, &rig.base, &joints, &spec.frame)?;
        let cloud = depth_frame_to_cloud(&frame, spec, &pose)?;
        let free = free_rays(&no_return, spec, &pose, config.no_return_clearing);
        let noise = config
            .uncertainty
            .camera_noise
            .averaged(config.frames_per_view.max(1));
        let free_space = camera_free_space(&frame, spec, &pose, noise)?;
        // The frame smoothed for the registration alone.
        let smoothed = (config.depth_smoothing == 0)
            .then(|| {
                let smoothed =
                    smooth_frame(frame.clone(), REGISTRATION_SMOOTHING, |z| noise.sigma(z));
                depth_frame_to_cloud(&smoothed, spec, &pose)
            })
            .transpose()?;
        let seen = Observation {
            joints,
            sensor_pose: pose,
            frame_points: cloud.len(),
            frame: cloud,
            free_space,
            smoothed,
            gain: InformationGain::default(),
        };
        Ok((seen, free))
    })
}

/// Where the camera at `pose` saw empty space in `frame`: in front of each pixel's return
/// by three of the frame's σ (`noise`: the averaged burst's).
fn camera_free_space(
    frame: &DepthFrame,
    spec: &DepthCameraSpec,
    pose: &Pose,
    noise: RangeNoise,
) -> Result<DepthImageFreeSpace, PipelineError> {
    Ok(DepthImageFreeSpace::new(
        *pose,
        spec.focal(),
        spec.width,
        spec.height,
        &frame.depth,
        |z| 3.0 * noise.sigma(z),
    )?)
}

/// How far (m) one view can grow an object's region past its sides and top: twice the
/// 3 cm margin, more than phase 1's box falls short by at a side the laser did not see
/// (5 cm on a box turned on paper-env2's table).
pub(super) const REGION_REACH: f64 = 0.06;

/// What a view saw of one object ([`object_view`]).
pub(super) struct ObjectView {
    /// The object's points of the frame ([`object_points`]).
    pub cloud: PointCloud,
    /// The object's points of the frame smoothed for the registration, cut as `cloud`.
    pub registration_cloud: Option<PointCloud>,
    /// The table the view itself sees around the object (with the object's surface: its
    /// pose error moves it), when it was found.
    pub table: Option<PlaneFit>,
    /// What the table says of the view's pose ([`table_evidence`]).
    pub table_seen: Option<TableEvidence>,
}

impl ObjectView {
    /// The view as the object records it: what `seen` saw of the object at `candidate`'s
    /// viewpoint, reached by a path of `plan`; no failure before it and no new surface
    /// counted (the exploration sets both).
    pub(super) fn recorded(
        self,
        candidate: &Candidate,
        seen: &Observation,
        plan: PlanStats,
    ) -> AcquiredView {
        AcquiredView {
            viewpoint: candidate.viewpoint.pose,
            score: candidate.score,
            predicted: (
                candidate.visible.unknown.len(),
                candidate.visible.occupied.len(),
            ),
            joints: seen.joints,
            sensor_pose: seen.sensor_pose,
            frame_points: seen.frame_points,
            cloud: self.cloud,
            free_space: seen.free_space.clone(),
            registration_cloud: self.registration_cloud,
            gain: seen.gain,
            table: self.table_seen,
            plan,
            failures_before: 0,
            new_surface: 0.0,
        }
    }
}

/// The object's part of the view `seen`: its points in `region` above the view's own table
/// (with `object_surface`; else above phase 1's `table`), as acquired and smoothed, and the
/// table's evidence on the view's pose (timed as registration).
pub(super) fn object_view(
    ep: &Episode<'_, '_>,
    seen: &Observation,
    region: &ObjectRegion,
    table: Option<&PlaneFit>,
    object_surface: bool,
    times: &mut StepTimes,
) -> ObjectView {
    let config = ep.config;
    let view_table = if object_surface {
        region.view_table(&seen.frame.points, REGION_REACH)
    } else {
        None
    };
    let cut = view_table.as_ref().or(table);
    let (cloud, registration_cloud) = object_points(
        &seen.frame,
        seen.smoothed.as_ref(),
        region,
        cut.zip(config.table_filter.as_ref()),
        &config.phase_one.exclude,
        object_surface,
    );
    let table_seen = timed(&mut times.registration, || {
        table_evidence(
            &seen.frame,
            &seen.sensor_pose,
            ep.rig.camera.spec().range[1],
            &ep.footprints,
            table,
            config,
        )
    });
    ObjectView {
        cloud,
        registration_cloud,
        table: view_table,
        table_seen,
    }
}

/// The share of the averaged frame's range noise left in a smoothed one, as the table
/// test of [`object_points`] reads it. The edge-gated plane fit ([`smooth_frame`]) takes
/// it to σ/5 over a whole 5 × 5 window of one surface and to σ/3 over 3 × 3: at σ/3 the
/// test's 2.5 cut lies at 4σ or more of a smoothed table. Tested on the averaged depths,
/// a 5 mm spatula blade and the lowest 7–11 mm of its neck lay within the 2.5σ cut
/// (10–16 mm at 0.3–0.45 m) and went with the table from every view.
pub const SMOOTHED_NOISE: f64 = 1.0 / 3.0;

/// The object's points of a view: `frame` (as acquired) cut to its `region`, the table
/// taken out (a plane and the filter that reads it) and the `known` obstacles' boxes; and
/// `smoothed` (the same pixels smoothed for the registration, [`REGISTRATION_SMOOTHING`])
/// cut alike. With `on_smoothed` (`[nbv] object_surface`, the twin preset) which points
/// are the table's is decided on the smoothed depths (`smoothed`, else `frame`, which
/// `[nbv] depth_smoothing` smoothed) at [`SMOOTHED_NOISE`] of the filter's noise: what
/// stands a few millimetres off the table is told from it where the noise is averaged over
/// the pixels around it, and the model keeps the acquired points of those pixels. Without
/// it, on `frame`'s depths at the filter's noise (the paper preset's views stay as they
/// were: its sphere is centred on the object's points).
///
/// The known obstacles are no object: what falls in their boxes (grown by the clustering
/// tolerance, as phase 1 leaves them out) leaves the view. Not grown by the camera's whole
/// declared pose error: at five times the scenes' errors that margin reaches 10 cm and
/// swallows objects standing in front of a known box; the views' misalignment is the
/// registration's to correct.
pub(super) fn object_points(
    frame: &PointCloud,
    smoothed: Option<&PointCloud>,
    region: &ObjectRegion,
    table: Option<(&PlaneFit, &TableFilter)>,
    known: &[OrientedBox],
    on_smoothed: bool,
) -> (PointCloud, Option<PointCloud>) {
    // The same pixels, in the same order: smoothing keeps every valid depth valid. A
    // smoothed cloud of another length (none is made) would be left out, not misread.
    debug_assert!(
        smoothed.is_none_or(|s| s.len() == frame.len()),
        "a smoothed cloud of another length than its frame's"
    );
    let smoothed = smoothed.filter(|s| s.len() == frame.len());
    let cut = |c: &PointCloud, keep: &dyn Fn(usize) -> bool| c.retain_indices(keep);
    let inside = |i: usize| region.contains(&frame.points[i]);
    let (mut cloud, mut smooth) = (cut(frame, &inside), smoothed.map(|s| cut(s, &inside)));
    if let Some((plane, filter)) = table {
        let (filter, decided) = if on_smoothed {
            let filter = TableFilter {
                sigma_at_1m: filter.sigma_at_1m * SMOOTHED_NOISE,
                ..*filter
            };
            (filter, smooth.as_ref().unwrap_or(&cloud))
        } else {
            (*filter, &cloud)
        };
        let keep = filter.kept(plane, decided);
        let kept = |i: usize| keep[i];
        (cloud, smooth) = (cut(&cloud, &kept), smooth.map(|s| cut(&s, &kept)));
    }
    let clear = |i: usize| !known.iter().any(|b| b.contains(&cloud.points[i]));
    (cut(&cloud, &clear), smooth.map(|s| cut(&s, &clear)))
}

/// Height (m) above the table at which a known obstacle's box is tested for standing on
/// a point of the table.
const FOOTPRINT_LIFT: f64 = 0.001;

/// What the table says of a view at `pose` (`frame`: its points at that pose), around
/// the objects' `footprints` (their regions' floors brought down to the table) and the
/// known obstacles, and nearer than three of a single frame's σ short of the camera's
/// `max_range` (there the limit drops the far side of the noise before the burst is
/// averaged); `None` unless the self-calibration uses it and phase 1 found the table.
fn table_evidence(
    frame: &PointCloud,
    pose: &Pose,
    max_range: f64,
    footprints: &[ObjectRegion],
    table: Option<&PlaneFit>,
    config: &ExploreConfig,
) -> Option<TableEvidence> {
    if !config.calibrate_hand_eye {
        return None;
    }
    let single = config.uncertainty.camera_noise;
    let noise = single.averaged(config.frames_per_view.max(1));
    let known = &config.phase_one.exclude;
    let plane = table?;
    TableEvidence::of_view(
        &frame.points,
        &Point3::from(pose.translation.vector),
        plane,
        noise,
        max_range - 3.0 * single.sigma(max_range),
        |q| {
            let above = q + plane.normal.into_inner() * FOOTPRINT_LIFT;
            !footprints.iter().any(|r| r.covers(q)) && !known.iter().any(|b| b.contains(&above))
        },
    )
}

/// `config.frames_per_view` frames (at least one) at the camera's current pose, averaged,
/// then smoothed by `config.depth_smoothing` ([`smooth_frame`]) at the averaged frame's
/// noise; and, when `config.no_return_clearing` clears anything, the burst's pixels
/// without a return ([`no_return_pixels`]; else none).
pub(super) fn capture_burst(
    camera: &mut dyn DepthCamera,
    config: &ExploreConfig,
) -> Result<(DepthFrame, Vec<bool>), RigError> {
    let n = config.frames_per_view.max(1);
    let frames = (0..n)
        .map(|_| camera.capture())
        .collect::<Result<Vec<_>, _>>()?;
    let no_return = if config.no_return_clearing > 0.0 {
        no_return_pixels(&frames)
    } else {
        Vec::new()
    };
    let frame = average_frames(&frames, config.return_share)?;
    let noise = config.uncertainty.camera_noise.averaged(n);
    let frame = smooth_frame(frame, config.depth_smoothing, |z| noise.sigma(z));
    Ok((frame, no_return))
}

/// The free rays of the pixels in `no_return` (row-major over `spec`'s image), from the
/// camera at `pose` along each pixel's ray, `length` metres long; none if `length` is 0.
fn free_rays(no_return: &[bool], spec: &DepthCameraSpec, pose: &Pose, length: f64) -> Vec<FreeRay> {
    if length <= 0.0 {
        return Vec::new();
    }
    let origin = Point3::from(pose.translation.vector);
    no_return
        .iter()
        .enumerate()
        .filter(|(_, empty)| **empty)
        .map(|(i, _)| {
            let ray = pose.rotation * spec.pixel_ray(i % spec.width, i / spec.width);
            FreeRay {
                origin,
                end: origin + ray * (length / ray.norm()),
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Translation3, UnitQuaternion, Vector3};

    /// The Dinast somewhere above the table, turned.
    fn camera() -> (DepthCameraSpec, Pose) {
        let pose = Pose::from_parts(
            Translation3::new(0.6, -0.1, 0.7),
            UnitQuaternion::from_euler_angles(2.8, -0.4, 1.1),
        );
        (DepthCameraSpec::ipa1110(), pose)
    }

    /// A frame of `spec`'s size with these depths.
    fn frame_of(spec: &DepthCameraSpec, depth: Vec<f32>) -> DepthFrame {
        DepthFrame {
            time: 0.0,
            width: spec.width,
            height: spec.height,
            depth,
            truth: None,
        }
    }

    /// A 10 × 7.5 cm blade 5 mm thick on a table 0.4 m in front of the camera, through a
    /// burst of eight frames' range noise (5.7 mm at 0.4 m): the view as acquired, and
    /// smoothed for the registration; the table's plane (its normal towards the camera)
    /// and the pipeline's filter.
    fn blade_on_the_table() -> (PointCloud, PointCloud, PlaneFit, TableFilter) {
        let spec = DepthCameraSpec::ipa1110();
        let sigma = DepthFrame::burst_sigma;
        let frame = DepthFrame::averaged_burst(&spec, 5, |ray| {
            let top = 0.395;
            let on_blade = (top * ray.x).abs() < 0.05 && (top * ray.y).abs() < 0.0375;
            Some(if on_blade { top } else { 0.4 })
        });
        let smoothed = smooth_frame(frame.clone(), REGISTRATION_SMOOTHING, sigma);
        let cloud = |f: &DepthFrame| depth_frame_to_cloud(f, &spec, &Pose::identity()).unwrap();
        let table = PlaneFit {
            normal: -Vector3::z_axis(),
            offset: 0.4,
            inliers: Vec::new(),
            rms: 0.0,
        };
        let filter = TableFilter::for_camera(0.04 / 8f64.sqrt(), 1.0);
        (cloud(&frame), cloud(&smoothed), table, filter)
    }

    #[test]
    fn a_blade_a_few_millimetres_thick_is_told_from_the_table_on_the_smoothed_depths() {
        let (acquired, smoothed, table, filter) = blade_on_the_table();
        let on_blade = |p: &Point3<f64>| p.x.abs() < 0.05 && p.y.abs() < 0.0375;
        let blade = acquired.points.iter().filter(|p| on_blade(p)).count();
        let shares = |c: &PointCloud| {
            let kept = c.points.iter().filter(|p| on_blade(p)).count();
            (
                kept as f64 / blade as f64,
                (c.len() - kept) as f64 / (acquired.len() - blade) as f64,
            )
        };
        let region = ObjectRegion {
            min: Point3::new(-0.2, -0.15, 0.3),
            max: Point3::new(0.2, 0.15, 0.45),
            table: None,
            top: 0.395,
        };
        let cut = |on_smoothed: bool| {
            object_points(
                &acquired,
                Some(&smoothed),
                &region,
                Some((&table, &filter)),
                &[],
                on_smoothed,
            )
        };
        // The acquired depths at their own noise (the paper preset's test): the blade is
        // the table's, its 5 mm within the cut's 14 mm.
        let (raw, _) = cut(false);
        assert_eq!(
            raw.points,
            filter.remove(&table, &region.crop(&acquired)).points
        );
        assert!(shares(&raw).0 < 0.3, "{:?}", shares(&raw));
        // Decided on the smoothed depths: the blade stays, the table goes, and the two
        // clouds keep the same pixels.
        let (object, registered) = cut(true);
        let registered = registered.unwrap();
        let (blade_kept, table_kept) = shares(&object);
        assert!(
            blade_kept > 0.85 && table_kept < 0.01,
            "{blade_kept} {table_kept}"
        );
        assert_eq!(object.len(), registered.len());
        for (a, s) in object.points.iter().zip(&registered.points) {
            assert!(a.coords.normalize().cross(&s.coords.normalize()).norm() < 1e-6);
        }
        // A known obstacle's box takes its points out of both.
        let everything =
            OrientedBox::from_bounds(Point3::new(-1.0, -1.0, 0.0), Point3::new(1.0, 1.0, 1.0));
        let (none, none_registered) = object_points(
            &acquired,
            Some(&smoothed),
            &region,
            Some((&table, &filter)),
            &[everything],
            true,
        );
        assert_eq!((none.len(), none_registered.map(|c| c.len())), (0, Some(0)));
    }

    #[test]
    fn free_rays_run_along_the_pixels_the_cloud_puts_points_on() {
        let (spec, pose) = camera();
        let (w, h) = (spec.width, spec.height);
        // Three pixels: a corner, the centre, an off-centre one.
        let pixels = [0, (h / 2) * w + w / 2, 37 * w + 250];
        let mut no_return = vec![false; w * h];
        let mut depth = vec![f32::NAN; w * h];
        for &i in &pixels {
            no_return[i] = true;
            depth[i] = 0.5;
        }
        let frame = frame_of(&spec, depth);
        let cloud = depth_frame_to_cloud(&frame, &spec, &pose).unwrap();
        let rays = free_rays(&no_return, &spec, &pose, 0.75);
        assert_eq!((rays.len(), cloud.len()), (3, 3));
        let origin = Point3::from(pose.translation.vector);
        for (ray, point) in rays.iter().zip(&cloud.points) {
            assert_eq!(ray.origin, origin);
            let along: Vector3<f64> = ray.end - ray.origin;
            assert!((along.norm() - 0.75).abs() < 1e-12);
            // The frame's point for the same pixel lies on the free ray's line.
            let to_point = (point - origin).normalize();
            assert!((along.normalize() - to_point).norm() < 1e-6);
        }
        // Off: no ray.
        assert!(free_rays(&no_return, &spec, &pose, 0.0).is_empty());
    }

    #[test]
    fn the_cameras_free_space_lies_in_front_of_the_frames_points() {
        let (spec, pose) = camera();
        let (w, h) = (spec.width, spec.height);
        // A tilted wall, a hole without a return in it.
        let depth = (0..w * h)
            .map(|i| {
                let (u, v) = (i % w, i / w);
                if (100..110).contains(&u) && (50..60).contains(&v) {
                    f32::NAN
                } else {
                    0.4 + 0.0005 * u as f32 + 0.0002 * v as f32
                }
            })
            .collect();
        let frame = frame_of(&spec, depth);
        let noise = RangeNoise::constant(0.002);
        let free = camera_free_space(&frame, &spec, &pose, noise).unwrap();
        let cloud = depth_frame_to_cloud(&frame, &spec, &pose).unwrap();
        let eye = Point3::from(pose.translation.vector);
        let (mut tested, mut hole) = (0, 0);
        for v in (5..h - 5).step_by(7) {
            for u in (5..w - 5).step_by(7) {
                let ray = pose.rotation * spec.pixel_ray(u, v);
                // Beside the hole the four pixels around a centre may include one of it.
                if (99..=110).contains(&u)
                    && (49..=60).contains(&v)
                    && frame.point(&spec, u, v).is_some()
                {
                    continue;
                }
                let Some(z) = frame.point(&spec, u, v).map(|p| p.z) else {
                    // Around the hole nothing is known.
                    assert!(!free.contains(&(eye + ray * 0.3)));
                    hole += 1;
                    continue;
                };
                // In front of the return by more than the margin (6 mm), within it, behind.
                assert!(free.contains(&(eye + ray * (z - 0.008))), "{u} {v}");
                assert!(!free.contains(&(eye + ray * (z - 0.004))), "{u} {v}");
                assert!(!free.contains(&(eye + ray * (z + 0.01))), "{u} {v}");
                tested += 1;
            }
        }
        assert!(tested > 1000 && hole > 0, "{tested} {hole}");
        assert_eq!(cloud.len(), w * h - 100);
    }
}
