//! [`CoverSets`]: which surface samples each candidate view covers, as bitsets, and the
//! greedy set cover over them (take the view that adds the most uncovered samples,
//! repeat): within (1 − 1/e) of the best coverage for any number of views (Nemhauser,
//! Wolsey & Fisher 1978), and the yardstick SCVP labels its training data with.

/// The samples a base observation covers and, per candidate view, the samples it covers.
///
/// ```
/// use nbv_sweep::oracle::CoverSets;
/// let mut sets = CoverSets::new(6, &[0]);
/// sets.push(&[1, 2, 3]);
/// sets.push(&[3, 4]);
/// sets.push(&[4, 5]);
/// assert_eq!(sets.union_count(), 6);
/// let greedy = sets.greedy();
/// assert_eq!(greedy.picks, vec![0, 2]); // {1,2,3} then {4,5}
/// assert_eq!(greedy.covered, vec![1, 4, 6]);
/// ```
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CoverSets {
    samples: usize,
    base: Vec<u64>,
    sets: Vec<Vec<u64>>,
}

/// The greedy cover: the views in the order taken and the samples covered before the first
/// and after each.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct GreedyCover {
    /// Indices of the views taken, in order (each adds at least one sample).
    pub picks: Vec<usize>,
    /// `covered[0]` by the base alone, `covered[k]` after `k` views; the last is the
    /// union of everything.
    pub covered: Vec<usize>,
}

impl CoverSets {
    /// No view yet; `samples` samples of which the base observation covers `base`
    /// (indices; those out of range are ignored).
    pub fn new(samples: usize, base: &[usize]) -> Self {
        Self {
            samples,
            base: bits(samples, base),
            sets: Vec::new(),
        }
    }

    /// Adds a view covering the samples `covered` (indices; out of range ignored).
    pub fn push(&mut self, covered: &[usize]) {
        self.sets.push(bits(self.samples, covered));
    }

    /// Adds a view from a mask over the samples (`mask[i]`: sample `i` covered).
    pub fn push_mask(&mut self, mask: &[bool]) {
        let covered: Vec<usize> = (0..mask.len().min(self.samples))
            .filter(|&i| mask[i])
            .collect();
        self.push(&covered);
    }

    /// The number of views.
    pub fn len(&self) -> usize {
        self.sets.len()
    }

    /// Whether there is no view.
    pub fn is_empty(&self) -> bool {
        self.sets.is_empty()
    }

    /// The number of samples.
    pub fn samples(&self) -> usize {
        self.samples
    }

    /// Samples the base covers.
    pub fn base_count(&self) -> usize {
        count(&self.base)
    }

    /// Samples the base and the views `views` cover together.
    pub fn count_with(&self, views: impl IntoIterator<Item = usize>) -> usize {
        let mut covered = self.base.clone();
        for v in views {
            or_into(&mut covered, &self.sets[v]);
        }
        count(&covered)
    }

    /// Samples the base and every view cover: the ceiling.
    pub fn union_count(&self) -> usize {
        count(&self.union_bits())
    }

    /// The samples neither the base nor any view covers, in order.
    pub fn uncovered(&self) -> Vec<usize> {
        let union = self.union_bits();
        (0..self.samples)
            .filter(|&i| union[i / 64] & (1 << (i % 64)) == 0)
            .collect()
    }

    fn union_bits(&self) -> Vec<u64> {
        let mut covered = self.base.clone();
        for s in &self.sets {
            or_into(&mut covered, s);
        }
        covered
    }

    /// The greedy cover: repeatedly the view adding the most uncovered samples (the lowest
    /// index among equals), until no view adds any.
    pub fn greedy(&self) -> GreedyCover {
        let mut covered = self.base.clone();
        let mut out = GreedyCover {
            picks: Vec::new(),
            covered: vec![count(&covered)],
        };
        let mut used = vec![false; self.sets.len()];
        loop {
            let mut best: Option<(usize, usize)> = None;
            for (i, s) in self.sets.iter().enumerate() {
                if used[i] {
                    continue;
                }
                let gain: usize = s
                    .iter()
                    .zip(&covered)
                    .map(|(a, c)| (a & !c).count_ones() as usize)
                    .sum();
                if gain > 0 && best.is_none_or(|(_, g)| gain > g) {
                    best = Some((i, gain));
                }
            }
            let Some((i, _)) = best else { break };
            used[i] = true;
            or_into(&mut covered, &self.sets[i]);
            out.picks.push(i);
            out.covered.push(count(&covered));
        }
        out
    }
}

fn bits(samples: usize, indices: &[usize]) -> Vec<u64> {
    let mut b = vec![0u64; samples.div_ceil(64)];
    for &i in indices.iter().filter(|&&i| i < samples) {
        b[i / 64] |= 1 << (i % 64);
    }
    b
}

fn or_into(into: &mut [u64], from: &[u64]) {
    into.iter_mut().zip(from).for_each(|(a, b)| *a |= b);
}

fn count(b: &[u64]) -> usize {
    b.iter().map(|w| w.count_ones() as usize).sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn sets_strategy() -> impl Strategy<Value = (usize, Vec<usize>, Vec<Vec<usize>>)> {
        (1usize..150).prop_flat_map(|n| {
            (
                Just(n),
                prop::collection::vec(0..n, 0..10),
                prop::collection::vec(prop::collection::vec(0..n, 0..40), 0..12),
            )
        })
    }

    proptest! {
        /// The greedy curve rises strictly, starts at the base, ends at the union, and
        /// its first pick is the best single view.
        #[test]
        fn greedy_is_monotone_and_ends_at_the_union((n, base, views) in sets_strategy()) {
            let mut sets = CoverSets::new(n, &base);
            for v in &views {
                sets.push(v);
            }
            let g = sets.greedy();
            prop_assert_eq!(g.covered[0], sets.base_count());
            prop_assert_eq!(*g.covered.last().unwrap(), sets.union_count());
            prop_assert!(g.covered.windows(2).all(|w| w[1] > w[0]));
            prop_assert_eq!(g.covered.len(), g.picks.len() + 1);
            for (k, _) in g.picks.iter().enumerate() {
                prop_assert_eq!(sets.count_with(g.picks[..=k].iter().copied()), g.covered[k + 1]);
            }
            if let Some(&first) = g.picks.first() {
                let best = (0..sets.len()).map(|v| sets.count_with([v])).max().unwrap();
                prop_assert_eq!(sets.count_with([first]), best);
            }
            prop_assert_eq!(sets.uncovered().len(), n - sets.union_count());
        }
    }

    #[test]
    fn duplicate_and_empty_views_are_never_picked() {
        let mut sets = CoverSets::new(10, &[]);
        sets.push(&[]);
        sets.push(&[1, 2]);
        sets.push(&[1, 2]);
        sets.push(&[99]);
        let g = sets.greedy();
        assert_eq!(g.picks, vec![1]);
        assert_eq!(g.covered, vec![0, 2]);
        assert_eq!(sets.uncovered(), vec![0, 3, 4, 5, 6, 7, 8, 9]);
    }
}
