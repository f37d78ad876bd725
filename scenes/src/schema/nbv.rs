//! [`Nbv`]: the next-best-view search of Algorithm 2 and its stopping rule.

use super::Check;
use crate::error::{Problem, SceneError};
pub use nbv_core::nbv::NbvPreset;
use nbv_core::nbv::{GainMeasure, HullScore, Objective, VisitedViews};
use serde::{Deserialize, Serialize};

/// Viewpoints on a sphere of radius `r` around the object centroid at inclinations
/// `θ = Δθ·i ≤ θ_max` and azimuths `φ = −π + Δφ·i` (eq. (3)), scored by
/// `α_u·|O_u| + α_o·|O_o|` (eq. (4)) or by another `objective`; an object is done when the
/// information gain (eq. (5)) of the latest view falls below `gain_threshold`, at the view
/// cap, or by the relative-gain rule.
///
/// Every key a file leaves out takes the value of its [`preset`](Nbv::preset): `"twin"`
/// (the default) or `"paper"`.
///
/// ```
/// use nbv_scenes::schema::{Nbv, NbvPreset};
/// let twin: Nbv = toml::from_str("").unwrap();
/// assert_eq!((twin.preset, twin.radius, twin.max_views_per_object), (NbvPreset::Twin, 0.45, 16));
/// let paper: Nbv = toml::from_str("preset = \"paper\"\nalpha_u = 2.0").unwrap();
/// assert_eq!((paper.radius, paper.dphi_deg, paper.alpha_u), (0.3, 30.0, 2.0));
/// // The paper preset keeps eq. (4) as printed and the stop rules the paper has.
/// assert_eq!((paper.object_surface, paper.new_surface), (false, 0.0));
/// assert_eq!((twin.object_surface, twin.new_surface, twin.new_surface_views), (true, 0.005, 2));
/// assert!(toml::from_str::<Nbv>("radious = 0.3").is_err());
/// let rse: Nbv = toml::from_str("objective = \"rear-side-entropy\"").unwrap();
/// assert_eq!(rse.objective, nbv_core::nbv::Objective::RearSideEntropy);
/// assert!(toml::from_str::<Nbv>("objective = \"rear-side\"").is_err());
/// ```
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(from = "NbvKeys")]
pub struct Nbv {
    /// The values the keys a file leaves out take: `"twin"` (default) or `"paper"`
    /// ([`NbvPreset`]).
    pub preset: NbvPreset,
    /// Viewing-sphere radius `r` (m). Twin 0.45, paper 0.3.
    pub radius: f64,
    /// The nearer radius (m) a sphere sample falls back to when the arm reaches none of
    /// its rolls at `radius`, in [0, radius); 0 is off. Twin 0.3, paper 0 (Algorithm 2 as
    /// printed).
    pub near_radius: f64,
    /// Inclination step `Δθ` (degrees). Twin 10, paper 15.
    pub dtheta_deg: f64,
    /// Largest inclination `θ_max` (degrees from straight above). Both 75.
    pub theta_max_deg: f64,
    /// Azimuth step `Δφ` (degrees). Twin 20, paper 30.
    pub dphi_deg: f64,
    /// Weight `α_u` of unknown voxels. Both 4 (paper).
    pub alpha_u: f64,
    /// Weight `α_o` of occupied voxels. Both 1 (paper).
    pub alpha_o: f64,
    /// Stop an object when the latest view's gain (nats, by `gain_measure`) is below
    /// this. Twin 2.5, paper 5.0 (assumed; the paper does not give its value).
    pub gain_threshold: f64,
    /// What `gain_threshold` is compared with: `"kl"` (default), the Bernoulli
    /// Kullback–Leibler divergence over the observed voxels, never negative; or `"eq5"`,
    /// eq. (5) as printed, negative for most views of surface (it stops an object after
    /// its first short-range view).
    pub gain_measure: GainMeasureName,
    /// Rolls about the optical axis tried per viewpoint, `k·360°/rolls` added to eq. (3)'s
    /// orientation, the first with a collision-free IK solution kept. Default 4 (the paper
    /// uses eq. (3)'s roll only: `rolls = 1`).
    pub rolls: u32,
    /// Keep every n-th camera pixel along rows and columns for the predicted ray set `D`.
    /// Default 8 (40 × 30 = 1200 rays).
    pub ray_subsample: u32,
    /// Discard candidates closer than this (m) to an already visited viewpoint.
    /// Default 0.08 (about one Δθ step on the sphere).
    pub visited_min_distance: f64,
    /// Hard cap on short-range views per object. Twin 16, paper 10 (it averages 5–6).
    pub max_views_per_object: u32,
    /// Depth frames averaged at each viewpoint (and each short-only survey pose): the
    /// camera's range noise falls by the square root. Default 8 (a quarter of a second at
    /// 30 Hz); 1 takes a single frame.
    pub frames_per_view: u32,
    /// A pixel of a burst's averaged frame is kept where more than this share of the
    /// frames returned, in [0, 1). Twin 0.2 (two of eight: a surface seen at a grazing
    /// angle returns in a few frames), paper 0.5 (the majority).
    pub return_share: f64,
    /// Half-width (pixels) of the edge-gated plane fit that smooths each averaged depth
    /// frame before it is used ([`smooth_frame`](nbv_core::rig::smooth_frame), which says
    /// why). Default 0 (the averaged frame as it is). 2 (a 5 × 5 window) lowers the
    /// registration's error in Table III and on held-out seeds but also the coverage, and
    /// on held-out seeds the F-score (docs/registration.md, "The registration's input smoothed").
    pub depth_smoothing: u32,
    /// What ranks the candidates: `"paper"` (eq. (4), default) or one of the seven
    /// information gains of Isler et al. 2016 / Delmerico et al. 2018:
    /// `"occlusion-aware"`, `"unobserved-voxel"`, `"rear-side-voxel"`,
    /// `"rear-side-entropy"`, `"proximity-count"`, `"area-factor"`, `"average-entropy"`
    /// ([`Objective`]).
    pub objective: Objective,
    /// λ of Isler's utility `G/ΣG − λ·c/Σc`, c the joint-space length of the planned
    /// motion to the candidate (≥ 0). Default 0: ranked by G alone.
    pub cost_weight: f64,
    /// The relative-gain stop rule: an object is done when its best candidate's objective
    /// value is below this share of its first round's best, in [0, 1). Default 0 (off).
    pub relative_gain: f64,
    /// Eq. (4) counts the object's surface: only the voxels of the object being explored
    /// (its phase-1 region grown by one voxel), not the table's or a neighbour's; an
    /// occupied voxel seen from a side no view has seen it from as new surface; an unknown
    /// voxel a taken view was predicted to observe and left unknown (an inside, the
    /// table contact, the gap behind an obstacle) no more
    /// ([`object_surface_score`](nbv_core::pipeline::object_surface_score)). Twin true,
    /// paper false (eq. (4) as printed).
    pub object_surface: bool,
    /// With `object_surface`, when a candidate scores the unseen area of the object's
    /// convex hull (its points and their footprint on the table) it would see, facing it,
    /// at the camera's return for the incidence, not hidden by another object
    /// ([`HullSurface`](nbv_core::nbv::HullSurface)), in place of eq. (4)'s voxel count:
    /// `"off"`, `"after-stall"` (once a view of the object added less than `new_surface`),
    /// `"always"`, or `"first"` (always, and eq. (4) takes the object over when the hull's
    /// stop would end it while its latest view still added surface) ([`HullScore`]). Twin
    /// `"first"`, paper `"off"` (docs/exploration.md, "Scoring the unseen hull").
    pub hull_score: HullScore,
    /// The planner takes the unknown space above every object phase 1 found (above the
    /// highest top of their regions) as free, not as an obstacle: the objects stand on the
    /// table and phase 1 saw each one's top, so nothing unknown stands higher; the known
    /// obstacles and the occupied voxels stay obstacles. Twin true, paper false (every
    /// unknown voxel is an obstacle).
    pub free_above_objects: bool,
    /// The new-surface stop rule: an object is done when each of its latest
    /// `new_surface_views` views added less new surface than this share of the surface
    /// seen before (points farther than 1 cm from the object's earlier points:
    /// [`new_surface_share`](nbv_core::nbv::new_surface_share)), in [0, 1). Twin 0.005
    /// (half a point: a view under it would be a wasted view by the report's measure),
    /// paper 0 (off).
    pub new_surface: f64,
    /// Views in a row the new-surface rule waits for (≥ 1). Both 2.
    pub new_surface_views: u32,
}

