//! The data term of the maximum a posteriori registration, at given poses: correspondences
//! (each source point's nearest point of a target view within the kernel's reach: `d_max`,
//! or a coarse-to-fine stage's own), their residuals
//! weighted by the sensors' noise, the robust kernel, and the Gauss–Newton normal
//! equations of all views at once.
//!
//! A correspondence pairs a source point `x` (view `v`) with the surfel `y` of its nearest
//! target point (view `w`) — or, with `along_rays` ([`MapParams::along_rays`]), the surfel
//! where the source's viewing ray crosses the target's surface (projective association, as
//! depth-camera trackers match along the camera's rays): the crossing of the ray with the
//! nearest point's plane, and the target point nearest to that crossing, where the ray is
//! known and meets the plane at more than ~17°, and the crossing's surfel has a normal and
//! is not on the boundary. The camera's noise lies along its rays and is centimetres: on a
//! curved target (a handle, a bottle) the nearest point of a displaced camera point lies
//! off its ray, on a plane tilted towards it, so the residual understates the view's
//! offset, and views settle millimetres short of the truth (paper-env1's mallet at seed 7
//! with only the hand-eye error, without priors: 2.1 mm nearest, 1.1 mm along the rays from
//! the first stage; the stages are `map.rs`'s).
//!
//! A correspondence's residual `e = x − y` (in the target's frame) has the covariance
//! `C = σ_x²·u_x u_xᵀ + σ_y²·u_y u_yᵀ + σ_f²·I + T`: each sensor's range noise along its
//! own viewing ray `u` (isotropic where the ray is unknown), a floor `σ_f`, and `T` the
//! freedom to slide along the surface — `L²·(I − n nᵀ)` with `L = d_max` where the target
//! surfel has a normal `n` (point-to-plane), else `((s/2)² + σ_x²)·I` for the target's
//! point spacing `s` (point-to-point): a point the noise moved along its ray finds its
//! nearest target point as far off in any direction where the target has no plane (an
//! edge, a corner, a curved patch), so across the ray the match is as uncertain as the
//! source's noise — weighted by the spacing alone, a box's edges dragged noisy camera
//! views sideways by millimetres. The cost of a correspondence is the truncated Cauchy
//! kernel `ρ(m²) = c²/2·ln(1 + m²/c²)` of its Mahalanobis distance `m² = eᵀC⁻¹e`, capped at
//! `m = cap`; a source point without a target point within reach costs the cap. A source
//! point beyond the edge of what the target saw (its nearest target point lies on the
//! target's boundary, and the point lies outside it: see [`MapView`]) pulls nothing and
//! costs what a true match is expected to cost (`ρ` at `m²` = the residual's constrained
//! dimensions), so a view gains nothing by sliding points off or onto the edge: matched
//! to the edge, such points would drag their view towards it (on a box's unseen faces,
//! several millimetres from noise-free views started at the truth).
//!
//! Where the target view knows its sensor's free space ([`FreeSpace`]: the laser sweep's,
//! in the pipeline), a point beyond the edge or out of reach is judged by where it lies.
//! Where the target's rays passed, it contradicts what the target saw: beyond the edge it
//! is matched point-to-point to the edge point itself (a view slid past the rim of a
//! box's top is pulled back), out of reach it costs the cap. Where no ray passed (an unseen
//! face, a shadow), it is merely unseen: it pulls nothing and costs a true match's
//! expected cost, beyond the edge or out of reach alike, so no view gains by bringing its
//! unseen faces within reach of the target's rim — without free space the cap out of
//! reach against the expected cost beyond the edge rewarded exactly that, and a box's
//! views slid along its top by up to 16 mm at three times the scenes' errors.
//!
//! A camera view that knows its own free space ([`DepthImageFreeSpace`]: its averaged
//! depth image, in the pipeline) is also judged by the reference's points, for
//! contradictions only: a reference point beyond the edge of the view's surface where the
//! camera saw through is pulled back onto the view's edge point; every other reference
//! point costs what a true match is expected to cost, wherever the views move. The laser's
//! free space catches a view that slid past a rim the laser saw beyond; a view that slid
//! the other way hangs its points over a rim the laser could not see past (the back of a
//! box's top), where only the camera knows that its rays passed beside the rim the laser
//! saw. Without that, the box's camera views slide along its top as far as their priors
//! let them.
//!
//! The whole data term is a function of the poses alone, which is what lets the solver
//! reject any step that raises it.
//!
//! Work is split into fixed chunks of (pair, source points), summed in chunk order: the
//! result is identical at any thread count.

