//! [`SetMoments`]: the members of p-ICP-GPA's independent sets summed by pair of views,
//! once per set of correspondences, so that each round of the generalised-Procrustes inner
//! loop (fit every view to the sets' centroids, then the new centroids' residual) costs
//! O(views²) small-matrix products instead of a pass over every member.
//!
//! View u's member of set s sits at `x = R_u q + τ_u`, with `q` the member in the view's
//! frame less the mean `p̄_u` of all the view's members and `τ_u = R_u p̄_u + t_u`. The set's
//! centroid is `c_s = (1/n_s) Σ_{u∈s} x_u`. Everything the loop needs is linear in sums over
//! the sets that two views u, v share, each set weighted by `1/n_s`:
//! `w_uv = Σ 1/n_s`, `a_uv = Σ q_u / n_s`, `B_uv = Σ q_u q_vᵀ / n_s`; and, per view, its
//! member count `N_u`, `σ_u = Σ q` and `Q_u = Σ |q|²`:
//! - view v's sums against the centroids: `Σ_{s∋v} c_s = Σ_u (R_u a_uv + w_uv τ_u)` and
//!   `Σ_{s∋v} q_v c_sᵀ = Σ_u (B_vu R_uᵀ + a_vu τ_uᵀ)`;
//! - the residual `Σ_s Σ_{u∈s} |x_u − c_s|² = Σ_u (Q_u + 2 τ_uᵀ R_u σ_u + N_u |τ_u|²)
//!   − Σ_{u,u'} (tr(R_uᵀ R_u' B_u'u) + 2 τ_uᵀ R_u' a_u'u + w_uu' τ_uᵀ τ_u')`.
//!
//! The residual is translation invariant, so every `τ` is taken relative to their mean,
//! which keeps the difference above well conditioned. Sums run over fixed chunks of sets
//! and merge in chunk order: the same result at any thread count.

use nalgebra::{Matrix3, Point3, Vector3};
use rayon::prelude::*;

use super::independent_sets::IndependentSets;
use crate::math::Pose;
use crate::registration::procrustes::CrossCovariance;
use crate::registration::view_tree::ViewTree;

/// Sets per parallel work item.
const CHUNK: usize = 512;

/// Sums of one pair of views (see the module doc).
#[derive(Debug, Clone, Copy)]
struct PairSums {
    w: f64,
    a: Vector3<f64>,
    b: Matrix3<f64>,
}

impl PairSums {
    const ZERO: Self = Self {
        w: 0.0,
        a: Vector3::new(0.0, 0.0, 0.0),
        b: Matrix3::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0),
    };
}

/// Sums of one view's members.
#[derive(Debug, Clone, Copy)]
struct ViewSums {
    n: usize,
    sigma: Vector3<f64>,
    q: f64,
}

impl ViewSums {
    const ZERO: Self = Self {
        n: 0,
        sigma: Vector3::new(0.0, 0.0, 0.0),
        q: 0.0,
    };
}

/// The independent sets' members summed by pair of views (see the module doc).
pub(crate) struct SetMoments {
    views: usize,
    /// `p̄_u`: mean of view u's members (own frame; the origin without members).
    means: Vec<Vector3<f64>>,
    /// Per view.
    own: Vec<ViewSums>,
    /// `pairs[u * views + v]`.
    pairs: Vec<PairSums>,
    /// Members in all sets.
    members: usize,
}

