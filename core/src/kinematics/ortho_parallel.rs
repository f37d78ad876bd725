//! Closed-form inverse kinematics of "ortho-parallel" six-axis arms with a spherical wrist:
//! J1 ⟂ J2, J2 ∥ J3, and J4, J5, J6 meeting in one point with J4 ⟂ J5 ⟂ J6; shoulder offset,
//! elbow offset and lateral offset allowed. This is the class of the Comau SMART SiX.
//!
//! The geometry is read from the loaded chain at q = 0 (product-of-exponentials form: world
//! axes and points of the six joints, the wrist centre, the tip pose), never from constants,
//! and the structure is verified first. Solving a tip pose then takes three steps:
//! 1. J1 from the wrist centre's position around the J1 axis (front and back branches);
//! 2. J3 from the shoulder-to-wrist distance (law of cosines in the plane of J2 and J3,
//!    elbow up and down), then J2 to swing the wrist centre onto the target;
//! 3. J4, J5, J6 from the remaining rotation (two wrist branches), using `atan2` of a sine
//!    and a cosine so that solutions stay accurate close to the wrist singularity.
//!
//! At an exact singularity the free angle (J1 on the shoulder singularity, J4 on the wrist
//! singularity) is taken from the reference configuration.

use super::ik_error::Unreachable;
use super::ik_solution::{Branch, Elbow, SINGULARITY_MARGIN, Shoulder, Singularity, Wrist};
use super::joints::{DOF, Joints, wrap_to_pi};
use super::rotation_subproblems::{angle_about, closest_points, parallel_distance, reject, rot};
use super::serial_chain::SerialChain;
use crate::math::Pose;
use nalgebra::{Point3, Vector3};
use serde::{Deserialize, Serialize};

/// Tolerance (rad for angles, m for distances) of the structure checks. Chains that deviate
/// by less (e.g. a URDF that writes π/2 as 1.5708) are accepted; their closed-form solutions
/// are then polished numerically on the exact chain.
pub const STRUCTURE_TOLERANCE: f64 = 1e-4;

/// Below this (m for the wrist centre's distance from J1, sine of the J4–J6 angle for the
/// wrist) a direction is numerically undefined: the configuration is treated as exactly
/// singular and the free angle is taken from the reference. Rounding near a second
/// singularity reaches about 1e-12, hence the margin; the error it leaves is of this order.
const FREE_EPS: f64 = 1e-10;

/// Relative slack on the reach test (|cos ψ| ≤ 1 + this), about 1e-11 m for the Comau.
const REACH_EPS: f64 = 1e-10;

/// Elbow angles this close to 0 or π are snapped onto them, merging the two elbow branches
/// of a stretched or folded arm. The position error this causes is second order
/// (about 1e-15 m).
const ELBOW_SNAP: f64 = 1e-7;

/// Why a chain is not of the ortho-parallel class.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum IkStructureError {
    /// J1 and J2 are not perpendicular.
    #[error("J1 and J2 are not perpendicular (|cos| = {cos:.3e})")]
    ShoulderNotPerpendicular {
        /// |cos| of the angle between the axes.
        cos: f64,
    },
    /// J2 and J3 are not parallel.
    #[error("J2 and J3 are not parallel (|sin| = {sin:.3e})")]
    ElbowNotParallel {
        /// |sin| of the angle between the axes.
        sin: f64,
    },
    /// J2 and J3 are the same line.
    #[error("J2 and J3 are the same axis (distance {distance:.3e} m)")]
    ElbowCoaxial {
        /// Distance between the axes.
        distance: f64,
    },
    /// Two consecutive wrist axes are not perpendicular.
    #[error("wrist axes J{first} and J{second} are not perpendicular (|cos| = {cos:.3e})")]
    WristNotPerpendicular {
        /// First axis (4 or 5).
        first: usize,
        /// Second axis (5 or 6).
        second: usize,
        /// |cos| of the angle between them.
        cos: f64,
    },
    /// J4, J5, J6 do not meet in one point.
    #[error("wrist axes J4, J5, J6 do not meet in one point (gap {gap:.3e} m)")]
    WristNotSpherical {
        /// Largest distance between the pairwise closest points.
        gap: f64,
    },
    /// The wrist centre lies on the J3 axis.
    #[error("the wrist centre lies on the J3 axis (distance {distance:.3e} m)")]
    WristOnElbowAxis {
        /// Its distance from the axis.
        distance: f64,
    },
}

