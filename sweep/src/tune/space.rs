//! [`Space`]: the tuned parameters as the optimiser sees them — one coordinate each (the
//! logarithm of a `log` range, an integer, or a choice's index) — and back to the scene
//! values a trial runs with. Real values are kept to four significant digits, so a
//! trial's parameters print, store and re-run exactly.

use crate::tune::spec::{Parameter, Range};
use egobox_ego::XType;

/// The search space of a tune file's parameters.
#[derive(Debug, Clone)]
pub struct Space {
    params: Vec<Parameter>,
}

/// `x` to four significant digits.
fn four_digits(x: f64) -> f64 {
    if x == 0.0 || !x.is_finite() {
        return x;
    }
    let scale = 10f64.powi(3 - x.abs().log10().floor() as i32);
    (x * scale).round() / scale
}

impl Space {
    /// The space of `params`.
    pub fn new(params: &[Parameter]) -> Self {
        Self {
            params: params.to_vec(),
        }
    }

    /// Its dimension.
    pub fn dim(&self) -> usize {
        self.params.len()
    }

    /// The coordinates' types for egobox.
    pub fn xtypes(&self) -> Vec<XType> {
        self.params
            .iter()
            .map(|p| match &p.range {
                Range::Float { min, max, log } if *log => XType::Float(min.ln(), max.ln()),
                Range::Float { min, max, .. } => XType::Float(*min, *max),
                Range::Int { min, max } => XType::Int(*min as i32, *max as i32),
                Range::Choice(c) => XType::Enum(c.len()),
            })
            .collect()
    }

    /// The point at `u` in the unit cube (each coordinate in `[0, 1)`), snapped to the
    /// values a trial can take.
    pub fn from_unit(&self, u: &[f64]) -> Vec<f64> {
        let x: Vec<f64> = self
            .params
            .iter()
            .zip(u)
            .map(|(p, &u)| {
                let u = u.clamp(0.0, 1.0);
                match &p.range {
                    Range::Float { min, max, log } if *log => min.ln() + u * (max.ln() - min.ln()),
                    Range::Float { min, max, .. } => min + u * (max - min),
                    Range::Int { min, max } => {
                        let n = (max - min + 1) as f64;
                        (*min as f64 + (u * n).floor()).min(*max as f64)
                    }
                    Range::Choice(c) => (u * c.len() as f64).floor().min(c.len() as f64 - 1.0),
                }
            })
            .collect();
        self.snap(&x)
    }

    /// `x` snapped to the values a trial can take (four digits, integers, indices).
    pub fn snap(&self, x: &[f64]) -> Vec<f64> {
        self.params
            .iter()
            .zip(x)
            .map(|(p, &x)| match &p.range {
                Range::Float { min, max, log } if *log => {
                    four_digits(x.exp().clamp(*min, *max)).ln()
                }
                Range::Float { min, max, .. } => four_digits(x.clamp(*min, *max)),
                Range::Int { min, max } => x.round().clamp(*min as f64, *max as f64),
                Range::Choice(c) => x.round().clamp(0.0, c.len() as f64 - 1.0),
            })
            .collect()
    }

    /// The scene values of the point `x`: `(dotted key, value)` in the file's order.
    pub fn values(&self, x: &[f64]) -> Vec<(String, toml::Value)> {
        self.params
            .iter()
            .zip(self.snap(x))
            .map(|(p, x)| {
                let v = match &p.range {
                    Range::Float { log: true, .. } => toml::Value::Float(four_digits(x.exp())),
                    Range::Float { .. } => toml::Value::Float(x),
                    Range::Int { .. } => toml::Value::Integer(x as i64),
                    Range::Choice(c) => c[x as usize].clone(),
                };
                (p.key.clone(), v)
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn space() -> Space {
        Space::new(&[
            Parameter {
                key: "nbv.alpha_u".into(),
                range: Range::Float {
                    min: 0.5,
                    max: 8.0,
                    log: true,
                },
            },
            Parameter {
                key: "nbv.gain_threshold".into(),
                range: Range::Float {
                    min: 1.0,
                    max: 20.0,
                    log: false,
                },
            },
            Parameter {
                key: "nbv.max_views_per_object".into(),
                range: Range::Int { min: 4, max: 16 },
            },
            Parameter {
                key: "nbv.objective".into(),
                range: Range::Choice(vec!["paper".into(), "rear-side-entropy".into()]),
            },
        ])
    }

    #[test]
    fn corners_map_to_the_bounds() {
        let s = space();
        let lo = s.values(&s.from_unit(&[0.0; 4]));
        assert_eq!(lo[0].1, toml::Value::Float(0.5));
        assert_eq!(lo[1].1, toml::Value::Float(1.0));
        assert_eq!(lo[2].1, toml::Value::Integer(4));
        assert_eq!(lo[3].1, toml::Value::String("paper".into()));
        let hi = s.values(&s.from_unit(&[0.999_999; 4]));
        assert_eq!(hi[0].1, toml::Value::Float(8.0));
        assert_eq!(hi[2].1, toml::Value::Integer(16));
        assert_eq!(hi[3].1, toml::Value::String("rear-side-entropy".into()));
        // The middle of a log range is the geometric mean.
        assert_eq!(
            s.values(&s.from_unit(&[0.5; 4]))[0].1,
            toml::Value::Float(2.0)
        );
    }

    proptest! {
        /// Snapping is idempotent and keeps every value in its range: the point a trial
        /// stores is the point it ran.
        #[test]
        fn snapped_points_stay_put_and_in_range(u in prop::array::uniform4(0.0f64..1.0)) {
            let s = space();
            let x = s.from_unit(&u);
            prop_assert_eq!(s.snap(&x), x.clone());
            for ((_, v), p) in s.values(&x).iter().zip(&s.params) {
                match (&p.range, v) {
                    (Range::Float { min, max, .. }, toml::Value::Float(v)) => {
                        prop_assert!(v >= min && v <= max);
                    }
                    (Range::Int { min, max }, toml::Value::Integer(v)) => {
                        prop_assert!(v >= min && v <= max);
                    }
                    (Range::Choice(c), v) => prop_assert!(c.contains(v)),
                    other => prop_assert!(false, "{:?}", other),
                }
            }
        }
    }
}