use std::cell::OnceCell;

use nalgebra::{DMatrix, DVector, Matrix3, Matrix6, Point3, Vector3, Vector6};
use rayon::prelude::*;

use super::correspondences::PairNearest;
use super::view::MapView;
use crate::math::Pose;
use crate::registration::nearest_cache::Updated;
use crate::registration::nearest_cache::matrix;
#[cfg(doc)]
use crate::registration::{DepthImageFreeSpace, FreeSpace, MapParams};

/// A viewing ray is followed to the target's plane only where it meets it at more than
/// this cosine of the normal (≈ 17° from grazing): nearer the plane the crossing runs off.
const MIN_RAY_INCIDENCE: f64 = 0.3;

/// A target surfel whose normal faces away from the source's sensor by more than this
/// cosine cannot be what the source saw (the far side of a thin object seen from the
/// other side): the point counts as without correspondence.
const MIN_FACING: f64 = 0.1;

/// One directed term set: points of `source` matched into `target`.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Pair {
    /// The view whose points are matched.
    pub source: usize,
    /// The view they are matched into.
    pub target: usize,
    /// Weight of the pair's costs (½ for each direction of a symmetric pair).
    pub weight: f64,
    /// Every `stride`-th source point is used.
    pub stride: usize,
    /// Which of the used points take part (by used index); `None`: all. A point outside
    /// the mask costs nothing wherever the views move, so the objective cannot gain by
    /// dragging unseen surfaces onto seen ones.
    pub mask: Option<Vec<bool>>,
    /// Only the source points that contradict the target's free space take part (beyond
    /// the edge of its surface where its sensor saw through); every other one costs what
    /// a true match is expected to cost, wherever the views move.
    pub contradictions_only: bool,
}

/// The kernel, noise and matching constants of the data term.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Kernel {
    /// Cauchy scale `c` (in σ).
    pub scale: f64,
    /// Cap `m` beyond which a correspondence is an outlier (in σ).
    pub cap: f64,
    /// Floor σ added to every residual (m).
    pub floor: f64,
    /// A point counts as matched (for masks) within this many σ.
    pub select: f64,
    /// Distance (m) within which a point's nearest target point is searched: `d_max`, or
    /// a coarse-to-fine stage's own (see [`register_coarse_to_fine`]).
    ///
    /// [`register_coarse_to_fine`]: crate::registration::register_coarse_to_fine
    pub reach: f64,
    /// `d_max` (m), whatever the stage: `L`, the freedom to slide along a target's plane,
    /// and the reach of the overlap test that pairs the views.
    pub d_max: f64,
    /// Match a point to the target's surfel where its viewing ray crosses the target's
    /// surface, not to its nearest one (see the module doc).
    pub along_rays: bool,
}

impl Kernel {
    /// The cost of a squared Mahalanobis distance, and its IRLS weight (0 beyond the cap).
    fn cost(&self, m2: f64) -> (f64, f64) {
        let c2 = self.scale * self.scale;
        let m2c = m2.min(self.cap * self.cap);
        let cost = 0.5 * c2 * (1.0 + m2c / c2).ln();
        let weight = if m2 < self.cap * self.cap {
            1.0 / (1.0 + m2 / c2)
        } else {
            0.0
        };
        (cost, weight)
    }

    /// The cost of a point with no correspondence.
    pub(crate) fn outlier_cost(&self) -> f64 {
        self.cost(f64::INFINITY).0
    }
}

