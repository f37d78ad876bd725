//! Signed-distance primitives (negative inside, metres) and the operations that combine
//! them. The solids of [`super::library`] are built from these.
//!
//! Exact distances for the capsule, the rounded box and the lathe; the ellipsoid uses the
//! usual first-order bound. A smooth union blends two shapes within a radius `k`, so
//! composed objects become one surface with fillets where the parts meet.

use nalgebra::{Point3, Vector2, Vector3};

/// Signed distance to a capsule: the segment `a`–`b` swept by a ball of radius `r`.
///
/// ```
/// use nbv_scenes::meshgen::sdf::capsule;
/// use nalgebra::Point3;
/// let d = capsule(&Point3::new(0.0, 0.5, 0.0), &Point3::origin(), &Point3::new(1.0, 0.0, 0.0), 0.2);
/// assert!((d - 0.3).abs() < 1e-12);
/// ```
pub fn capsule(p: &Point3<f64>, a: &Point3<f64>, b: &Point3<f64>, r: f64) -> f64 {
    let ab = b - a;
    let ap = p - a;
    let len2 = ab.norm_squared();
    let t = if len2 > 0.0 {
        (ap.dot(&ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (ap - ab * t).norm() - r
}

/// Signed distance to a tube of radius `r` along a polyline (a chain of capsules).
pub fn tube(p: &Point3<f64>, path: &[Point3<f64>], r: f64) -> f64 {
    path.windows(2)
        .map(|w| capsule(p, &w[0], &w[1], r))
        .fold(f64::INFINITY, f64::min)
}

/// Signed distance to a box centred at `c` with half extents `half`, its edges rounded with
/// radius `round` (`round` ≤ every half extent).
pub fn round_box(p: &Point3<f64>, c: &Point3<f64>, half: &Vector3<f64>, round: f64) -> f64 {
    let q = (p - c).abs() - (half - Vector3::repeat(round));
    let outside = q.sup(&Vector3::zeros()).norm();
    let inside = q.x.max(q.y).max(q.z).min(0.0);
    outside + inside - round
}

/// Approximate signed distance to an axis-aligned ellipsoid (exact on the surface and
/// for spheres; a bound elsewhere, which is enough for meshing).
pub fn ellipsoid(p: &Point3<f64>, c: &Point3<f64>, radii: &Vector3<f64>) -> f64 {
    let q = p - c;
    let k0 = q.component_div(radii).norm();
    let k1 = q.component_div(&radii.component_mul(radii)).norm();
    if k1 > 0.0 {
        k0 * (k0 - 1.0) / k1
    } else {
        -radii.min()
    }
}

/// Signed distance to a capped cylinder between the centres `a` and `b` of its end faces,
/// radius `r`, edges rounded with radius `round` (≤ `r` and ≤ half the length).
pub fn round_cylinder(
    p: &Point3<f64>,
    a: &Point3<f64>,
    b: &Point3<f64>,
    r: f64,
    round: f64,
) -> f64 {
    let axis = b - a;
    let len = axis.norm();
    let Some(u) = axis.try_normalize(0.0) else {
        return (p - a).norm() - r;
    };
    let ap = p - a;
    let along = ap.dot(&u) - 0.5 * len;
    let radial = (ap - u * ap.dot(&u)).norm();
    let d = Vector2::new(radial - r + round, along.abs() - 0.5 * len + round);
    d.sup(&Vector2::zeros()).norm() + d.x.max(d.y).min(0.0) - round
}

/// A solid of revolution about the z axis, from its half profile in the `(ρ, z)` plane.
///
/// The profile lists the outline from the axis at the bottom to the axis at the top
/// (`ρ ≥ 0`, first and last points on `ρ = 0`); the axis closes it.
#[derive(Debug, Clone, PartialEq)]
pub struct Lathe {
    profile: Vec<Vector2<f64>>,
}

impl Lathe {
    /// A lathe solid from `(ρ, z)` points (see the type's doc).
    ///
    /// ```
    /// use nbv_scenes::meshgen::sdf::Lathe;
    /// use nalgebra::Point3;
    /// // A cylinder of radius 1 and height 2.
    /// let l = Lathe::new(&[[0.0, 0.0], [1.0, 0.0], [1.0, 2.0], [0.0, 2.0]]);
    /// assert!((l.distance(&Point3::new(0.0, 0.0, 1.0)) + 1.0).abs() < 1e-12);
    /// assert!((l.distance(&Point3::new(3.0, 0.0, 1.0)) - 2.0).abs() < 1e-12);
    /// ```
    pub fn new(profile: &[[f64; 2]]) -> Self {
        Self {
            profile: profile.iter().map(|&[r, z]| Vector2::new(r, z)).collect(),
        }
    }

    /// Signed distance from `p` to the solid.
    pub fn distance(&self, p: &Point3<f64>) -> f64 {
        let q = Vector2::new((p.x * p.x + p.y * p.y).sqrt(), p.z);
        let mut best = f64::INFINITY;
        let mut inside = false;
        for w in self.profile.windows(2) {
            let (a, b) = (w[0], w[1]);
            let ab = b - a;
            let len2 = ab.norm_squared();
            let t = if len2 > 0.0 {
                ((q - a).dot(&ab) / len2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            best = best.min((q - a - ab * t).norm());
            // Crossing test of a horizontal ray towards +ρ.
            if (a.y > q.y) != (b.y > q.y) {
                let x = a.x + (q.y - a.y) / (b.y - a.y) * (b.x - a.x);
                if q.x < x {
                    inside = !inside;
                }
            }
        }
        // The closing segment lies on the axis (ρ = 0), where q.x ≥ 0 never crosses it
        // towards +ρ except exactly on the axis, which the profile ends already cover.
        if inside { -best } else { best }
    }
}

/// Smooth union of two signed distances with blend radius `k` (polynomial smooth minimum;
/// `k = 0` is the plain union).
///
/// ```
/// use nbv_scenes::meshgen::sdf::smooth_union;
/// assert_eq!(smooth_union(1.0, 2.0, 0.0), 1.0);
/// assert!(smooth_union(0.0, 0.0, 0.1) < 0.0); // fillet where both meet
/// assert_eq!(smooth_union(0.0, 1.0, 0.1), 0.0); // far apart: unchanged
/// ```
pub fn smooth_union(a: f64, b: f64, k: f64) -> f64 {
    if k <= 0.0 {
        return a.min(b);
    }
    let h = (k - (a - b).abs()).max(0.0) / k;
    a.min(b) - h * h * k * 0.25
}

/// Intersection with the half-space `z ≥ 0`: a flat base on the table plane.
pub fn above_floor(d: f64, p: &Point3<f64>) -> f64 {
    d.max(-p.z)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_box_distances() {
        let c = Point3::origin();
        let half = Vector3::new(1.0, 2.0, 3.0);
        assert!((round_box(&Point3::new(2.0, 0.0, 0.0), &c, &half, 0.1) - 1.0).abs() < 1e-12);
        assert!((round_box(&Point3::origin(), &c, &half, 0.1) + 1.0).abs() < 1e-12);
    }

    #[test]
    fn round_cylinder_distances() {
        let a = Point3::origin();
        let b = Point3::new(0.0, 0.0, 2.0);
        assert!(
            (round_cylinder(&Point3::new(3.0, 0.0, 1.0), &a, &b, 1.0, 0.1) - 2.0).abs() < 1e-12
        );
        assert!(
            (round_cylinder(&Point3::new(0.0, 0.0, 3.0), &a, &b, 1.0, 0.1) - 1.0).abs() < 1e-12
        );
        assert!(
            (round_cylinder(&Point3::new(0.0, 0.0, 1.0), &a, &b, 1.0, 0.1) + 1.0).abs() < 1e-12
        );
    }

    #[test]
    fn ellipsoid_is_exact_on_axes_surface() {
        let r = Vector3::new(0.3, 0.2, 0.1);
        let c = Point3::origin();
        assert!(ellipsoid(&Point3::new(0.3, 0.0, 0.0), &c, &r).abs() < 1e-12);
        assert!(ellipsoid(&Point3::new(0.0, 0.0, 0.1), &c, &r).abs() < 1e-12);
        assert!(ellipsoid(&Point3::origin(), &c, &r) < 0.0);
    }

    #[test]
    fn lathe_sign_and_distance() {
        // A cone of base radius 1 and height 1.
        let l = Lathe::new(&[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]);
        assert!(l.distance(&Point3::new(0.0, 0.2, 0.2)) < 0.0);
        assert!((l.distance(&Point3::new(0.0, 0.0, -0.5)) - 0.5).abs() < 1e-12);
        let d = l.distance(&Point3::new(1.0, 0.0, 1.0));
        assert!((d - std::f64::consts::FRAC_1_SQRT_2).abs() < 1e-12);
    }
}
