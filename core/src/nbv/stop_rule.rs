//! [`StopRule`]: when the short-range exploration of an object ends (Algorithm 1, line 10):
//! the information gain of the latest view fell below `gain_thr`, or no viewpoint is left.

use super::{InformationGain, NbvError};

/// Why the exploration of an object stops.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum StopReason {
    /// The latest view's gain G (eq. (5)) is below the threshold.
    LowGain {
        /// G of the latest view.
        gain: f64,
        /// The threshold.
        threshold: f64,
    },
    /// No candidate viewpoint is left (all unreachable, visited, or failed to plan).
    NoViewpoint,
}

/// The stop rule with its threshold.
///
/// The paper gives no value for `gain_thr`. Default 0.5: about two unknown voxels cleared
/// (0.2554 each with p̄ = 0.7, see [`InformationGain`]) net of what re-observed surface
/// subtracts; a view whose O_v mostly re-observes known surface yields G ≤ 0 and stops.
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
    /// gain_thr: stop when G < gain_thr (finite).
    pub gain_threshold: f64,
}

impl Default for StopRule {
    fn default() -> Self {
        Self {
            gain_threshold: 0.5,
        }
    }
}

impl StopRule {
    /// Checks that the threshold is finite.
    pub fn validate(&self) -> Result<(), NbvError> {
        if self.gain_threshold.is_finite() {
            Ok(())
        } else {
            Err(NbvError::InvalidParameter {
                name: "gain_thr",
                value: self.gain_threshold,
                reason: "must be finite",
            })
        }
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
            && g.total < self.gain_threshold
        {
            return Some(StopReason::LowGain {
                gain: g.total,
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
                gain_threshold: f64::NAN
            }
            .validate()
            .is_err()
        );
    }
}