impl SetMoments {
    /// The moments of `sets`, whose members are `locals` (view, point index into
    /// `trees[view]`), set after set.
    pub(crate) fn new(trees: &[ViewTree], sets: &IndependentSets, locals: &[(u32, u32)]) -> Self {
        let w = trees.len();
        let point = |&(v, i): &(u32, u32)| trees[v as usize].points()[i as usize].coords;
        let mut means = vec![Vector3::zeros(); w];
        let mut counts = vec![0usize; w];
        for m in locals {
            means[m.0 as usize] += point(m);
            counts[m.0 as usize] += 1;
        }
        for (mean, &n) in means.iter_mut().zip(&counts) {
            if n > 0 {
                *mean /= n as f64;
            }
        }
        let chunks: Vec<(Vec<ViewSums>, Vec<PairSums>)> = (0..sets.len().div_ceil(CHUNK))
            .into_par_iter()
            .map(|c| {
                let mut own = vec![ViewSums::ZERO; w];
                let mut pairs = vec![PairSums::ZERO; w * w];
                for s in c * CHUNK..((c + 1) * CHUNK).min(sets.len()) {
                    let members = &locals[sets.range(s)];
                    let weight = 1.0 / members.len() as f64;
                    for m in members {
                        let u = m.0 as usize;
                        let q = point(m) - means[u];
                        let o = &mut own[u];
                        o.n += 1;
                        o.sigma += q;
                        o.q += q.norm_squared();
                        for n in members {
                            let v = n.0 as usize;
                            let r = point(n) - means[v];
                            let p = &mut pairs[u * w + v];
                            p.w += weight;
                            p.a += q * weight;
                            p.b += q * r.transpose() * weight;
                        }
                    }
                }
                (own, pairs)
            })
            .collect();
        let mut own = vec![ViewSums::ZERO; w];
        let mut pairs = vec![PairSums::ZERO; w * w];
        for (o, p) in chunks {
            for (sum, x) in own.iter_mut().zip(&o) {
                sum.n += x.n;
                sum.sigma += x.sigma;
                sum.q += x.q;
            }
            for (sum, x) in pairs.iter_mut().zip(&p) {
                sum.w += x.w;
                sum.a += x.a;
                sum.b += x.b;
            }
        }
        Self {
            views: w,
            means,
            own,
            pairs,
            members: locals.len(),
        }
    }

    /// Each view's rotation matrix and `τ` at `poses`, the `τ` less their mean over views
    /// with members, and that mean.
    fn frames(&self, poses: &[Pose]) -> (Vec<Matrix3<f64>>, Vec<Vector3<f64>>, Vector3<f64>) {
        let rotations: Vec<Matrix3<f64>> = poses
            .iter()
            .map(|p| p.rotation.to_rotation_matrix().into_inner())
            .collect();
        let mut taus: Vec<Vector3<f64>> = (0..self.views)
            .map(|u| rotations[u] * self.means[u] + poses[u].translation.vector)
            .collect();
        let with_members = (0..self.views).filter(|&u| self.own[u].n > 0);
        let (sum, n) =
            with_members.fold((Vector3::zeros(), 0usize), |(s, n), u| (s + taus[u], n + 1));
        let shift = if n > 0 {
            sum / n as f64
        } else {
            Vector3::zeros()
        };
        for tau in &mut taus {
            *tau -= shift;
        }
        (rotations, taus, shift)
    }

    /// For every view, the rigid transform moving its members (own frame) onto their sets'
    /// centroids at `poses`, or `None` if they do not determine one.
    pub(crate) fn fits(&self, poses: &[Pose]) -> Vec<Option<Pose>> {
        let w = self.views;
        let (rotations, taus, shift) = self.frames(poses);
        (0..w)
            .map(|v| {
                let own = &self.own[v];
                let (mut sum_c, mut sum_xc) = (Vector3::zeros(), Matrix3::zeros());
                for u in 0..w {
                    let uv = &self.pairs[u * w + v];
                    let vu = &self.pairs[v * w + u];
                    sum_c += rotations[u] * uv.a + taus[u] * uv.w;
                    sum_xc += vu.b * rotations[u].transpose() + vu.a * taus[u].transpose();
                }
                CrossCovariance::from_sums(
                    Point3::from(self.means[v]),
                    Point3::from(shift),
                    own.n,
                    own.sigma,
                    sum_c,
                    sum_xc,
                )
                .solve()
                .ok()
            })
            .collect()
    }

    /// The mean squared distance of the members to their sets' centroids at `poses` (0
    /// without members).
    pub(crate) fn mean_squared_residual(&self, poses: &[Pose]) -> f64 {
        if self.members == 0 {
            return 0.0;
        }
        let w = self.views;
        let (rotations, taus, _) = self.frames(poses);
        let mut total = 0.0;
        for u in 0..w {
            let own = &self.own[u];
            total += own.q
                + 2.0 * taus[u].dot(&(rotations[u] * own.sigma))
                + own.n as f64 * taus[u].norm_squared();
            for v in 0..w {
                let vu = &self.pairs[v * w + u];
                let relative = rotations[u].transpose() * rotations[v];
                total -= (relative * vu.b).trace()
                    + 2.0 * taus[u].dot(&(rotations[v] * vu.a))
                    + vu.w * taus[u].dot(&taus[v]);
            }
        }
        total.max(0.0) / self.members as f64
    }
}

