//! Independent sets of p-ICP-GPA (Figure 4, line 17): groups of points, at most one per
//! view and at least two, that are matched to each other across views.
//!
//! The input is the mutual-nearest-neighbour graph (one node per point, an edge per
//! mutual pair) as a partner table: each point's mutual nearest neighbour in every other
//! view ([`MutualSearch::partners`](super::mutual_neighbours::MutualSearch::partners)).
//! Because a point has at most one mutual nearest neighbour in each other view, every node
//! has at most one neighbour per view, and a complete subgraph can never hold two points of
//! one view. Two rules are offered ([`SetRule`]):
//!
//! - [`SetRule::Cliques`] (default, the paper's definition): a set is a connected
//!   component that is a complete graph. A component that is not complete (say a–b and
//!   b–c linked but not a–c) is dropped whole, so no point is driven towards two
//!   centroids and the result does not depend on any visiting order. The test is local:
//!   node u leads a set iff it has the smallest id of its closed neighbourhood
//!   S = {u} ∪ N(u) and every v ∈ N(u) has exactly S as closed neighbourhood; then S is
//!   closed under adjacency (a component) and complete. It runs in parallel over nodes.
//! - [`SetRule::Components`]: every connected component with at most one point per view,
//!   complete or not (what a public implementation does).
//!
//! Sets come out ordered by their smallest global point id, members in increasing id
//! (hence view) order, whatever the thread count.

use rayon::prelude::*;

use super::mutual_neighbours::ViewLayout;
use crate::registration::SetRule;
use crate::registration::nearest_cache::NONE;

/// Nodes per parallel work item.
const CHUNK: usize = 1024;

/// Independent sets in compressed form.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct IndependentSets {
    /// Members of all sets (global ids), set after set.
    members: Vec<u32>,
    /// Set s is `members[starts[s]..starts[s + 1]]`.
    starts: Vec<usize>,
    /// Points with at least one mutual nearest neighbour.
    linked: usize,
}

impl IndependentSets {
    /// Number of sets.
    pub(crate) fn len(&self) -> usize {
        self.starts.len() - 1
    }

    /// Whether there is no set.
    pub(crate) fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Members (global ids) of set `s`.
    pub(crate) fn set(&self, s: usize) -> &[u32] {
        &self.members[self.range(s)]
    }

    /// Positions of set `s`'s members in [`members`](Self::members).
    pub(crate) fn range(&self, s: usize) -> std::ops::Range<usize> {
        self.starts[s]..self.starts[s + 1]
    }

    /// Points in some set.
    pub(crate) fn points_in_sets(&self) -> usize {
        self.members.len()
    }

    /// Points with at least one mutual nearest neighbour.
    pub(crate) fn linked_points(&self) -> usize {
        self.linked
    }

    /// (view, local point index) of every member, set after set.
    pub(crate) fn locals(&self, layout: &ViewLayout) -> Vec<(u32, u32)> {
        self.members
            .par_iter()
            .map(|&m| {
                let (v, i) = layout.local(m as usize);
                (v as u32, i as u32)
            })
            .collect()
    }

    /// The sets given one by one (members in increasing id order), with the count of
    /// linked points.
    pub(crate) fn from_sets(sets: impl IntoIterator<Item = Vec<u32>>, linked: usize) -> Self {
        let mut members = Vec::new();
        let mut starts = vec![0];
        for s in sets {
            members.extend_from_slice(&s);
            starts.push(members.len());
        }
        Self {
            members,
            starts,
            linked,
        }
    }
}

/// Independent sets of the graph with nodes `0..layout.total()` given as a partner table:
/// `partners[u * w + k]` is u's neighbour in view k, or `NONE` (a symmetric table; `w`
/// views).
pub(crate) fn find_independent_sets(
    layout: &ViewLayout,
    partners: &[u32],
    rule: SetRule,
) -> IndependentSets {
    let w = layout.views();
    let total = layout.total();
    debug_assert_eq!(partners.len(), total * w);
    let row = |u: usize| &partners[u * w..(u + 1) * w];
    let linked = (0..total.div_ceil(CHUNK))
        .into_par_iter()
        .map(|c| {
            (c * CHUNK..((c + 1) * CHUNK).min(total))
                .filter(|&u| row(u).iter().any(|&p| p != NONE))
                .count()
        })
        .sum();
    match rule {
        SetRule::Cliques => {
            // Per chunk: its sets' members, one after another, and each set's size.
            let chunks: Vec<(Vec<u32>, Vec<usize>)> = (0..total.div_ceil(CHUNK))
                .into_par_iter()
                .map(|c| {
                    let (mut members, mut sizes) = (Vec::new(), Vec::new());
                    for u in c * CHUNK..((c + 1) * CHUNK).min(total) {
                        let before = members.len();
                        if clique_led_by(u, layout.local(u).0, &row, &mut members) {
                            sizes.push(members.len() - before);
                        }
                    }
                    (members, sizes)
                })
                .collect();
            let mut sets = IndependentSets {
                members: Vec::with_capacity(chunks.iter().map(|c| c.0.len()).sum()),
                starts: vec![0],
                linked,
            };
            for (members, sizes) in chunks {
                sets.members.extend_from_slice(&members);
                for size in sizes {
                    let end = sets.starts[sets.starts.len() - 1] + size;
                    sets.starts.push(end);
                }
            }
            sets
        }
        SetRule::Components => {
            let mut seen = vec![false; total];
            let mut sets = Vec::new();
            let mut stack = Vec::new();
            for u in 0..total {
                if seen[u] || row(u).iter().all(|&p| p == NONE) {
                    continue;
                }
                let mut component = Vec::new();
                seen[u] = true;
                stack.push(u as u32);
                while let Some(v) = stack.pop() {
                    component.push(v);
                    for &p in row(v as usize) {
                        if p != NONE && !seen[p as usize] {
                            seen[p as usize] = true;
                            stack.push(p);
                        }
                    }
                }
                component.sort_unstable();
                let distinct_views = component.windows(2).all(|pair| {
                    layout.local(pair[0] as usize).0 != layout.local(pair[1] as usize).0
                });
                if distinct_views {
                    sets.push(component);
                }
            }
            IndependentSets::from_sets(sets, linked)
        }
    }
}

