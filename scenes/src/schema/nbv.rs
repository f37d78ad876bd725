//! [`Nbv`]: the next-best-view search of Algorithm 2 and its stopping rule.

use serde::{Deserialize, Serialize};

/// Viewpoints on a sphere of radius `r` around the object centroid at inclinations
/// `θ = Δθ·i ≤ θ_max` and azimuths `φ = −π + Δφ·i` (eq. (3)), scored by
/// `α_u·|O_u| + α_o·|O_o|` (eq. (4)); an object is done when the information gain
/// (eq. (5)) of the latest view falls below `gain_threshold`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Nbv {
    /// Viewing-sphere radius `r` (m). Default 0.3 (paper).
    pub radius: f64,
    /// Inclination step `Δθ` (degrees). Default 15.
    pub dtheta_deg: f64,
    /// Largest inclination `θ_max` (degrees from straight above). Default 75.
    pub theta_max_deg: f64,
    /// Azimuth step `Δφ` (degrees). Default 30.
    pub dphi_deg: f64,
    /// Weight `α_u` of unknown voxels. Default 4 (paper).
    pub alpha_u: f64,
    /// Weight `α_o` of occupied voxels. Default 1 (paper).
    pub alpha_o: f64,
    /// Stop an object when the latest view's gain (nats, by `gain_measure`) is below
    /// this. Default 5.0 (assumed; the paper does not give its value).
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
    /// Hard cap on short-range views per object. Default 10 (the paper averages 5–6).
    pub max_views_per_object: u32,
    /// Depth frames averaged at each viewpoint (and each short-only survey pose): the
    /// camera's range noise falls by the square root. Default 8 (a quarter of a second at
    /// 30 Hz); 1 takes a single frame.
    pub frames_per_view: u32,
}

impl Default for Nbv {
    fn default() -> Self {
        Self {
            radius: 0.3,
            dtheta_deg: 15.0,
            theta_max_deg: 75.0,
            dphi_deg: 30.0,
            alpha_u: 4.0,
            alpha_o: 1.0,
            gain_threshold: 5.0,
            gain_measure: GainMeasureName::Kl,
            rolls: 4,
            ray_subsample: 8,
            visited_min_distance: 0.08,
            max_views_per_object: 10,
            frames_per_view: 8,
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