#[cfg(test)]
mod tests {
    use super::super::mutual_neighbours::ViewLayout;
    use super::*;
    use nalgebra::{Isometry3, Vector3};
    use proptest::prelude::*;

    /// A small deterministic generator for the cases' numbers.
    struct Lcg(u64);
    impl Lcg {
        fn unit(&mut self) -> f64 {
            self.0 = self
                .0
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (self.0 >> 11) as f64 / (1u64 << 53) as f64
        }
        fn below(&mut self, n: usize) -> usize {
            ((self.unit() * n as f64) as usize).min(n - 1)
        }
    }

    proptest! {
        /// The fits and the residual from the moments are those of a pass over every
        /// member: for random views, sets (two or more views each) and poses.
        #[test]
        fn moments_match_the_members(seed in any::<u64>(), w in 2usize..6, k in 1usize..40) {
            let mut r = Lcg(seed);
            let sizes: Vec<usize> = (0..w).map(|_| 5 + r.below(30)).collect();
            let trees: Vec<ViewTree> = sizes
                .iter()
                .enumerate()
                .map(|(v, &n)| {
                    let points: Vec<Point3<f64>> = (0..n)
                        .map(|_| {
                            let (x, y, z) = (r.unit(), r.unit(), r.unit());
                            Point3::new(0.5 + 0.2 * x, 0.3 - 0.2 * y, 0.8 + 0.1 * z)
                        })
                        .collect();
                    ViewTree::build(v, &points).unwrap()
                })
                .collect();
            let layout = ViewLayout::new(sizes.iter().copied());
            let sets: Vec<Vec<u32>> = (0..k)
                .map(|_| {
                    let first = r.below(w);
                    let count = 2 + r.below(w - 1);
                    (0..count)
                        .map(|j| {
                            let v = (first + j) % w;
                            layout.global(v, r.below(sizes[v])) as u32
                        })
                        .collect::<Vec<u32>>()
                })
                .map(|mut s| {
                    s.sort_unstable();
                    s
                })
                .collect();
            let sets = IndependentSets::from_sets(sets, 0);
            let locals = sets.locals(&layout);
            let poses: Vec<Pose> = (0..w)
                .map(|_| {
                    let t = Vector3::new(r.unit(), r.unit(), r.unit()) * 0.1;
                    let a = Vector3::new(r.unit(), r.unit(), r.unit()) - Vector3::repeat(0.5);
                    let a = a * 0.6;
                    Isometry3::new(t, a)
                })
                .collect();
            let moments = SetMoments::new(&trees, &sets, &locals);

            // Member by member.
            let position = |&(v, i): &(u32, u32)| {
                poses[v as usize] * trees[v as usize].points()[i as usize]
            };
            let centroids: Vec<Point3<f64>> = (0..sets.len())
                .map(|s| {
                    let m = &locals[sets.range(s)];
                    let sum: Vector3<f64> = m.iter().map(|x| position(x).coords).sum();
                    Point3::from(sum / m.len() as f64)
                })
                .collect();
            let sum_sq: f64 = (0..sets.len())
                .flat_map(|s| locals[sets.range(s)].iter().map(move |m| (s, m)))
                .map(|(s, m)| (position(m) - centroids[s]).norm_squared())
                .sum();
            let mse = sum_sq / locals.len() as f64;
            let got = moments.mean_squared_residual(&poses);
            prop_assert!((got - mse).abs() <= 1e-12 + 1e-9 * mse, "{got} vs {mse}");

            let fits = moments.fits(&poses);
            for (v, fit) in fits.iter().enumerate() {
                let mut acc: Option<CrossCovariance> = None;
                for s in 0..sets.len() {
                    for &(u, i) in &locals[sets.range(s)] {
                        if u as usize == v {
                            let p = trees[v].points()[i as usize];
                            acc.get_or_insert_with(|| CrossCovariance::new(p, centroids[s]))
                                .add(&p, &centroids[s]);
                        }
                    }
                }
                let expected = acc.and_then(|a| a.solve().ok());
                match (fit, expected) {
                    (Some(a), Some(b)) => {
                        let d = a.inverse() * b;
                        let close =
                            d.rotation.angle() < 1e-8 && d.translation.vector.norm() < 1e-9;
                        prop_assert!(close, "view {v}: {a:?} vs {b:?}");
                    }
                    (None, None) => {}
                    (a, b) => prop_assert!(false, "view {v}: {a:?} vs {b:?}"),
                }
            }
        }
    }
}