/// Geometric parameters of an ortho-parallel arm, measured on the loaded chain (m). For the
/// Comau SMART SiX they equal its DH lengths.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct OrthoParallelParams {
    /// Shoulder offset: distance between the J1 and J2 axes.
    pub a1: f64,
    /// Shoulder height: distance along J1 from the root origin to the common perpendicular
    /// of J1 and J2.
    pub d1: f64,
    /// Upper arm: distance between the J2 and J3 axes.
    pub a2: f64,
    /// Elbow offset: distance between the J3 and J4 axes.
    pub a3: f64,
    /// Forearm: distance along J4 from its common perpendicular with J3 to the wrist centre.
    pub d4: f64,
    /// Wrist centre to tip-link origin.
    pub d6: f64,
    /// Lateral offset: signed distance of the wrist centre from J1 along J2.
    pub lateral: f64,
}

/// One geometric solution before joint limits are applied (angles in (-π, π]).
#[derive(Debug, Clone, Copy)]
pub(crate) struct RawSolution {
    pub q: [f64; DOF],
    pub branch: Branch,
    pub singularity: Singularity,
}

/// The solver, with everything it needs precomputed from the chain at q = 0.
#[derive(Debug, Clone)]
pub(crate) struct OrthoParallel {
    pub params: OrthoParallelParams,
    /// World axes at q = 0.
    u: [Vector3<f64>; DOF],
    /// Points on J1, J2, J3.
    p1: Vector3<f64>,
    p2: Vector3<f64>,
    p3: Vector3<f64>,
    /// Wrist centre at q = 0.
    w0: Vector3<f64>,
    /// Inverse of the tip pose at q = 0.
    tip0_inv: Pose,
    /// Unit vector ⟂ J1, J2 pointing to the front.
    v: Vector3<f64>,
    /// Lateral offset.
    s: f64,
    /// J5 angle that aligns J6 with J4.
    beta: f64,
    /// Triangle orientation (shoulder, elbow, wrist) about J2 of the elbow-up front arm.
    sigma_up: f64,
    /// w0 - p3 and p2 - p3 orthogonal to J3, and their lengths.
    xp: Vector3<f64>,
    xn: f64,
    yn: f64,
    /// Angle about J3 from `xp` to the projection of p2 - p3.
    theta0: f64,
}