/// The data term at some poses, with its normal equations over all views
/// (`6·views` unknowns: rotation then translation per view, as perturbations about each
/// view's current correction centre). Each work item sums its inliers' blocks of the
/// normal equations as it finds them (a few 3×3 products per inlier, cheaper than keeping
/// the inliers for later: a record per inlier was ~8 % of `nbv register`'s time in page
/// faults alone), unless the evaluation is for its cost and matches only (a stage's
/// selection, the objective at the initial poses); the global matrices are assembled on
/// first use.
#[derive(Debug, Clone)]
pub(crate) struct DataTerm {
    /// Σ weight·ρ over all used source points.
    pub cost: f64,
    /// Inlier correspondences per view (as source or target).
    pub inliers: Vec<usize>,
    /// Inlier correspondences in all.
    pub inlier_count: usize,
    /// Σ |e|² over inliers (m²).
    pub sum_sq: f64,
    /// Per pair, per used source point: matched within `Kernel::select` σ.
    pub matched: Vec<Vec<bool>>,
    /// Each work item's blocks, in order; `None` for an evaluation without them.
    chunks: Option<Vec<Blocks>>,
    views: usize,
    normal: OnceCell<(DMatrix<f64>, DVector<f64>)>,
}

impl DataTerm {
    /// Gauss–Newton Hessian.
    pub fn hessian(&self) -> &DMatrix<f64> {
        &self.normal().0
    }

    /// Gradient.
    pub fn gradient(&self) -> &DVector<f64> {
        &self.normal().1
    }

    /// The normal equations, summed over the work items in their order (identical at any
    /// thread count).
    ///
    /// # Panics
    /// On a term evaluated without them (a bug of the caller).
    fn normal(&self) -> &(DMatrix<f64>, DVector<f64>) {
        self.normal.get_or_init(|| {
            let chunks = self
                .chunks
                .as_ref()
                .expect("the normal equations of a data term evaluated without them");
            let w = self.views;
            let mut hessian = DMatrix::zeros(6 * w, 6 * w);
            let mut gradient = DVector::zeros(6 * w);
            for b in chunks {
                let (v, t) = (b.source, b.target);
                add_block(&mut hessian, v, v, &b.hvv);
                add_block(&mut hessian, t, t, &b.hww);
                add_block(&mut hessian, v, t, &b.hvw);
                add_block(&mut hessian, t, v, &b.hvw.transpose());
                let mut gv = gradient.fixed_rows_mut::<6>(6 * v);
                gv += b.gv;
                let mut gw = gradient.fixed_rows_mut::<6>(6 * t);
                gw += b.gw;
            }
            (hessian, gradient)
        })
    }
}

/// One work item's blocks of the normal equations (world frame), between its source view
/// `source` and target view `target`.
#[derive(Debug, Clone)]
struct Blocks {
    source: usize,
    target: usize,
    hvv: Matrix6<f64>,
    hvw: Matrix6<f64>,
    hww: Matrix6<f64>,
    gv: Vector6<f64>,
    gw: Vector6<f64>,
}

/// The running sums of one work item's inliers, in the target view's frame (where the
/// data term is evaluated). `J_v = [S_x, I]` and `J_w = −[S_y, I]` with `S = −[x − c]×` (a
/// perturbation about the view's centre `c`): every block of `JᵀAJ` is a 3×3 product, and
/// only the distinct sums are kept: `J_vᵀAJ_v = [[Σ S_xᵀAS_x, (Σ AS_x)ᵀ], [Σ AS_x, Σ A]]`,
/// `J_wᵀAJ_w` alike with `S_y`, `J_vᵀAJ_w = −[[Σ S_xᵀAS_y, (Σ AS_x)ᵀ], [Σ AS_y, Σ A]]`.
struct LinearSums {
    /// The source's and the target's correction centres (target frame).
    centres: [Vector3<f64>; 2],
    /// `Σ S_xᵀAS_x, Σ S_xᵀAS_y, Σ S_yᵀAS_y, Σ AS_x, Σ AS_y, Σ A`.
    sums: [Matrix3<f64>; 6],
    /// `Σ S_xᵀAe, Σ S_yᵀAe, Σ Ae`.
    gradient: [Vector3<f64>; 3],
}

