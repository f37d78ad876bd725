//! [`obstacle_sliver`]: a cluster that is only a known obstacle's face, shifted by the pose
//! error out of the box that should have excluded it.
//!
//! Under a calibration error the whole sweep moves, and with it the front face of a known
//! wall: the points that leave the wall's exclusion box form a flat layer, a few
//! millimetres thick (the range noise), parallel to the face and just in front of it. Such
//! a layer is no object; a real object standing against the wall is thicker than the
//! sensor's noise or not parallel to it.

use nalgebra::{Matrix3, Point3, SymmetricEigen, Vector3};
use serde::{Deserialize, Serialize};

use crate::cloud::Cluster;

use super::OrientedBox;

/// A cluster found to be a sliver of a known obstacle's face.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ObstacleSliver {
    /// The obstacle (index into the boxes given).
    pub obstacle: usize,
    /// Points of the cluster.
    pub points: usize,
    /// Its centroid.
    pub centroid: Point3<f64>,
    /// The cluster's thickness: 4 standard deviations along its least-spread direction (m).
    pub thickness: f64,
    /// Distance of its centroid in front of the box face it parallels (m; negative:
    /// behind the face, inside the box).
    pub distance: f64,
    /// Angle between the cluster's plane and the face (degrees).
    pub angle_deg: f64,
}

/// Largest angle (rad) between a sliver's plane and the face it lies against: 20°.
const MAX_ANGLE: f64 = 0.349;

