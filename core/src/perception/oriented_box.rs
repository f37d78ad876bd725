//! [`OrientedBox`]: a box with a pose — the region phase 1 keeps, or a known obstacle whose
//! points must not become an object cluster.

use nalgebra::{Isometry3, Point3, Vector3};

/// A box of half extents `half_extents` centred on the origin of the frame `pose`
/// (`T_world_box`). Points on the faces are inside.
///
/// ```
/// use nbv_core::perception::OrientedBox;
/// use nalgebra::{Isometry3, Point3, Vector3};
/// let b = OrientedBox::from_bounds(Point3::new(0.0, 0.0, 0.0), Point3::new(1.0, 2.0, 3.0));
/// assert!(b.contains(&Point3::new(0.5, 2.0, 1.0)));
/// assert!(!b.contains(&Point3::new(-0.01, 1.0, 1.0)));
/// // Rotated 90° about z: the long side now lies along x.
/// let r = OrientedBox::new(
///     Isometry3::rotation(Vector3::z() * std::f64::consts::FRAC_PI_2),
///     Vector3::new(0.1, 1.0, 0.1),
/// );
/// assert!(r.contains(&Point3::new(0.9, 0.0, 0.0)) && !r.contains(&Point3::new(0.0, 0.9, 0.0)));
/// assert!(r.inflated(0.05).contains(&Point3::new(0.0, 0.14, 0.0)));
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OrientedBox {
    /// Pose of the box centre (`T_world_box`).
    pub pose: Isometry3<f64>,
    /// Half side lengths along the box's own x, y, z (m, ≥ 0).
    pub half_extents: Vector3<f64>,
}

impl OrientedBox {
    /// A box at `pose` with the given half extents (negative values count as 0).
    pub fn new(pose: Isometry3<f64>, half_extents: Vector3<f64>) -> Self {
        Self {
            pose,
            half_extents: half_extents.map(|h| h.max(0.0)),
        }
    }

    /// The axis-aligned box `[min, max]` (corners in any order).
    pub fn from_bounds(min: Point3<f64>, max: Point3<f64>) -> Self {
        let (lo, hi) = (min.inf(&max), min.sup(&max));
        let c = nalgebra::center(&lo, &hi);
        Self::new(Isometry3::translation(c.x, c.y, c.z), (hi - lo) / 2.0)
    }

    /// The same box grown by `margin` on every side (shrunk for a negative margin, never
    /// below zero size).
    pub fn inflated(&self, margin: f64) -> Self {
        Self::new(self.pose, self.half_extents.add_scalar(margin))
    }

    /// Whether `p` lies inside or on the box.
    pub fn contains(&self, p: &Point3<f64>) -> bool {
        let local = self.pose.inverse_transform_point(p);
        (0..3).all(|a| local[a].abs() <= self.half_extents[a])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Translation3, UnitQuaternion};
    use proptest::prelude::*;

    proptest! {
        /// Containment is a property of the box and the point together: moving both by
        /// the same rigid motion does not change it.
        #[test]
        fn containment_is_invariant_under_rigid_motion(
            p in prop::array::uniform3(-1.0f64..1.0),
            h in prop::array::uniform3(0.01f64..0.8),
            r in prop::array::uniform3(-3.0f64..3.0),
            t in prop::array::uniform3(-2.0f64..2.0),
        ) {
            let b = OrientedBox::new(Isometry3::identity(), Vector3::from(h));
            let m = Isometry3::from_parts(
                Translation3::new(t[0], t[1], t[2]),
                UnitQuaternion::from_euler_angles(r[0], r[1], r[2]),
            );
            let moved = OrientedBox::new(m, Vector3::from(h));
            let p = Point3::from(p);
            // Skip points within rounding distance of a face.
            let margin = (0..3).map(|a| (p[a].abs() - h[a]).abs()).fold(f64::INFINITY, f64::min);
            prop_assume!(margin > 1e-9);
            prop_assert_eq!(b.contains(&p), moved.contains(&(m * p)));
            prop_assert_eq!(b.contains(&p), (0..3).all(|a| p[a].abs() <= h[a]));
        }
    }
}
