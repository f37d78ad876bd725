//! `[nbv]` as nbv-core's types: Algorithm 2's [`NbvParams`] and the [`StopRule`].

use crate::schema::{GainMeasureName, Nbv};
use nbv_core::nbv::{GainMeasure, NbvParams, ScoreWeights, StopRule, ViewSphere};

impl Nbv {
    /// Algorithm 2's parameters: the sphere, eq. (4)'s weights, the ray subsampling.
    ///
    /// ```
    /// let p = nbv_scenes::schema::Nbv::default().params();
    /// assert_eq!((p.sphere.radius, p.weights.unknown, p.ray_stride), (0.45, 4.0, 8));
    /// ```
    pub fn params(&self) -> NbvParams {
        NbvParams {
            sphere: ViewSphere {
                radius: self.radius,
                delta_theta: self.dtheta_deg.to_radians(),
                theta_max: self.theta_max_deg.to_radians(),
                delta_phi: self.dphi_deg.to_radians(),
                near_radius: self.near_radius,
            },
            weights: ScoreWeights {
                unknown: self.alpha_u,
                occupied: self.alpha_o,
            },
            ray_stride: self.ray_subsample.max(1) as usize,
            roll_candidates: self.rolls.max(1) as usize,
            objective: self.objective,
            cost_weight: self.cost_weight,
            object_surface: self.object_surface,
            hull_score: self.hull_score,
            free_above_objects: self.free_above_objects,
            ..NbvParams::default()
        }
    }

    /// The stop rule: the latest view's gain (by `gain_measure`) against `gain_threshold`.
    ///
    /// ```
    /// use nbv_core::nbv::GainMeasure;
    /// let rule = nbv_scenes::schema::Nbv::default().stop_rule();
    /// assert_eq!((rule.gain_threshold, rule.measure), (2.5, GainMeasure::BernoulliKl));
    /// ```
    pub fn stop_rule(&self) -> StopRule {
        StopRule {
            gain_threshold: self.gain_threshold,
            measure: match self.gain_measure {
                GainMeasureName::Eq5 => GainMeasure::Eq5,
                GainMeasureName::Kl => GainMeasure::BernoulliKl,
            },
            relative_gain: self.relative_gain,
            new_surface: self.new_surface,
            new_surface_views: self.new_surface_views as usize,
        }
    }
}