impl Default for Nbv {
    /// The twin preset.
    fn default() -> Self {
        Self::preset(NbvPreset::Twin)
    }
}

impl Nbv {
    /// Every value of `preset`, as nbv-core defines it ([`NbvPreset`]); the keys no core
    /// type holds (frames, smoothing) are the same in both.
    pub fn preset(preset: NbvPreset) -> Self {
        let p = preset.params();
        let stop = preset.stop_rule();
        Self {
            preset,
            radius: p.sphere.radius,
            near_radius: p.sphere.near_radius,
            dtheta_deg: whole_degrees(p.sphere.delta_theta),
            theta_max_deg: whole_degrees(p.sphere.theta_max),
            dphi_deg: whole_degrees(p.sphere.delta_phi),
            alpha_u: p.weights.unknown,
            alpha_o: p.weights.occupied,
            gain_threshold: stop.gain_threshold,
            gain_measure: match stop.measure {
                GainMeasure::Eq5 => GainMeasureName::Eq5,
                GainMeasure::BernoulliKl => GainMeasureName::Kl,
            },
            rolls: p.roll_candidates as u32,
            ray_subsample: p.ray_stride as u32,
            visited_min_distance: VisitedViews::default().distance,
            max_views_per_object: preset.max_views_per_object() as u32,
            frames_per_view: 8,
            return_share: preset.return_share(),
            depth_smoothing: 0,
            objective: p.objective,
            cost_weight: p.cost_weight,
            relative_gain: stop.relative_gain,
            object_surface: p.object_surface,
            hull_score: p.hull_score,
            free_above_objects: p.free_above_objects,
            new_surface: stop.new_surface,
            new_surface_views: stop.new_surface_views as u32,
        }
    }
}