impl OrthoParallel {
    /// Reads and verifies the geometry of `chain`.
    pub fn from_chain(chain: &SerialChain) -> Result<Self, IkStructureError> {
        let tol = STRUCTURE_TOLERANCE;
        let q0 = Joints::zeros();
        let axes = chain.joint_axes(&q0);
        let u: [Vector3<f64>; DOF] = std::array::from_fn(|k| axes[k].0);
        let p: [Vector3<f64>; DOF] = std::array::from_fn(|k| axes[k].1);
        let tip0 = chain.tip_pose(&q0);

        let cos12 = u[0].dot(&u[1]).abs();
        if cos12 > tol {
            return Err(IkStructureError::ShoulderNotPerpendicular { cos: cos12 });
        }
        let sin23 = u[1].cross(&u[2]).norm();
        if sin23 > tol {
            return Err(IkStructureError::ElbowNotParallel { sin: sin23 });
        }
        let a2 = parallel_distance(&p[1], &u[1], &p[2]);
        if a2 < tol {
            return Err(IkStructureError::ElbowCoaxial { distance: a2 });
        }
        for (first, second) in [(3, 4), (4, 5)] {
            let cos = u[first].dot(&u[second]).abs();
            if cos > tol {
                return Err(IkStructureError::WristNotPerpendicular {
                    first: first + 1,
                    second: second + 1,
                    cos,
                });
            }
        }
        let not_spherical = IkStructureError::WristNotSpherical { gap: f64::INFINITY };
        let (c4, c5a) =
            closest_points(&p[3], &u[3], &p[4], &u[4], 0.5).ok_or(not_spherical.clone())?;
        let (c5b, c6) = closest_points(&p[4], &u[4], &p[5], &u[5], 0.5).ok_or(not_spherical)?;
        let gap = (c4 - c5a)
            .norm()
            .max((c5b - c6).norm())
            .max((c5a - c5b).norm());
        if gap > tol {
            return Err(IkStructureError::WristNotSpherical { gap });
        }
        let w0 = (c4 + c5a + c5b + c6) / 4.0;

        let xp = reject(&(w0 - p[2]), &u[2]);
        let yp = reject(&(p[1] - p[2]), &u[2]);
        let (xn, yn) = (xp.norm(), yp.norm());
        if xn < tol {
            return Err(IkStructureError::WristOnElbowAxis { distance: xn });
        }
        let theta0 =
            angle_about(&u[2], &xp, &yp).ok_or(IkStructureError::ElbowCoaxial { distance: yn })?;

        // Parameters, measured.
        let (f1, f2) = closest_points(&p[0], &u[0], &p[1], &u[1], 0.5)
            .ok_or(IkStructureError::ShoulderNotPerpendicular { cos: cos12 })?;
        let a1 = (f2 - f1).norm();
        let root_on_j1 = p[0] - u[0] * u[0].dot(&p[0]);
        let d1 = (f1 - root_on_j1).norm();
        let (a3, d4) = match closest_points(&p[2], &u[2], &p[3], &u[3], tol) {
            Some((c3, c4)) => ((c4 - c3).norm(), (w0 - c4).norm()),
            None => {
                let a3 = parallel_distance(&p[2], &u[2], &p[3]);
                (a3, (xn * xn - a3 * a3).max(0.0).sqrt())
            }
        };
        let d6 = (tip0.translation.vector - w0).norm();
        let s = u[1].dot(&(w0 - p[0]));

        // Front direction: towards the shoulder offset (or the wrist centre at q = 0).
        let v0 = u[0].cross(&u[1]).normalize();
        let v = if a1 > tol {
            if v0.dot(&(f2 - f1)) < 0.0 { -v0 } else { v0 }
        } else if v0.dot(&(w0 - p[0])) < -tol {
            -v0
        } else {
            v0
        };
        // "Up": along J1, the side the upper arm points to at q = 0.
        let along = u[0].dot(&(p[2] - p[1]));
        let up = if along < -tol { -u[0] } else { u[0] };
        let sigma_up = if u[1].dot(&up.cross(&v)) >= 0.0 {
            1.0
        } else {
            -1.0
        };
        let beta =
            angle_about(&u[4], &u[5], &u[3]).ok_or(IkStructureError::WristNotPerpendicular {
                first: 5,
                second: 6,
                cos: 1.0,
            })?;

        Ok(Self {
            params: OrthoParallelParams {
                a1,
                d1,
                a2,
                a3,
                d4,
                d6,
                lateral: s,
            },
            u,
            p1: p[0],
            p2: p[1],
            p3: p[2],
            w0,
            tip0_inv: tip0.inverse(),
            v,
            s,
            beta,
            sigma_up,
            xp,
            xn,
            yn,
            theta0,
        })
    }

