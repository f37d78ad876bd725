//! [`NextBestView`]: Algorithm 2 (ComputeViewpointList) — candidate viewpoints on the
//! viewing sphere around the object's centroid, filtered by inverse kinematics and by the
//! visited views, each with its predicted visible set O_v, sorted by eq. (4).

use std::f64::consts::TAU;

use nalgebra::Point3;
use rayon::prelude::*;

use super::{
    GainMap, NbvError, Objective, ScoreWeights, SensorRays, SphereSample, ViewSphere,
    VisibleVoxels, VisitedViews, view_gain, view_pose, view_pose_rolled, visible_voxels,
    visible_voxels_literal,
};
use crate::cloud::PointCloud;
use crate::kinematics::{IkError, IkSolution, Joints, Robot};
use crate::math::Pose;
use crate::occupancy::ReducedMap;
use crate::rig::DepthCameraSpec;

/// Which implementation computes O_v (both give the same sets; see
/// [`visibility`](super::visible_voxels)).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum VisibilityForm {
    /// DDA through the dense lattice with the reduced map's bitsets.
    #[default]
    Dda,
    /// Every ray against every voxel of M̄ (the paper's literal loop; slow).
    Literal,
}

/// Parameters of Algorithm 2 besides the sensor.
///
/// Defaults: the twin preset's ([`NbvPreset::params`](super::NbvPreset::params), beside
/// the paper's).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NbvParams {
    /// The viewing sphere.
    pub sphere: ViewSphere,
    /// The weights of eq. (4).
    pub weights: ScoreWeights,
    /// Keep every `ray_stride`-th pixel in u and v (≥ 1).
    pub ray_stride: usize,
    /// Rolls about the optical axis tried for reachability (≥ 1): roll k·2π/n for
    /// k = 0..n, in that order, the first reachable one kept. 1 = eq. (3)'s roll only.
    pub roll_candidates: usize,
    /// How O_v is computed.
    pub visibility: VisibilityForm,
    /// What ranks the candidates: eq. (4) (default) or an information gain over the grid.
    pub objective: Objective,
    /// λ of Isler's utility `G/ΣG − λ·c/Σc` ([`apply_movement_cost`](super::apply_movement_cost));
    /// 0 (default) ranks by G alone.
    pub cost_weight: f64,
    /// Eq. (4) counts the object's surface ([`view_candidates`]): only the voxels of
    /// the object being explored (in its region), an occupied voxel seen from a side no
    /// view has seen it from as new ([`SurfaceSides`](super::SurfaceSides)), an unknown
    /// voxel a taken view missed no more ([`MissedVoxels`](super::MissedVoxels)); and each
    /// view's object points are cut at the table that view sees, told from the object on
    /// its smoothed depths. False (default): every voxel of M̄ the rays reach, as printed,
    /// and the views cut at phase 1's table on their averaged depths.
    ///
    /// [`view_candidates`]: crate::pipeline::view_candidates
    pub object_surface: bool,
    /// With `object_surface`, when a candidate scores the unseen area of the object's
    /// convex hull it would see ([`HullSurface`](super::HullSurface)) in place of eq. (4)'s
    /// voxel count ([`HullScore`](super::HullScore)).
    pub hull_score: super::HullScore,
    /// The planner takes the unknown space above every object phase 1 found (above the
    /// highest top of their regions, [`ExplorationMap::free_above`]) as free; false
    /// (default): every unknown voxel of M̄ is an obstacle, as in the paper.
    ///
    /// [`ExplorationMap::free_above`]: crate::pipeline::ExplorationMap::free_above
    pub free_above_objects: bool,
}

impl Default for NbvParams {
    fn default() -> Self {
        super::NbvPreset::default().params()
    }
}

/// A reachable viewpoint: its sample, the roll applied to eq. (3) and the sensor pose, with
/// every IK solution that puts the sensor frame there (the planner's goals).
#[derive(Debug, Clone, PartialEq)]
pub struct Viewpoint {
    /// The (θ, φ) sample.
    pub sample: SphereSample,
    /// Roll about the optical axis applied to eq. (3)'s pose (rad).
    pub roll: f64,
    /// Sensor pose `T_base_sensor`.
    pub pose: Pose,
    /// IK solutions of the sensor frame at `pose` (non-empty).
    pub solutions: Vec<IkSolution>,
}