/// `rad` in degrees, a whole number where it is one but for the rounding of the
/// conversion (the presets' angles are whole degrees: 15° comes back as 14.999999999999998).
fn whole_degrees(rad: f64) -> f64 {
    let d = rad.to_degrees();
    if (d - d.round()).abs() < 1e-9 {
        d.round()
    } else {
        d
    }
}

/// `[nbv]` as written: the keys given, over the preset's values.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct NbvKeys {
    preset: Option<NbvPreset>,
    radius: Option<f64>,
    near_radius: Option<f64>,
    dtheta_deg: Option<f64>,
    theta_max_deg: Option<f64>,
    dphi_deg: Option<f64>,
    alpha_u: Option<f64>,
    alpha_o: Option<f64>,
    gain_threshold: Option<f64>,
    gain_measure: Option<GainMeasureName>,
    rolls: Option<u32>,
    ray_subsample: Option<u32>,
    visited_min_distance: Option<f64>,
    max_views_per_object: Option<u32>,
    frames_per_view: Option<u32>,
    return_share: Option<f64>,
    depth_smoothing: Option<u32>,
    objective: Option<Objective>,
    cost_weight: Option<f64>,
    relative_gain: Option<f64>,
    object_surface: Option<bool>,
    hull_score: Option<HullScore>,
    free_above_objects: Option<bool>,
    new_surface: Option<f64>,
    new_surface_views: Option<u32>,
}