impl LinearSums {
    /// No inliers yet, with the correction centres `centres` (target frame).
    fn new(centres: [Vector3<f64>; 2]) -> Self {
        Self {
            centres,
            sums: [Matrix3::zeros(); 6],
            gradient: [Vector3::zeros(); 3],
        }
    }

    /// Adds an inlier: its weighted information `a = w·C⁻¹` and its matched points `x`,
    /// `y` (the residual is `e = x − y`).
    fn add(&mut self, a: &Matrix3<f64>, x: &Vector3<f64>, y: &Vector3<f64>) {
        let [cx, cy] = &self.centres;
        let sx = -(x - cx).cross_matrix();
        let sy = -(y - cy).cross_matrix();
        let (asx, asy) = (a * sx, a * sy);
        let [sxx, sxy, syy, asx_sum, asy_sum, a_sum] = &mut self.sums;
        *sxx += sx.transpose() * asx;
        *sxy += sx.transpose() * asy;
        *syy += sy.transpose() * asy;
        *asx_sum += asx;
        *asy_sum += asy;
        *a_sum += a;
        let ae = a * (x - y);
        let [sx_ae, sy_ae, ae_sum] = &mut self.gradient;
        *sx_ae += sx.transpose() * ae;
        *sy_ae += sy.transpose() * ae;
        *ae_sum += ae;
    }

    /// The blocks in the world frame, for the target's rotation `r` (target frame →
    /// world): with `S_world = R S Rᵀ` and `A_world = R A Rᵀ`, each block is
    /// `diag(R, R) · block · diag(R, R)ᵀ`.
    fn blocks(&self, source: usize, target: usize, r: &Matrix3<f64>) -> Blocks {
        let [sxx, sxy, syy, asx_sum, asy_sum, a_sum] = self.sums;
        let [sx_ae, sy_ae, ae_sum] = self.gradient;
        let mut b = Blocks {
            source,
            target,
            hvv: Matrix6::zeros(),
            hvw: Matrix6::zeros(),
            hww: Matrix6::zeros(),
            gv: Vector6::zeros(),
            gw: Vector6::zeros(),
        };
        let put = |h: &mut Matrix6<f64>, blocks: [Matrix3<f64>; 4]| {
            for ((row, col), m) in [(0, 0), (0, 3), (3, 0), (3, 3)].into_iter().zip(blocks) {
                h.fixed_view_mut::<3, 3>(row, col)
                    .copy_from(&(r * m * r.transpose()));
            }
        };
        put(&mut b.hvv, [sxx, asx_sum.transpose(), asx_sum, a_sum]);
        put(&mut b.hww, [syy, asy_sum.transpose(), asy_sum, a_sum]);
        put(&mut b.hvw, [-sxy, -asx_sum.transpose(), -asy_sum, -a_sum]);
        let put = |g: &mut Vector6<f64>, parts: [Vector3<f64>; 2]| {
            for (row, v) in [0, 3].into_iter().zip(parts) {
                g.fixed_rows_mut::<3>(row).copy_from(&(r * v));
            }
        };
        put(&mut b.gv, [sx_ae, ae_sum]);
        put(&mut b.gw, [-sy_ae, -ae_sum]);
        b
    }
}

/// Partial sums of one work item.
struct Sums {
    cost: f64,
    inliers: usize,
    sum_sq: f64,
    matched: Vec<bool>,
    blocks: Option<Blocks>,
}