impl Viewpoint {
    /// The joint goals that reach it: its IK solutions' joints, in order (the planner's
    /// goals).
    pub fn goals(&self) -> Vec<Joints> {
        self.solutions.iter().map(|s| s.joints).collect()
    }
}

/// A viewpoint with its predicted visible set and its score.
#[derive(Debug, Clone, PartialEq)]
pub struct Candidate {
    /// The viewpoint.
    pub viewpoint: Viewpoint,
    /// O_v.
    pub visible: VisibleVoxels,
    /// The objective's value G(v): eq. (4) by default.
    pub score: f64,
    /// What the candidates are sorted by: `score`, or Isler's utility with a movement
    /// cost ([`apply_movement_cost`](super::apply_movement_cost)).
    pub utility: f64,
}

/// The reachable, unvisited viewpoints of one sphere (Algorithm 2, lines 1–10) and how many
/// samples were dropped.
#[derive(Debug, Clone, PartialEq)]
pub struct ViewpointSet {
    /// Centre of the sphere.
    pub centroid: Point3<f64>,
    /// Kept viewpoints, in sample order.
    pub viewpoints: Vec<Viewpoint>,
    /// Samples on the sphere (after removing duplicates).
    pub samples: usize,
    /// Samples dropped as close to a visited view.
    pub visited: usize,
    /// Samples dropped because no roll had an IK solution.
    pub unreachable: usize,
}

/// The output of Algorithm 2: candidates sorted best first, with the counts.
#[derive(Debug, Clone, PartialEq)]
pub struct ViewpointList {
    /// Centre of the sphere.
    pub centroid: Point3<f64>,
    /// Candidates by decreasing score; ties by (i_θ, i_φ).
    pub candidates: Vec<Candidate>,
    /// Samples on the sphere.
    pub samples: usize,
    /// Samples dropped as visited.
    pub visited: usize,
    /// Samples dropped as unreachable.
    pub unreachable: usize,
    /// Rays cast per candidate (|D|).
    pub rays_per_view: usize,
}

impl ViewpointList {
    /// Removes and returns the best remaining candidate (Algorithm 1's `pop_first`).
    pub fn pop_first(&mut self) -> Option<Candidate> {
        (!self.candidates.is_empty()).then(|| self.candidates.remove(0))
    }
}

/// Algorithm 2 for one sensor: the sensor frame on the robot, its ray set D and the
/// parameters.
///
/// ```
/// use nbv_core::kinematics::Robot;
/// use nbv_core::nbv::{NbvPreset, NextBestView, VisitedViews};
/// use nbv_core::occupancy::{GridGeometry, OccupancyGrid, OccupancyParams, ReducedMap};
/// use nbv_core::rig::DepthCameraSpec;
/// use nalgebra::Point3;
/// let path = nbv_core::kinematics::COMAU_URDF;
/// let robot = Robot::from_urdf_file(path)?;
/// let camera = DepthCameraSpec::ipa1110();
/// // The paper's sphere: r = 0.3 m, 61 samples.
/// let nbv = NextBestView::new(NbvPreset::Paper.params(), &camera)?;
/// // A grid where one voxel is occupied, the rest seen empty.
/// let g = GridGeometry::new(Point3::new(0.5, -0.3, 0.2), Point3::new(1.1, 0.3, 0.6), 0.02)?;
/// let mut values = vec![-1.0f32; g.len()];
/// let centroid = Point3::new(0.81, 0.01, 0.31);
/// values[g.linear(g.voxel_of(&centroid).unwrap()).unwrap()] = 1.0;
/// let map = ReducedMap::from_grid(&OccupancyGrid::from_log_odds(g, OccupancyParams::default(), values)?);
/// let list = nbv.candidates_around(&robot, &map, &centroid, &VisitedViews::default())?;
/// assert_eq!(list.samples, 61);
/// assert_eq!(list.samples, list.candidates.len() + list.unreachable + list.visited);
/// // Every candidate looks at the centroid, so its central rays see the voxel.
/// assert!(list.candidates.iter().all(|c| c.visible.occupied.len() == 1 && c.score == 1.0));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct NextBestView {
    /// Parameters.
    pub params: NbvParams,
    /// The sensor frame on the robot (the camera spec's `frame`, e.g. `dinast`).
    pub frame: String,
    /// The predicted sensor's rays D and its range.
    pub rays: SensorRays,
    /// The camera the views are taken with.
    pub camera: DepthCameraSpec,
}

