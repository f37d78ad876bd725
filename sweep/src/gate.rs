//! [`Gate`]: a `--require METRIC OP VALUE` threshold on a sweep's aggregate (e.g.
//! `f_score>=0.8`, `collisions==0`), parsed from the command line and checked against the
//! [`Aggregate`](crate::rows::Aggregate).

use crate::rows::Aggregate;
use serde::Serialize;
use std::str::FromStr;

/// A comparison operator.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum Op {
    /// `>=`
    Ge,
    /// `<=`
    Le,
    /// `==`
    Eq,
    /// `>`
    Gt,
    /// `<`
    Lt,
}

impl Op {
    fn text(self) -> &'static str {
        match self {
            Self::Ge => ">=",
            Self::Le => "<=",
            Self::Eq => "==",
            Self::Gt => ">",
            Self::Lt => "<",
        }
    }

    fn holds(self, a: f64, b: f64) -> bool {
        match self {
            Self::Ge => a >= b,
            Self::Le => a <= b,
            Self::Eq => a == b,
            Self::Gt => a > b,
            Self::Lt => a < b,
        }
    }
}

/// `METRIC OP VALUE`, e.g. `coverage>=0.9`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Gate {
    /// An [`Aggregate`] metric name.
    pub metric: String,
    /// The comparison.
    pub op: Op,
    /// The threshold.
    pub value: f64,
}

impl FromStr for Gate {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        let s = s.trim();
        // Two-character operators first.
        for (text, op) in [
            (">=", Op::Ge),
            ("<=", Op::Le),
            ("==", Op::Eq),
            (">", Op::Gt),
            ("<", Op::Lt),
        ] {
            if let Some(at) = s.find(text) {
                let metric = s[..at].trim().to_string();
                let value_text = s[at + text.len()..].trim();
                if Aggregate::of(&[]).metric(&metric).is_none() {
                    return Err(format!(
                        "`{s}`: unknown metric `{metric}` (one of: {})",
                        Aggregate::METRICS.join(", ")
                    ));
                }
                let value: f64 = value_text
                    .parse()
                    .ok()
                    .filter(|v: &f64| v.is_finite())
                    .ok_or_else(|| format!("`{s}`: `{value_text}` is not a finite number"))?;
                return Ok(Self { metric, op, value });
            }
        }
        Err(format!(
            "`{s}`: expected METRIC OP VALUE with OP one of >=, <=, ==, >, < (e.g. coverage>=0.9)"
        ))
    }
}

/// A gate's outcome.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GateResult {
    /// The gate as written back (`coverage>=0.9`).
    pub gate: String,
    /// The measured value.
    pub measured: f64,
    /// Whether it holds.
    pub pass: bool,
}

impl Gate {
    /// Checks the gate on an aggregate.
    pub fn check(&self, a: &Aggregate) -> GateResult {
        let measured = a.metric(&self.metric).unwrap_or(f64::NAN);
        GateResult {
            gate: format!("{}{}{}", self.metric, self.op.text(), self.value),
            measured,
            pass: self.op.holds(measured, self.value),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn parse_and_check() {
        let a = Aggregate {
            coverage: 0.85,
            collisions: 0,
            ..Aggregate::default()
        };
        let g: Gate = "coverage>=0.9".parse().unwrap();
        assert_eq!((g.op, g.value), (Op::Ge, 0.9));
        let r = g.check(&a);
        assert!(!r.pass && r.measured == 0.85 && r.gate == "coverage>=0.9");
        assert!("collisions == 0".parse::<Gate>().unwrap().check(&a).pass);
        // The F-score: no episode scores 0, and 0.85 passes 0.8.
        let g: Gate = "f_score >= 0.8".parse().unwrap();
        assert!(!g.check(&a).pass);
        let f = Aggregate {
            f_score: 0.85,
            ..Aggregate::default()
        };
        assert!(g.check(&f).pass && g.check(&f).gate == "f_score>=0.8");
        assert!("coverage < 0.9".parse::<Gate>().unwrap().check(&a).pass);
        assert!(
            "speed>=1"
                .parse::<Gate>()
                .unwrap_err()
                .contains("unknown metric `speed`")
        );
        assert!(
            "coverage>=x"
                .parse::<Gate>()
                .unwrap_err()
                .contains("not a finite number")
        );
        assert!(
            "coverage"
                .parse::<Gate>()
                .unwrap_err()
                .contains("METRIC OP VALUE")
        );
    }

    proptest! {
        /// Every metric and operator round-trips through its text.
        #[test]
        fn round_trip(m in 0usize..Aggregate::METRICS.len(), op in 0usize..5, v in -1e6f64..1e6) {
            let ops = [">=", "<=", "==", ">", "<"];
            let text = format!("{}{}{}", Aggregate::METRICS[m], ops[op], v);
            let g: Gate = text.parse().unwrap();
            prop_assert_eq!(g.metric.as_str(), Aggregate::METRICS[m]);
            prop_assert_eq!(g.op.text(), ops[op]);
            prop_assert_eq!(g.value, v);
        }
    }
}