/// Evaluates the data term of `pairs` at the poses `poses` (view → world), the
/// perturbation of view `v` being centred at `centres[v]` (world); `nearest` holds each
/// pair's correspondences, brought up to date for `poses` first. Without
/// `normal_equations` only the cost, the counts and the matches are kept.
pub(crate) fn evaluate(
    views: &[MapView],
    pairs: &[Pair],
    nearest: &mut [PairNearest],
    poses: &[Pose],
    centres: &[Point3<f64>],
    kernel: &Kernel,
    normal_equations: bool,
) -> DataTerm {
    // Each work item brings a chunk of a pair's correspondences up to date and sums its
    // terms at once, on the same thread.
    let work = super::correspondences::begin_update(nearest, views, pairs, poses);
    let items: Vec<usize> = work.iter().map(|(p, _)| *p).collect();
    let sums: Vec<Sums> = work
        .into_par_iter()
        .map(|(p, chunk)| {
            chunk_sums(
                views,
                &pairs[p],
                chunk.run_and_read(),
                poses,
                centres,
                kernel,
                normal_equations,
            )
        })
        .collect();
    let w = views.len();
    let mut term = DataTerm {
        cost: 0.0,
        inliers: vec![0; w],
        inlier_count: 0,
        sum_sq: 0.0,
        matched: vec![Vec::new(); pairs.len()],
        chunks: normal_equations.then(|| Vec::with_capacity(items.len())),
        views: w,
        normal: OnceCell::new(),
    };
    for (&p, s) in items.iter().zip(sums) {
        let (v, t) = (pairs[p].source, pairs[p].target);
        term.matched[p].extend_from_slice(&s.matched);
        term.cost += s.cost;
        term.inliers[v] += s.inliers;
        term.inliers[t] += s.inliers;
        term.inlier_count += s.inliers;
        term.sum_sq += s.sum_sq;
        if let (Some(chunks), Some(blocks)) = (&mut term.chunks, s.blocks) {
            chunks.push(blocks);
        }
    }
    term
}

fn add_block(h: &mut DMatrix<f64>, a: usize, b: usize, block: &Matrix6<f64>) {
    let mut view = h.fixed_view_mut::<6, 6>(6 * a, 6 * b);
    view += block;
}

/// The target point whose surfel the source point `x` (target frame) saw: where its
/// viewing ray `u` (target frame; zero if unknown) crosses the plane of the surfel `j`
/// nearest to it, the nearest point within `radius` of that crossing, if its surfel has a
/// normal and is not on the boundary; else `j` (no normal, no ray, a ray within ~17° of
/// the plane, nothing there).
fn along_ray(dst: &MapView, j: usize, x: &Point3<f64>, u: &Vector3<f64>, radius: f64) -> usize {
    let surfel = &dst.surfels[j];
    let Some(n) = surfel.normal else {
        return j;
    };
    let along = n.dot(u);
    if along.abs() < MIN_RAY_INCIDENCE {
        return j;
    }
    let crossing = x + u * (n.dot(&(surfel.position - x)) / along);
    match dst.tree.nearest_within(&crossing, radius) {
        Some(k) if dst.surfels[k].normal.is_some() && dst.surfels[k].boundary.is_none() => k,
        _ => j,
    }
}

/// The noise of a point along its ray `u` (world), or isotropic without one.
fn ray_covariance(u: &Vector3<f64>, variance: f64) -> Matrix3<f64> {
    if u.norm_squared() > 0.5 {
        u * u.transpose() * variance
    } else {
        Matrix3::identity() * variance
    }
}