impl NextBestView {
    /// Checks the parameters and builds D from the camera.
    pub fn new(params: NbvParams, camera: &DepthCameraSpec) -> Result<Self, NbvError> {
        params.sphere.validate()?;
        params.weights.validate()?;
        if !(params.cost_weight.is_finite() && params.cost_weight >= 0.0) {
            return Err(NbvError::InvalidParameter {
                name: "cost_weight",
                value: params.cost_weight,
                reason: "must be finite and >= 0",
            });
        }
        if params.roll_candidates == 0 {
            return Err(NbvError::InvalidParameter {
                name: "roll_candidates",
                value: 0.0,
                reason: "must be >= 1",
            });
        }
        let rays = SensorRays::from_camera(camera, params.ray_stride)?;
        Ok(Self {
            params,
            frame: camera.frame.clone(),
            rays,
            camera: camera.clone(),
        })
    }

    /// Lines 1–10: the sphere's samples around `centroid`, their poses by eq. (3) (at the
    /// near radius where none is reachable at the radius, when the sphere has one), minus
    /// those close to a visited view and those without an IK solution for the sensor frame
    /// (IK failures other than "unreachable" — an unknown frame, an unsupported robot —
    /// are errors; a pose whose closed-form solutions cannot be polished counts as
    /// unreachable).
    pub fn viewpoints(
        &self,
        robot: &Robot,
        centroid: &Point3<f64>,
        visited: &VisitedViews,
    ) -> Result<ViewpointSet, NbvError> {
        self.viewpoints_where(robot, centroid, visited, &|_| true)
    }

    /// [`viewpoints`](Self::viewpoints) keeping only the IK solutions `usable` accepts
    /// (e.g. those free of self-collision and of known obstacles); a roll none of whose
    /// solutions is usable counts as unreachable and the next roll is tried.
    pub fn viewpoints_where(
        &self,
        robot: &Robot,
        centroid: &Point3<f64>,
        visited: &VisitedViews,
        usable: &GoalFilter<'_>,
    ) -> Result<ViewpointSet, NbvError> {
        if !centroid.iter().all(|v| v.is_finite()) {
            return Err(NbvError::InvalidInput("object centroid is not finite"));
        }
        visited.validate()?;
        let samples = self.params.sphere.samples()?;
        let outcomes = samples
            .par_iter()
            .map(|s| self.viewpoint(robot, centroid, visited, s, usable))
            .collect::<Result<Vec<_>, NbvError>>()?;
        let mut set = ViewpointSet {
            centroid: *centroid,
            viewpoints: Vec::new(),
            samples: samples.len(),
            visited: 0,
            unreachable: 0,
        };
        for o in outcomes {
            match o {
                SampleOutcome::Kept(v) => set.viewpoints.push(v),
                SampleOutcome::Visited => set.visited += 1,
                SampleOutcome::Unreachable => set.unreachable += 1,
            }
        }
        Ok(set)
    }

    /// The sample's viewpoint at the sphere's radius, or — none of its rolls reachable
    /// there — at its near radius.
    fn viewpoint(
        &self,
        robot: &Robot,
        centroid: &Point3<f64>,
        visited: &VisitedViews,
        sample: &SphereSample,
        usable: &GoalFilter<'_>,
    ) -> Result<SampleOutcome, NbvError> {
        let sphere = &self.params.sphere;
        let near = (sphere.near_radius > 0.0).then_some(sphere.near_radius);
        for radius in std::iter::once(sphere.radius).chain(near) {
            let base = view_pose(centroid, radius, sample.theta, sample.phi);
            // Position and optical axis do not depend on the roll.
            if visited.is_close(&base) {
                return Ok(SampleOutcome::Visited);
            }
            let n = self.params.roll_candidates;
            for k in 0..n {
                let roll = TAU * k as f64 / n as f64;
                let pose = view_pose_rolled(&base, roll);
                match robot.ik(&self.frame, &pose) {
                    Ok(mut solutions) => {
                        solutions.retain(|s| usable(s));
                        if solutions.is_empty() {
                            continue;
                        }
                        return Ok(SampleOutcome::Kept(Viewpoint {
                            sample: *sample,
                            roll,
                            pose,
                            solutions,
                        }));
                    }
                    Err(IkError::Unreachable(_) | IkError::NotConverged { .. }) => {}
                    Err(e) => return Err(e.into()),
                }
            }
        }
        Ok(SampleOutcome::Unreachable)
    }