/// Whether node `u` (of view `view_u`) leads a complete component; if so, its members
/// (in increasing id order) are appended to `out`.
fn clique_led_by<'a>(
    u: usize,
    view_u: usize,
    row: &impl Fn(usize) -> &'a [u32],
    out: &mut Vec<u32>,
) -> bool {
    let row_u = row(u);
    // The set by view slot: u in its own slot, its partners in theirs.
    let slot = |k: usize| if k == view_u { u as u32 } else { row_u[k] };
    let mut has_partner = false;
    for (k, &v) in row_u.iter().enumerate() {
        if v == NONE {
            continue;
        }
        has_partner = true;
        if (v as usize) < u {
            return false;
        }
        // v's closed neighbourhood must be exactly the set.
        let row_v = row(v as usize);
        if row_v
            .iter()
            .enumerate()
            .any(|(m, &pv)| m != k && pv != slot(m))
        {
            return false;
        }
    }
    if has_partner {
        out.extend((0..row_u.len()).map(slot).filter(|&p| p != NONE));
    }
    has_partner
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The partner table of a graph given by its edges.
    fn partners(layout: &ViewLayout, edges: &[[u32; 2]]) -> Vec<u32> {
        let w = layout.views();
        let mut partners = vec![NONE; layout.total() * w];
        for &[a, b] in edges {
            let (va, vb) = (layout.local(a as usize).0, layout.local(b as usize).0);
            partners[a as usize * w + vb] = b;
            partners[b as usize * w + va] = a;
        }
        partners
    }

    /// Sets as plain vectors, for comparison.
    fn sets(layout: &ViewLayout, edges: &[[u32; 2]], rule: SetRule) -> Vec<Vec<u32>> {
        let s = find_independent_sets(layout, &partners(layout, edges), rule);
        (0..s.len()).map(|k| s.set(k).to_vec()).collect()
    }

    // Four views of three points each: view v holds ids 3v, 3v+1, 3v+2.
    fn layout() -> ViewLayout {
        ViewLayout::new([3, 3, 3, 3])
    }

    #[test]
    fn pairs_and_triangles_are_sets() {
        let edges = [[0, 3], [1, 4], [1, 7], [4, 7]];
        let l = layout();
        for rule in [SetRule::Cliques, SetRule::Components] {
            assert_eq!(sets(&l, &edges, rule), vec![vec![0, 3], vec![1, 4, 7]]);
        }
        let s = find_independent_sets(&l, &partners(&l, &edges), SetRule::Cliques);
        assert_eq!((s.linked_points(), s.points_in_sets()), (5, 5));
    }

    #[test]
    fn complete_graph_on_four_views() {
        let edges = [[2, 5], [2, 8], [2, 11], [5, 8], [5, 11], [8, 11]];
        for rule in [SetRule::Cliques, SetRule::Components] {
            assert_eq!(sets(&layout(), &edges, rule), vec![vec![2, 5, 8, 11]]);
        }
    }

    #[test]
    fn chain_is_a_set_only_for_the_component_rule() {
        // 0 (view 0) – 4 (view 1) – 8 (view 2): 0 and 8 are not mutual neighbours.
        let edges = [[0, 4], [4, 8], [1, 5]];
        assert_eq!(sets(&layout(), &edges, SetRule::Cliques), vec![vec![1, 5]]);
        assert_eq!(
            sets(&layout(), &edges, SetRule::Components),
            vec![vec![0, 4, 8], vec![1, 5]]
        );
        let s = find_independent_sets(&layout(), &partners(&layout(), &edges), SetRule::Cliques);
        assert_eq!((s.linked_points(), s.points_in_sets()), (5, 2));
    }

    #[test]
    fn four_clique_missing_one_edge_is_dropped_by_cliques() {
        let edges = [[2, 5], [2, 8], [2, 11], [5, 8], [5, 11]];
        assert!(sets(&layout(), &edges, SetRule::Cliques).is_empty());
        assert_eq!(
            sets(&layout(), &edges, SetRule::Components),
            vec![vec![2, 5, 8, 11]]
        );
    }

    #[test]
    fn two_points_of_one_view_are_never_a_set() {
        // 0 (view 0) – 4 (view 1) – 1 (view 0): a path through two points of view 0.
        let edges = [[0, 4], [1, 7], [4, 7], [0, 9]];
        // Component {0, 1, 4, 7, 9}: not complete, and view 0 twice.
        for rule in [SetRule::Cliques, SetRule::Components] {
            assert!(sets(&layout(), &edges, rule).is_empty());
        }
    }

    #[test]
    fn leader_is_not_the_first_view() {
        // A triangle on views 1, 2, 3 and a pair on views 2, 3.
        let edges = [[3, 6], [3, 9], [6, 9], [7, 10]];
        for rule in [SetRule::Cliques, SetRule::Components] {
            assert_eq!(
                sets(&layout(), &edges, rule),
                vec![vec![3, 6, 9], vec![7, 10]]
            );
        }
        assert!(sets(&layout(), &[], SetRule::Cliques).is_empty());
    }
}