fn chunk_sums(
    views: &[MapView],
    pair: &Pair,
    nearest: Updated<'_>,
    poses: &[Pose],
    centres: &[Point3<f64>],
    kernel: &Kernel,
    normal_equations: bool,
) -> Sums {
    let (src, dst) = (&views[pair.source], &views[pair.target]);
    let pt = &poses[pair.target];
    // Everything is evaluated in the target's frame, where its surfels and free space are
    // (the Mahalanobis distance does not depend on the frame): the source's points and
    // rays are taken there by one matrix each.
    let to_target = pt.inverse() * poses[pair.source];
    let (rotation, translation) = matrix(&to_target);
    let (pt_rotation, pt_translation) = matrix(pt);
    // The correction centres in the target's frame.
    let mut linear = normal_equations.then(|| {
        LinearSums::new(
            [pair.source, pair.target]
                .map(|v| pt_rotation.transpose() * (centres[v].coords - pt_translation)),
        )
    });
    // The source's sensor (where its rays are known): it can only have seen target
    // surfaces that face it.
    let eye = to_target * src.centre;
    let slide = 0.25 * dst.spacing * dst.spacing;
    let plane_slack = kernel.d_max * kernel.d_max;
    let floor = kernel.floor * kernel.floor;
    let mut cost = 0.0;
    let (mut inliers, mut sum_sq) = (0, 0.0);
    let mut matched = Vec::with_capacity(nearest.entries.len());
    for (k, entry) in (nearest.start..).zip(nearest.entries) {
        matched.push(false);
        if pair.mask.as_ref().is_some_and(|m| !m[k]) {
            continue;
        }
        let i = k * pair.stride;
        let x = Point3::from(rotation * src.tree.points()[i].coords + translation);
        let ray = rotation * src.rays[i];
        // Whether the target's sensor saw empty space where the point lies, if known (see
        // `FreeSpace`): at the point and one σ of its own noise farther along its ray, so
        // that the noise alone does not put a point of a surface next to the target's
        // free space (a silhouette seen at grazing) into it.
        let seen_through = || {
            dst.free_space
                .as_ref()
                .map(|f| f.contains(&x) && f.contains(&(x + ray * src.sigmas[i])))
        };
        let Some((j, _)) = entry.within(kernel.reach) else {
            // Out of reach: an outlier, unless the target's sensor never looked there.
            cost += pair.weight
                * match seen_through() {
                    Some(false) => kernel.cost(1.0).0,
                    _ => kernel.outlier_cost(),
                };
            continue;
        };
        let surfel = &dst.surfels[j];
        let beyond = surfel
            .boundary
            .is_some_and(|out| (x - dst.tree.points()[j]).dot(&out) > 0.0);
        // Beyond the edge where the target's sensor saw through: the point contradicts
        // the target, and is pulled back onto the edge point itself (point-to-point).
        let contradicts = beyond && seen_through() == Some(true);
        if (beyond || pair.contradictions_only) && !contradicts {
            // Beyond the edge of what the target saw (see `MapView`), where it did not see
            // empty space: no pull, and the cost a true match is expected to have (m² =
            // its constrained dimensions), so sliding a point off the edge neither gains
            // nor loses.
            let dims = if surfel.normal.is_some() { 1.0 } else { 3.0 };
            cost += pair.weight * kernel.cost(dims).0;
            continue;
        }
        let (j, surfel) = if contradicts || !kernel.along_rays {
            (j, surfel)
        } else {
            let k = along_ray(dst, j, &x, &ray, kernel.reach);
            (k, &dst.surfels[k])
        };
        let (y, normal) = if contradicts {
            (dst.tree.points()[j], None)
        } else {
            (surfel.position, surfel.normal)
        };
        // Only where both sensors are known: without its own, the source's centre is its
        // centroid, behind a convex view's rim, not a place it was seen from.
        let sensors_known = dst.rays[j] != Vector3::zeros() && ray != Vector3::zeros();
        if let Some(n) = normal.filter(|_| sensors_known) {
            let to_eye = eye - y;
            if n.dot(&to_eye) < -MIN_FACING * to_eye.norm() {
                cost += pair.weight * kernel.outlier_cost();
                continue;
            }
        }
        let e = x - y;
        let var_x = src.sigmas[i] * src.sigmas[i];
        let mut cov = ray_covariance(&ray, var_x)
            + ray_covariance(&dst.rays[j], surfel.variance)
            + Matrix3::identity() * floor;
        cov += match normal {
            Some(n) => (Matrix3::identity() - n * n.transpose()) * plane_slack,
            None => Matrix3::identity() * (slide + var_x),
        };
        let Some(info) = cov.try_inverse() else {
            cost += pair.weight * kernel.outlier_cost();
            continue;
        };
        let m2 = e.dot(&(info * e));
        if let Some(last) = matched.last_mut() {
            *last = m2 <= kernel.select * kernel.select;
        }
        let (point_cost, weight) = kernel.cost(m2);
        cost += pair.weight * point_cost;
        if weight == 0.0 {
            continue;
        }
        inliers += 1;
        sum_sq += e.norm_squared();
        if let Some(linear) = &mut linear {
            linear.add(&(info * (pair.weight * weight)), &x.coords, &y.coords);
        }
    }
    Sums {
        cost,
        inliers,
        sum_sq,
        matched,
        blocks: linear.map(|l| l.blocks(pair.source, pair.target, &pt_rotation)),
    }
}