    /// Lines 11–24 for one viewpoint: O_v and eq. (4).
    pub fn evaluate(&self, map: &ReducedMap, viewpoint: Viewpoint) -> Result<Candidate, NbvError> {
        self.evaluate_with(map, None, viewpoint)
    }

    /// O_v and the objective's value: eq. (4) on `map`, or an information gain on `gains`
    /// (an error if the objective needs it and it is `None`).
    pub fn evaluate_with(
        &self,
        map: &ReducedMap,
        gains: Option<&GainMap<'_>>,
        viewpoint: Viewpoint,
    ) -> Result<Candidate, NbvError> {
        let visible = match self.params.visibility {
            VisibilityForm::Dda => visible_voxels(map, &viewpoint.pose, &self.rays)?,
            VisibilityForm::Literal => visible_voxels_literal(map, &viewpoint.pose, &self.rays)?,
        };
        let score = match (self.params.objective, gains) {
            (Objective::Paper, _) => self.params.weights.score(&visible),
            (o, Some(g)) => view_gain(o, g, &viewpoint.pose, &self.rays)?,
            (_, None) => {
                return Err(NbvError::InvalidInput(
                    "an information-gain objective needs the occupancy grid",
                ));
            }
        };
        Ok(Candidate {
            viewpoint,
            visible,
            score,
            utility: score,
        })
    }

    /// Algorithm 2 around a given centroid: viewpoints, O_v of each (in parallel), sorted by
    /// eq. (4) best first (line 26), ties by (i_θ, i_φ).
    pub fn candidates_around(
        &self,
        robot: &Robot,
        map: &ReducedMap,
        centroid: &Point3<f64>,
        visited: &VisitedViews,
    ) -> Result<ViewpointList, NbvError> {
        self.candidates_around_where(robot, map, centroid, visited, &|_| true)
    }

    /// [`candidates_around`](Self::candidates_around) with the IK solutions filtered as in
    /// [`viewpoints_where`](Self::viewpoints_where).
    pub fn candidates_around_where(
        &self,
        robot: &Robot,
        map: &ReducedMap,
        centroid: &Point3<f64>,
        visited: &VisitedViews,
        usable: &GoalFilter<'_>,
    ) -> Result<ViewpointList, NbvError> {
        self.candidates_scored(robot, map, None, centroid, visited, usable)
    }

    /// [`candidates_around_where`](Self::candidates_around_where) scored by the
    /// parameters' objective, the information gains on `gains`.
    pub fn candidates_scored(
        &self,
        robot: &Robot,
        map: &ReducedMap,
        gains: Option<&GainMap<'_>>,
        centroid: &Point3<f64>,
        visited: &VisitedViews,
        usable: &GoalFilter<'_>,
    ) -> Result<ViewpointList, NbvError> {
        let set = self.viewpoints_where(robot, centroid, visited, usable)?;
        let mut candidates = set
            .viewpoints
            .into_par_iter()
            .map(|v| self.evaluate_with(map, gains, v))
            .collect::<Result<Vec<_>, NbvError>>()?;
        sort_best_first(&mut candidates);
        Ok(ViewpointList {
            centroid: set.centroid,
            candidates,
            samples: set.samples,
            visited: set.visited,
            unreachable: set.unreachable,
            rays_per_view: self.rays.len(),
        })
    }

