//! [`Shard`]: `I/N`, the part of a sweep one machine runs — episode `k` belongs to shard
//! `k mod N`, so a batch scheduler's array index picks it.

use serde::{Deserialize, Serialize};

/// `I/N`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Shard {
    /// This shard, 0-based.
    pub index: usize,
    /// Shards in all.
    pub count: usize,
}

impl Shard {
    /// Whether episode `k` of the grid belongs to `shard` (every episode without one).
    pub fn holds(shard: Option<Self>, k: usize) -> bool {
        shard.is_none_or(|s| k % s.count == s.index)
    }
}

impl std::str::FromStr for Shard {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        let bad = || format!("`{s}`: expected I/N with 0 <= I < N (e.g. 0/3)");
        let (i, n) = s.split_once('/').ok_or_else(bad)?;
        let (index, count) = (
            i.trim().parse().map_err(|_| bad())?,
            n.trim().parse().map_err(|_| bad())?,
        );
        if count == 0 || index >= count {
            return Err(bad());
        }
        Ok(Self { index, count })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_parse() {
        assert_eq!(
            "1/3".parse::<Shard>().unwrap(),
            Shard { index: 1, count: 3 }
        );
        assert!("3/3".parse::<Shard>().is_err());
        assert!("0/0".parse::<Shard>().is_err());
        assert!("x".parse::<Shard>().unwrap_err().contains("I/N"));
    }

    #[test]
    fn every_episode_is_in_exactly_one_shard() {
        for count in 1..5 {
            for k in 0..20 {
                let n = (0..count)
                    .filter(|&index| Shard::holds(Some(Shard { index, count }), k))
                    .count();
                assert_eq!(n, 1);
            }
        }
        assert!(Shard::holds(None, 7));
    }
}
