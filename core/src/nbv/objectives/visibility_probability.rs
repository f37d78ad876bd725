//! [`Visibility`]: the probability that a voxel on a ray is seen, as Isler et al. (2016)
//! define it: `P_v(x_k) = Π_{i<k} (1 − p_i)` over the voxels before x_k.
//!
//! The reference code (`rpg_ig_active_reconstruction`, `octomap_information_gain.inl`)
//! multiplies by `p_i` instead of `1 − p_i` (its issue #9, open and unfixed): the two agree
//! at p = 0.5, but a clamped free voxel (p = 0.12) keeps 0.12 of the visibility there and
//! 0.88 here. This is the papers' definition.
//!
//! [`visible_entropy`]: the sum of `P_v · h(p)` over the voxels of a ray that a rule keeps,
//! the visibility lowered by every voxel — the occlusion-aware and unobserved-voxel gains.

use super::{RayVoxel, entropy};

/// The running visibility along one ray, 1 at its first voxel.
///
/// ```
/// use nbv_core::nbv::Visibility;
/// let mut v = Visibility::default();
/// assert_eq!(v.get(), 1.0);
/// v.pass(0.5);
/// v.pass(0.2);
/// assert!((v.get() - 0.4).abs() < 1e-15);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Visibility(f64);

impl Default for Visibility {
    fn default() -> Self {
        Self(1.0)
    }
}

impl Visibility {
    /// P_v of the current voxel.
    pub fn get(&self) -> f64 {
        self.0
    }

    /// Moves past a voxel of occupancy probability `p`.
    pub fn pass(&mut self, p: f64) {
        self.0 *= 1.0 - p;
    }
}

/// `Σ_{k: keep(x_k)} P_v(x_k) · h(p_k)` along `ray`, with the visibility updated at every
/// voxel, kept or not.
pub(crate) fn visible_entropy(ray: &[RayVoxel], keep: impl Fn(&RayVoxel) -> bool) -> f64 {
    let mut visibility = Visibility::default();
    let mut sum = 0.0;
    for v in ray {
        let p = v.probability();
        if keep(v) {
            sum += visibility.get() * entropy(p);
        }
        visibility.pass(p);
    }
    sum
}