/// Whether cluster `cluster` of `points` is a flat layer — thinner than `max_thickness`
/// (4σ along its least-spread direction) — parallel to a face of one of `boxes` (within
/// 20°), with its centroid at most `reach` in front of that face (and not deeper behind it
/// than `max_thickness`) and over the face (within `reach` of its edges). The first such
/// box is returned.
///
/// ```
/// use nbv_core::cloud::Cluster;
/// use nbv_core::perception::{OrientedBox, obstacle_sliver};
/// use nalgebra::{Point3, Vector3};
/// // A wall whose front face is x = 1.0, and 400 points of that face seen 12 mm in front
/// // of it, with ±2 mm of range noise (a checkerboard).
/// let wall = OrientedBox::from_bounds(Point3::new(1.0, -0.5, 0.0), Point3::new(1.05, 0.5, 0.5));
/// let pts: Vec<_> = (0..400)
///     .map(|i| {
///         let noise = if (i + i / 20) % 2 == 0 { 0.002 } else { -0.002 };
///         Point3::new(0.988 + noise, -0.1 + (i % 20) as f64 * 0.01, 0.1 + (i / 20) as f64 * 0.01)
///     })
///     .collect();
/// let sliver = Cluster::from_indices(&pts, (0..400).collect());
/// let s = obstacle_sliver(&pts, &sliver, &[wall], 0.01, 0.05).unwrap();
/// assert!((s.distance - 0.012).abs() < 1e-6 && (s.thickness - 0.008).abs() < 1e-6);
/// // A box-shaped object in the same place is no sliver.
/// let solid: Vec<_> = pts.iter().map(|p| p - Vector3::new((p.y * 100.0).rem_euclid(4.0) * 0.01, 0.0, 0.0)).collect();
/// assert!(obstacle_sliver(&solid, &Cluster::from_indices(&solid, (0..400).collect()), &[wall], 0.01, 0.05).is_none());
/// ```
pub fn obstacle_sliver(
    points: &[Point3<f64>],
    cluster: &Cluster,
    boxes: &[OrientedBox],
    max_thickness: f64,
    reach: f64,
) -> Option<ObstacleSliver> {
    if cluster.len() < 3 {
        return None;
    }
    let c = cluster.centroid;
    let cov = cluster.indices.iter().fold(Matrix3::zeros(), |acc, &i| {
        let d = points[i] - c;
        acc + d * d.transpose()
    }) / cluster.len() as f64;
    let eigen = SymmetricEigen::new(cov);
    let k = eigen.eigenvalues.imin();
    let thickness = 4.0 * eigen.eigenvalues[k].max(0.0).sqrt();
    if thickness > max_thickness {
        return None;
    }
    let normal: Vector3<f64> = eigen.eigenvectors.column(k).into_owned();
    boxes.iter().enumerate().find_map(|(obstacle, b)| {
        let n = b.pose.rotation.inverse() * normal;
        let local = b.pose.inverse() * c;
        let axis = n.iamax();
        let cos = n[axis].abs().min(1.0);
        if cos < MAX_ANGLE.cos() {
            return None;
        }
        let distance = local[axis].abs() - b.half_extents[axis];
        let over_face = (0..3).all(|a| a == axis || local[a].abs() <= b.half_extents[a] + reach);
        (distance <= reach && distance >= -max_thickness && over_face).then(|| ObstacleSliver {
            obstacle,
            points: cluster.len(),
            centroid: c,
            thickness,
            distance,
            angle_deg: cos.acos().to_degrees(),
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Isometry3, UnitQuaternion};
    use proptest::prelude::*;

    fn face_layer(x: f64, half_thickness: f64) -> Vec<Point3<f64>> {
        (0..400)
            .map(|i| {
                let n = if i % 3 == 0 {
                    -half_thickness
                } else if i % 3 == 1 {
                    0.0
                } else {
                    half_thickness
                };
                Point3::new(
                    x + n,
                    -0.1 + (i % 20) as f64 * 0.01,
                    0.1 + (i / 20) as f64 * 0.01,
                )
            })
            .collect()
    }

    proptest! {
        /// Whatever the wall's and the cluster's pose, a thin layer parallel to the face
        /// and close to it is a sliver; moved beyond reach or thickened it is not.
        #[test]
        fn found_in_any_pose(
            yaw in -3.1f64..3.1,
            shift in -0.008f64..0.04,
            t in proptest::collection::vec(-1.0f64..1.0, 3),
        ) {
            let wall = OrientedBox::from_bounds(Point3::new(1.0, -0.5, 0.0), Point3::new(1.05, 0.5, 0.5));
            let motion = Isometry3::from_parts(
                Vector3::new(t[0], t[1], t[2]).into(),
                UnitQuaternion::from_euler_angles(0.0, 0.0, yaw),
            );
            let moved = OrientedBox::new(motion * wall.pose, wall.half_extents);
            let near: Vec<_> = face_layer(1.0 - shift, 0.002).iter().map(|p| motion * p).collect();
            let cluster = Cluster::from_indices(&near, (0..near.len()).collect());
            let s = obstacle_sliver(&near, &cluster, &[moved], 0.01, 0.05);
            prop_assert!(s.is_some(), "not found");
            let s = s.unwrap();
            // (The layer's three sheets hold 134, 133 and 133 points: its mean sits 5 µm
            // off the middle sheet.)
            prop_assert!((s.distance - shift).abs() < 1e-4, "{:?} shift {}", s, shift);
            prop_assert!(s.angle_deg < 0.1);
            let far: Vec<_> = face_layer(0.93, 0.002).iter().map(|p| motion * p).collect();
            let fc = Cluster::from_indices(&far, (0..far.len()).collect());
            prop_assert!(obstacle_sliver(&far, &fc, &[moved], 0.01, 0.05).is_none());
            let thick: Vec<_> = face_layer(1.0 - shift, 0.01).iter().map(|p| motion * p).collect();
            let tc = Cluster::from_indices(&thick, (0..thick.len()).collect());
            prop_assert!(obstacle_sliver(&thick, &tc, &[moved], 0.01, 0.05).is_none());
        }
    }

    #[test]
    fn a_layer_across_the_face_is_not_a_sliver() {
        // The same thin layer, turned 90° (its plane normal along y): not parallel.
        let wall =
            OrientedBox::from_bounds(Point3::new(1.0, -0.5, 0.0), Point3::new(1.05, 0.5, 0.5));
        let turn = Isometry3::rotation(Vector3::z() * std::f64::consts::FRAC_PI_2);
        let pts: Vec<_> = face_layer(0.0, 0.002)
            .iter()
            .map(|p| turn * p + Vector3::new(0.95, 0.0, 0.0))
            .collect();
        let c = Cluster::from_indices(&pts, (0..pts.len()).collect());
        assert!(obstacle_sliver(&pts, &c, &[wall], 0.01, 0.05).is_none());
    }
}