    /// Algorithm 2 as printed: the sphere around the centroid of the object's cloud (all
    /// its views so far, line 1).
    pub fn candidates(
        &self,
        robot: &Robot,
        map: &ReducedMap,
        object: &PointCloud,
        visited: &VisitedViews,
    ) -> Result<ViewpointList, NbvError> {
        let centroid = object
            .centroid()
            .ok_or(NbvError::InvalidInput("the object cloud is empty"))?;
        self.candidates_around(robot, map, &centroid, visited)
    }
}

/// Which IK solutions of a viewpoint may be planning goals.
pub type GoalFilter<'a> = dyn Fn(&IkSolution) -> bool + Sync + 'a;

enum SampleOutcome {
    Kept(Viewpoint),
    Visited,
    Unreachable,
}

/// Sorts by decreasing utility (the score unless a movement cost was applied), ties by
/// increasing (i_θ, i_φ).
pub fn sort_best_first(candidates: &mut [Candidate]) {
    candidates.sort_by(compare_best_first);
}

/// The order of [`sort_best_first`]: higher utility first, ties by sphere sample.
pub fn compare_best_first(a: &Candidate, b: &Candidate) -> std::cmp::Ordering {
    b.utility.total_cmp(&a.utility).then_with(|| {
        let key = |c: &Candidate| (c.viewpoint.sample.i_theta, c.viewpoint.sample.i_phi);
        key(a).cmp(&key(b))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn candidate(i_theta: usize, i_phi: usize, unknown: usize, occupied: usize) -> Candidate {
        let visible = VisibleVoxels {
            unknown: (0..unknown).collect(),
            occupied: (100..100 + occupied).collect(),
            ..VisibleVoxels::default()
        };
        Candidate {
            viewpoint: Viewpoint {
                sample: SphereSample {
                    i_theta,
                    i_phi,
                    theta: 0.0,
                    phi: 0.0,
                },
                roll: 0.0,
                pose: Pose::identity(),
                solutions: Vec::new(),
            },
            score: ScoreWeights::default().score(&visible),
            utility: ScoreWeights::default().score(&visible),
            visible,
        }
    }

    #[test]
    fn best_first_with_index_ties() {
        // Scores: 4·2 + 1 = 9, 4·1 + 5 = 9, 4·3 = 12, 4·0 + 9 = 9, 0.
        let mut c = vec![
            candidate(2, 5, 2, 1),
            candidate(1, 7, 1, 5),
            candidate(3, 0, 3, 0),
            candidate(1, 2, 0, 9),
            candidate(0, 0, 0, 0),
        ];
        sort_best_first(&mut c);
        let order: Vec<_> = c
            .iter()
            .map(|x| {
                (
                    x.score,
                    x.viewpoint.sample.i_theta,
                    x.viewpoint.sample.i_phi,
                )
            })
            .collect();
        assert_eq!(
            order,
            vec![
                (12.0, 3, 0),
                (9.0, 1, 2),
                (9.0, 1, 7),
                (9.0, 2, 5),
                (0.0, 0, 0)
            ]
        );
        let mut list = ViewpointList {
            centroid: Point3::origin(),
            candidates: c,
            samples: 5,
            visited: 0,
            unreachable: 0,
            rays_per_view: 0,
        };
        assert_eq!(list.pop_first().unwrap().score, 12.0);
        assert_eq!(list.candidates.len(), 4);
    }

    #[test]
    fn invalid_parameters() {
        let camera = DepthCameraSpec::ipa1110();
        let d = NbvParams::default();
        for bad in [
            NbvParams {
                roll_candidates: 0,
                ..d
            },
            NbvParams { ray_stride: 0, ..d },
            NbvParams {
                cost_weight: -0.5,
                ..d
            },
            NbvParams {
                weights: ScoreWeights {
                    unknown: -1.0,
                    occupied: 1.0,
                },
                ..d
            },
            NbvParams {
                sphere: ViewSphere {
                    radius: -0.3,
                    ..d.sphere
                },
                ..d
            },
        ] {
            assert!(matches!(
                NextBestView::new(bad, &camera),
                Err(NbvError::InvalidParameter { .. })
            ));
        }
        let nbv = NextBestView::new(d, &camera).unwrap();
        assert_eq!(nbv.rays.len(), 1200);
        assert_eq!(nbv.frame, "dinast");
    }
}