    /// All geometric solutions for a tip-link pose, angles wrapped to (-π, π], duplicates
    /// (coinciding branches) merged. `reference` supplies free angles at singularities.
    pub fn solve(&self, tip: &Pose, reference: &Joints) -> Result<Vec<RawSolution>, Unreachable> {
        let [u1, u2, u3, u4, u5, u6] = self.u;
        let g = tip * self.tip0_inv;
        let w = g.transform_point(&Point3::from(self.w0)).coords;
        let rg = g.rotation.to_rotation_matrix();
        let wrist_centre = [w.x, w.y, w.z];

        // J1.
        let r = w - self.p1;
        let r_perp = reject(&r, &u1);
        let n = r_perp.norm();
        let rho2 = (n - self.s.abs()) * (n + self.s.abs());
        if n < self.s.abs() - FREE_EPS {
            return Err(Unreachable::InsideOffset {
                wrist_centre,
                by: self.s.abs() - n,
            });
        }
        let rho = rho2.max(0.0).sqrt();
        let shoulder_free = n < FREE_EPS;

        let mut out: Vec<RawSolution> = Vec::with_capacity(8);
        let mut failure: Option<Unreachable> = None;
        for (sigma1, shoulder) in [(1.0, Shoulder::Front), (-1.0, Shoulder::Back)] {
            // On the J1 axis the back branch is the front branch turned by π: one family.
            if shoulder_free && sigma1 < 0.0 {
                continue;
            }
            let a = u2 * self.s + self.v * (sigma1 * rho);
            let q1 = if shoulder_free {
                reference[0]
            } else {
                angle_about(&u1, &a, &r_perp).unwrap_or(reference[0])
            };
            let r1 = rot(&u1, q1);
            let wp = r1.inverse() * r + self.p1;

            // J3 by the law of cosines orthogonally to J2 ∥ J3.
            let d = reject(&(wp - self.p2), &u3).norm();
            let cos_psi =
                (self.xn * self.xn + self.yn * self.yn - d * d) / (2.0 * self.xn * self.yn);
            if cos_psi < -1.0 - REACH_EPS {
                failure.get_or_insert(Unreachable::TooFar {
                    wrist_centre,
                    by: d - (self.xn + self.yn),
                });
                continue;
            }
            if cos_psi > 1.0 + REACH_EPS {
                failure.get_or_insert(Unreachable::TooClose {
                    wrist_centre,
                    by: (self.xn - self.yn).abs() - d,
                });
                continue;
            }
            let mut psi = cos_psi.clamp(-1.0, 1.0).acos();
            if psi < ELBOW_SNAP {
                psi = 0.0;
            } else if std::f64::consts::PI - psi < ELBOW_SNAP {
                psi = std::f64::consts::PI;
            }
            let singular_elbow = psi.sin() < SINGULARITY_MARGIN;

            for sigma2 in [1.0, -1.0] {
                let q3 = self.theta0 - sigma2 * psi;
                let x3 = rot(&u3, q3) * self.xp;
                let elbow_vec = rot(&u3, q3) * (self.w0 - self.p3);
                let wrist_at = elbow_vec + self.p3;
                let q2 = angle_about(&u2, &(wrist_at - self.p2), &(wp - self.p2))
                    .unwrap_or(reference[1]);
                let orientation = u2.dot(&(self.p3 - self.p2).cross(&x3));
                let elbow = if orientation * sigma1 * self.sigma_up >= 0.0 {
                    Elbow::Up
                } else {
                    Elbow::Down
                };

                // Wrist: R4 R5 R6 = M.
                let r123 = r1 * rot(&u2, q2) * rot(&u3, q3);
                let m = r123.transpose() * rg;
                let mu6 = m * u6;
                let c5 = u4.dot(&mu6);
                let s5 = u4.cross(&mu6).norm();
                let wrist_free = s5 < FREE_EPS;
                for (sigma3, wrist) in [(1.0, Wrist::Positive), (-1.0, Wrist::Negative)] {
                    if wrist_free && sigma3 < 0.0 {
                        continue;
                    }
                    let (q4, q5) = if wrist_free {
                        // J4 from the reference; J5 the best fit for it (an error of the
                        // order of `FREE_EPS`, polished away if it matters).
                        let q4 = reference[3];
                        let aim = rot(&u4, q4).inverse() * mu6;
                        (q4, angle_about(&u5, &u6, &aim).unwrap_or(self.beta))
                    } else {
                        let q5 = self.beta + sigma3 * s5.atan2(c5);
                        let n5 = rot(&u5, q5) * u6;
                        (angle_about(&u4, &n5, &mu6).unwrap_or(reference[3]), q5)
                    };
                    let rest = (rot(&u4, q4) * rot(&u5, q5)).transpose() * m;
                    let q6 = angle_about(&u6, &u5, &(rest * u5)).unwrap_or(reference[5]);
                    let candidate = RawSolution {
                        q: [q1, q2, q3, q4, q5, q6].map(wrap_to_pi),
                        branch: Branch {
                            shoulder,
                            elbow,
                            wrist,
                        },
                        singularity: Singularity {
                            shoulder: rho < SINGULARITY_MARGIN,
                            elbow: singular_elbow,
                            wrist: s5 < SINGULARITY_MARGIN,
                        },
                    };
                    push_unique(&mut out, candidate);
                }
            }
        }
        match failure {
            Some(reason) if out.is_empty() => Err(reason),
            _ => Ok(out),
        }
    }
}

/// Appends `candidate` unless an equal configuration (mod 2π) is already there.
fn push_unique(out: &mut Vec<RawSolution>, candidate: RawSolution) {
    let same = |a: &RawSolution| {
        a.q.iter()
            .zip(candidate.q.iter())
            .all(|(x, y)| wrap_to_pi(x - y).abs() < 1e-9)
    };
    if !out.iter().any(same) {
        out.push(candidate);
    }
}