impl From<NbvKeys> for Nbv {
    fn from(k: NbvKeys) -> Self {
        let base = Nbv::preset(k.preset.unwrap_or_default());
        Self {
            preset: base.preset,
            radius: k.radius.unwrap_or(base.radius),
            near_radius: k.near_radius.unwrap_or(base.near_radius),
            dtheta_deg: k.dtheta_deg.unwrap_or(base.dtheta_deg),
            theta_max_deg: k.theta_max_deg.unwrap_or(base.theta_max_deg),
            dphi_deg: k.dphi_deg.unwrap_or(base.dphi_deg),
            alpha_u: k.alpha_u.unwrap_or(base.alpha_u),
            alpha_o: k.alpha_o.unwrap_or(base.alpha_o),
            gain_threshold: k.gain_threshold.unwrap_or(base.gain_threshold),
            gain_measure: k.gain_measure.unwrap_or(base.gain_measure),
            rolls: k.rolls.unwrap_or(base.rolls),
            ray_subsample: k.ray_subsample.unwrap_or(base.ray_subsample),
            visited_min_distance: k.visited_min_distance.unwrap_or(base.visited_min_distance),
            max_views_per_object: k.max_views_per_object.unwrap_or(base.max_views_per_object),
            frames_per_view: k.frames_per_view.unwrap_or(base.frames_per_view),
            return_share: k.return_share.unwrap_or(base.return_share),
            depth_smoothing: k.depth_smoothing.unwrap_or(base.depth_smoothing),
            objective: k.objective.unwrap_or(base.objective),
            cost_weight: k.cost_weight.unwrap_or(base.cost_weight),
            relative_gain: k.relative_gain.unwrap_or(base.relative_gain),
            object_surface: k.object_surface.unwrap_or(base.object_surface),
            hull_score: k.hull_score.unwrap_or(base.hull_score),
            free_above_objects: k.free_above_objects.unwrap_or(base.free_above_objects),
            new_surface: k.new_surface.unwrap_or(base.new_surface),
            new_surface_views: k.new_surface_views.unwrap_or(base.new_surface_views),
        }
    }
}

/// `[nbv] gain_measure`: which information-gain number the stop rule compares.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum GainMeasureName {
    /// Eq. (5) as printed.
    Eq5,
    /// The Bernoulli Kullback–Leibler divergence.
    Kl,
}

impl Nbv {
    /// Checks every value of `[nbv]`; the error names the key.
    pub(crate) fn check(&self, c: &Check) -> Result<(), SceneError> {
        c.positive("nbv.radius", self.radius)?;
        c.within(
            "nbv.near_radius",
            self.near_radius,
            0.0,
            self.radius.next_down(),
            "[0, nbv.radius): 0 is off",
        )?;
        c.within(
            "nbv.dtheta_deg",
            self.dtheta_deg,
            0.1,
            180.0,
            "[0.1, 180] degrees",
        )?;
        c.within(
            "nbv.theta_max_deg",
            self.theta_max_deg,
            0.0,
            180.0,
            "[0, 180] degrees",
        )?;
        c.within(
            "nbv.dphi_deg",
            self.dphi_deg,
            0.1,
            360.0,
            "[0.1, 360] degrees",
        )?;
        c.within("nbv.alpha_u", self.alpha_u, 0.0, f64::MAX, "≥ 0")?;
        c.within("nbv.alpha_o", self.alpha_o, 0.0, f64::MAX, "≥ 0")?;
        if self.alpha_u + self.alpha_o <= 0.0 {
            return Err(c.err(
                "nbv.alpha_u",
                Problem::NotPositive("alpha_u + alpha_o = 0".into()),
            ));
        }
        c.within(
            "nbv.gain_threshold",
            self.gain_threshold,
            0.0,
            f64::MAX,
            "≥ 0",
        )?;
        c.at_least("nbv.ray_subsample", self.ray_subsample.into(), 1)?;
        c.at_least("nbv.rolls", self.rolls.into(), 1)?;
        c.within(
            "nbv.visited_min_distance",
            self.visited_min_distance,
            0.0,
            10.0,
            "[0, 10] m",
        )?;
        c.at_least(
            "nbv.max_views_per_object",
            self.max_views_per_object.into(),
            1,
        )?;
        c.at_least("nbv.frames_per_view", self.frames_per_view.into(), 1)?;
        c.within(
            "nbv.return_share",
            self.return_share,
            0.0,
            1.0 - f64::EPSILON,
            "[0, 1)",
        )?;
        c.within(
            "nbv.depth_smoothing",
            self.depth_smoothing.into(),
            0.0,
            8.0,
            "[0, 8] pixels",
        )?;
        c.within("nbv.cost_weight", self.cost_weight, 0.0, f64::MAX, "≥ 0")?;
        c.within(
            "nbv.relative_gain",
            self.relative_gain,
            0.0,
            1.0 - f64::EPSILON,
            "[0, 1)",
        )?;
        c.within(
            "nbv.new_surface",
            self.new_surface,
            0.0,
            1.0 - f64::EPSILON,
            "[0, 1)",
        )?;
        c.at_least("nbv.new_surface_views", self.new_surface_views.into(), 1)?;
        Ok(())
    }
}
