//! [`NbvPreset`]: the two sets of Algorithm 2's parameters and stop rule the project
//! ships — the paper's, for reproductions, and the twin's, the default. Every default of
//! [`NbvParams`], [`StopRule`] and [`ViewSphere`] is written here once; a scene's `[nbv]`
//! section reads them.

use serde::{Deserialize, Serialize};

use super::{
    GainMeasure, HullScore, NbvParams, Objective, ScoreWeights, StopRule, ViewSphere,
    VisibilityForm,
};

/// Where the parameters of Algorithm 2 and its stop rule come from.
///
/// ```
/// use nbv_core::nbv::{NbvParams, NbvPreset, StopRule};
/// let (paper, twin) = (NbvPreset::Paper.params(), NbvPreset::Twin.params());
/// assert_eq!((paper.sphere.radius, twin.sphere.radius), (0.3, 0.45));
/// assert_eq!(NbvParams::default(), twin);
/// assert_eq!(StopRule::default(), NbvPreset::Twin.stop_rule());
/// assert_eq!(NbvPreset::Paper.stop_rule().new_surface, 0.0); // the paper's stop rules only
/// assert_eq!(NbvPreset::Paper.max_views_per_object(), 10);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum NbvPreset {
    /// For the twin's and the real rig's Dinast (1–2 cm of range noise at 0.3–0.45 m): a
    /// wider, denser viewing sphere (r 0.45 m, Δθ 10°, Δφ 20°, 0.3 m where 0.45 is out of
    /// reach), eq. (4) counting the object's surface, a lower gain threshold (2.5), the
    /// new-surface stop rule and 16 views at most. Chosen over generated scenes, where the paper's values leave far
    /// sides unseen (`examples/sweeps/nbv_presets.toml`, docs/presets.md).
    #[default]
    Twin,
    /// The paper's (Aleotti et al. 2014): r 0.3 m, Δθ 15°, Δφ 30°, eq. (4) as printed,
    /// threshold 5 (assumed: the paper gives none), 10 views at most — for reproductions.
    Paper,
}

impl NbvPreset {
    /// The viewing sphere. The paper gives no values for Δθ, θ_max and Δφ: 15°, 75° (down
    /// to 15° above the horizontal plane through the centroid, which keeps the arm above
    /// the table) and 30° with its r = 0.3 m give 1 + 5·12 = 61 samples.
    pub fn sphere(self) -> ViewSphere {
        match self {
            Self::Paper => ViewSphere {
                radius: 0.3,
                delta_theta: 15f64.to_radians(),
                theta_max: 75f64.to_radians(),
                delta_phi: 30f64.to_radians(),
                near_radius: 0.0,
            },
            Self::Twin => ViewSphere {
                radius: 0.45,
                delta_theta: 10f64.to_radians(),
                theta_max: 75f64.to_radians(),
                delta_phi: 20f64.to_radians(),
                near_radius: 0.3,
            },
        }
    }

    /// Algorithm 2's parameters: the sphere, the paper's (α_u, α_o) = (4, 1), every 8th
    /// Dinast pixel in u and v (1200 rays; the paper does not say how D was subsampled),
    /// four rolls about the optical axis (eq. (3)'s first), eq. (4) ranking, and — twin
    /// only — eq. (4) counting the object's surface, the unseen hull ranking an object's
    /// candidates from its first view and eq. (4) taking it over where the hull sees nothing
    /// left ([`HullScore::First`]), and the unknown space above the objects free for the
    /// planner.
    pub fn params(self) -> NbvParams {
        NbvParams {
            sphere: self.sphere(),
            weights: ScoreWeights::default(),
            ray_stride: 8,
            roll_candidates: 4,
            visibility: VisibilityForm::Dda,
            objective: Objective::Paper,
            cost_weight: 0.0,
            object_surface: self == Self::Twin,
            hull_score: match self {
                Self::Paper => HullScore::Off,
                Self::Twin => HullScore::First,
            },
            free_above_objects: self == Self::Twin,
        }
    }

    /// The stop rule: the Bernoulli KL divergence of the latest view below 5 nats (paper)
    /// or 2.5 (twin); the relative-gain rule off; the new-surface rule off (paper) or at 0.5 %
    /// over two views in a row (twin).
    pub fn stop_rule(self) -> StopRule {
        let paper = StopRule {
            gain_threshold: 5.0,
            measure: GainMeasure::BernoulliKl,
            relative_gain: 0.0,
            new_surface: 0.0,
            new_surface_views: 2,
        };
        match self {
            Self::Paper => paper,
            Self::Twin => StopRule {
                gain_threshold: 2.5,
                new_surface: 0.005,
                ..paper
            },
        }
    }

    /// The share of a burst's frames a pixel must return in, more than which it is kept in
    /// the averaged frame ([`average_frames`](crate::rig::average_frames)): 0.5, the
    /// majority (paper), 0.2 (twin: two of eight frames). A surface seen at 60–80° of
    /// incidence returns in a few frames of a burst, and the majority dropped it: on
    /// `examples/sweeps/exploration_hull.toml`, 11 → 13 objects of 14 at 95 % of their
    /// ceiling with the hull score (docs/exploration.md, "A burst keeps its grazing
    /// returns").
    pub fn return_share(self) -> f64 {
        match self {
            Self::Paper => 0.5,
            Self::Twin => 0.2,
        }
    }

    /// The cap on short-range views per object: 10 (paper: it averages 5–6), 16 (twin).
    pub fn max_views_per_object(self) -> usize {
        match self {
            Self::Paper => 10,
            Self::Twin => 16,
        }
    }
}
