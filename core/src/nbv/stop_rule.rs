//! [`StopRule`]: when the short-range exploration of an object ends (Algorithm 1, line 10):
//! the information gain of the latest view fell below `gain_thr`, or no viewpoint is left;
//! optionally, the best candidate's objective value fell below a share of what the best
//! candidate of the object's first round promised (the relative-gain rule). The view cap,
//! the reference implementation's only rule, is the pipeline's `max_views_per_object`.

use super::{InformationGain, NbvError};

/// Why the exploration of an object stops.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum StopReason {
    /// The latest view's gain (by the rule's measure) is below the threshold.
    LowGain {
        /// The gain measure of the latest view.
        gain: f64,
        /// The threshold.
        threshold: f64,
    },
    /// No candidate viewpoint is left (all unreachable, visited, or failed to plan).
    NoViewpoint,
    /// The best candidate's objective value is below `ratio` × the best value of the
    /// object's first round.
    RelativeGain {
        /// The best candidate's value now.
        gain: f64,
        /// The best value of the first round.
        first: f64,
        /// The ratio.
        ratio: f64,
    },
    /// The best candidate would see less of the object's unseen hull than the
    /// new-surface threshold's share of the hull ([`HullSurface`](super::HullSurface)).
    NoUnseenHull {
        /// The best candidate's unseen area as a share of the hull's area.
        share: f64,
        /// The threshold.
        threshold: f64,
    },
    /// The latest views each added less new surface than the threshold
    /// ([`SurfaceSides`](super::SurfaceSides)).
    NoNewSurface {
        /// The latest view's share of new surface.
        share: f64,
        /// The threshold.
        threshold: f64,
        /// How many views in a row fell below it.
        views: usize,
    },
}

/// Which number of an [`InformationGain`] the stop rule compares with `gain_thr`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum GainMeasure {
    /// G of eq. (5) as printed ([`InformationGain::total`]); can be negative.
    #[default]
    Eq5,
    /// The Bernoulli Kullback–Leibler divergence ([`InformationGain::bernoulli_kl`]);
    /// never negative.
    BernoulliKl,
}

impl GainMeasure {
    /// The measure's value for a gain.
    pub fn value(&self, gain: &InformationGain) -> f64 {
        match self {
            Self::Eq5 => gain.total,
            Self::BernoulliKl => gain.bernoulli_kl,
        }
    }
}

/// The stop rule with its threshold and measure.
///
/// The paper gives no value for `gain_thr`. Default: the twin preset's
/// ([`NbvPreset::stop_rule`](super::NbvPreset::stop_rule), beside the paper's), on the
/// Bernoulli KL divergence.
///
/// Behaviour of the literal G (see [`InformationGain`]): every voxel a view *hits* adds a
/// negative term, so a view of surface gives a negative G even when it uncovers much. On
/// the synthetic table-top scene of the tests, the best first short-range view of the
/// cylinder gives G = −33.3 (+10.4 from voxels seen free, −43.7 from voxels hit) over
/// |O_v| = 770 voxels, while its Bernoulli KL divergence is +25.6: with
/// [`GainMeasure::Eq5`] the exploration of an object stops after its first short-range view
/// for any threshold above −33, whereas the paper reports about five views per object.
/// [`GainMeasure::BernoulliKl`] is offered for the pipeline to choose.
///
/// ```
/// use nbv_core::nbv::{InformationGain, StopReason, StopRule};
/// let rule = StopRule::default();
/// assert_eq!(rule.check(None, 3), None); // no view yet: go on
/// let g = InformationGain { total: 0.1, ..Default::default() };
/// assert!(matches!(rule.check(Some(&g), 3), Some(StopReason::LowGain { .. })));
/// assert_eq!(rule.check(None, 0), Some(StopReason::NoViewpoint));
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StopRule {
    /// gain_thr: stop when the measure < gain_thr (finite).
    pub gain_threshold: f64,
    /// What is compared.
    pub measure: GainMeasure,
    /// The relative-gain rule's ratio in [0, 1): stop when the best candidate's objective
    /// value is below it times the first round's best (0, the default: off).
    pub relative_gain: f64,
    /// The new-surface rule: stop when each of the latest [`new_surface_views`] views
    /// added less than this share of new surface
    /// ([`new_surface_share`](super::new_surface_share)); 0: off.
    ///
    /// [`new_surface_views`]: Self::new_surface_views
    pub new_surface: f64,
    /// Views in a row the new-surface rule waits for (≥ 1 when the rule is on).
    pub new_surface_views: usize,
}

impl Default for StopRule {
    fn default() -> Self {
        super::NbvPreset::default().stop_rule()
    }
}

impl StopRule {
    /// Checks that the threshold is finite and the ratio in [0, 1).
    pub fn validate(&self) -> Result<(), NbvError> {
        if !self.gain_threshold.is_finite() {
            return Err(NbvError::InvalidParameter {
                name: "gain_thr",
                value: self.gain_threshold,
                reason: "must be finite",
            });
        }
        if !(self.relative_gain >= 0.0 && self.relative_gain < 1.0) {
            return Err(NbvError::InvalidParameter {
                name: "relative_gain",
                value: self.relative_gain,
                reason: "must be in [0, 1)",
            });
        }
        if !(self.new_surface >= 0.0 && self.new_surface < 1.0) {
            return Err(NbvError::InvalidParameter {
                name: "new_surface",
                value: self.new_surface,
                reason: "must be in [0, 1)",
            });
        }
        if self.new_surface > 0.0 && self.new_surface_views == 0 {
            return Err(NbvError::InvalidParameter {
                name: "new_surface_views",
                value: 0.0,
                reason: "must be >= 1 when new_surface > 0",
            });
        }
        Ok(())
    }

    /// The new-surface rule: `shares` are the new-surface shares of the object's views so
    /// far, in order. Off at a threshold of 0.
    ///
    /// ```
    /// use nbv_core::nbv::{NbvPreset, StopReason, StopRule};
    /// let rule = StopRule { new_surface: 0.02, new_surface_views: 2, ..StopRule::default() };
    /// assert_eq!(rule.check_new_surface(&[0.3, 0.01]), None); // one low view
    /// assert!(matches!(rule.check_new_surface(&[0.3, 0.01, 0.005]), Some(StopReason::NoNewSurface { views: 2, .. })));
    /// assert_eq!(rule.check_new_surface(&[0.3, 0.01, 0.05]), None);
    /// assert_eq!(NbvPreset::Paper.stop_rule().check_new_surface(&[0.0, 0.0, 0.0]), None);
    /// ```
    pub fn check_new_surface(&self, shares: &[f64]) -> Option<StopReason> {
        let k = self.new_surface_views;
        if self.new_surface <= 0.0 || k == 0 || shares.len() < k {
            return None;
        }
        let recent = &shares[shares.len() - k..];
        recent
            .iter()
            .all(|&s| s < self.new_surface)
            .then(|| StopReason::NoNewSurface {
                share: recent[k - 1],
                threshold: self.new_surface,
                views: k,
            })
    }

    /// The new-surface rule on what the best candidate would see, with the hull score:
    /// `unseen` is its unseen hull area, `hull` the hull's area (both m²). Off at a
    /// threshold of 0 or without a hull.
    ///
    /// ```
    /// use nbv_core::nbv::{StopReason, StopRule};
    /// let rule = StopRule { new_surface: 0.005, ..StopRule::default() };
    /// assert_eq!(rule.check_unseen_hull(0.0002, 0.03), None); // 0.7 % of the hull
    /// assert!(matches!(rule.check_unseen_hull(0.0001, 0.03), Some(StopReason::NoUnseenHull { .. })));
    /// assert_eq!(rule.check_unseen_hull(0.0, 0.0), None);
    /// ```
    pub fn check_unseen_hull(&self, unseen: f64, hull: f64) -> Option<StopReason> {
        (self.new_surface > 0.0 && hull > 0.0 && unseen < self.new_surface * hull).then_some(
            StopReason::NoUnseenHull {
                share: unseen / hull,
                threshold: self.new_surface,
            },
        )
    }

    /// The relative-gain rule: `best` is the best candidate's objective value now, `first`
    /// the best of the object's first round. Off (never stops) at ratio 0 or with a first
    /// value ≤ 0.
    ///
    /// ```
    /// use nbv_core::nbv::{StopReason, StopRule};
    /// let rule = StopRule { relative_gain: 0.1, ..StopRule::default() };
    /// assert_eq!(rule.check_relative(200.0, 25.0), None);
    /// assert!(matches!(rule.check_relative(200.0, 19.0), Some(StopReason::RelativeGain { .. })));
    /// assert_eq!(StopRule::default().check_relative(200.0, 0.0), None);
    /// ```
    pub fn check_relative(&self, first: f64, best: f64) -> Option<StopReason> {
        (self.relative_gain > 0.0 && first > 0.0 && best < self.relative_gain * first).then_some(
            StopReason::RelativeGain {
                gain: best,
                first,
                ratio: self.relative_gain,
            },
        )
    }

    /// Whether to stop, given the latest view's gain (`None` before the first short-range
    /// view: the paper starts with gain = ∞) and the number of candidate viewpoints left.
    /// The gain is tested first.
    pub fn check(
        &self,
        latest: Option<&InformationGain>,
        candidates_left: usize,
    ) -> Option<StopReason> {
        if let Some(g) = latest
            && self.measure.value(g) < self.gain_threshold
        {
            return Some(StopReason::LowGain {
                gain: self.measure.value(g),
                threshold: self.gain_threshold,
            });
        }
        (candidates_left == 0).then_some(StopReason::NoViewpoint)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn threshold_is_strict_and_gain_first() {
        let rule = StopRule {
            gain_threshold: 1.0,
            measure: GainMeasure::Eq5,
            ..StopRule::default()
        };
        let g = |total| InformationGain {
            total,
            ..Default::default()
        };
        assert_eq!(rule.check(Some(&g(1.0)), 5), None);
        assert_eq!(
            rule.check(Some(&g(0.999)), 5),
            Some(StopReason::LowGain {
                gain: 0.999,
                threshold: 1.0
            })
        );
        assert!(matches!(
            rule.check(Some(&g(-2.0)), 0),
            Some(StopReason::LowGain { .. })
        ));
        assert_eq!(rule.check(Some(&g(3.0)), 0), Some(StopReason::NoViewpoint));
        assert!(
            StopRule {
                gain_threshold: f64::NAN,
                ..StopRule::default()
            }
            .validate()
            .is_err()
        );
        // The KL measure reads its own field.
        let kl = StopRule {
            gain_threshold: 1.0,
            measure: GainMeasure::BernoulliKl,
            ..StopRule::default()
        };
        let g = InformationGain {
            total: -5.0,
            bernoulli_kl: 2.0,
            ..Default::default()
        };
        assert_eq!(kl.check(Some(&g), 5), None);
        assert!(rule.check(Some(&g), 5).is_some());
        let bad = StopRule {
            relative_gain: 1.0,
            ..StopRule::default()
        };
        assert!(bad.validate().is_err());
    }
}
