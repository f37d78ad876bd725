//! [`estimate_view_direction`]: which way a single range view was seen from, read from the
//! view itself — for scans whose frame is not their sensor's (a turntable's frame, an
//! object frame a scanner's software exported), where the frame's origin says nothing of
//! where the sensor stood and the MAP's test of which way a surface faces would go wrong.
//!
//! A range sensor sees only the surfaces that face it, sampled in proportion to their area
//! as the sensor sees them. The view's normals, oriented consistently over its surface (each
//! sampled point's normal turned to agree with its neighbours', the most nearly parallel
//! first),
//! lie in one hemisphere, and their mean points along the viewing direction or against it
//! (a uniform spread weighted by the cosine has a mean of length ⅔; the Stanford bunny's
//! real scans 0.6–0.7). The sign: what a sensor sees of an object bulges towards it — the
//! points whose normal lies along the mean (the middle of what was seen) stand farther
//! along it than those seen at grazing (its rim). A view whose normals do not agree on a
//! side, or that has no middle or no rim (one flat face), has no estimate.

use std::collections::BinaryHeap;

use kiddo::{ImmutableKdTree, SquaredEuclidean};
use nalgebra::{Unit, Vector3};

use super::local_planes::{LocalPlane, sampled_local_planes};
use crate::cloud::PointCloud;

/// Points sampled per view.
const SAMPLES: usize = 2000;

/// Neighbours a sampled point hands its normal's side to.
const ORIENTATION_NEIGHBOURS: usize = 8;

/// The consistently oriented normals' mean must be at least this long.
const MIN_MEAN_LENGTH: f64 = 0.4;

/// A normal within this cosine of the mean is the middle of the view; below
/// [`RIM_COSINE`] it is the rim.
const MIDDLE_COSINE: f64 = 0.9;
const RIM_COSINE: f64 = 0.5;

/// Fewest samples in the middle and in the rim.
const MIN_SAMPLES_EACH: usize = 20;

/// The unit direction from `view`'s points towards the sensor that saw them (in the
/// view's frame), `None` where the view does not tell (see the module doc).
///
/// ```
/// use nbv_core::cloud::PointCloud;
/// use nbv_core::registration::estimate_view_direction;
/// use nalgebra::Point3;
/// // The half of a 5 cm sphere that faces +z, sampled on a grid as seen from above.
/// let mut pts = Vec::new();
/// for i in -50..=50 {
///     for j in -50..=50 {
///         let (x, y) = (i as f64 * 0.001, j as f64 * 0.001);
///         if x * x + y * y < 0.05 * 0.05 {
///             pts.push(Point3::new(x, y, (0.05f64 * 0.05 - x * x - y * y).sqrt()));
///         }
///     }
/// }
/// let d = estimate_view_direction(&PointCloud::from_points(pts)).unwrap();
/// assert!(d.z > 0.99, "{d:?}");
/// ```
pub fn estimate_view_direction(view: &PointCloud) -> Option<Unit<Vector3<f64>>> {
    let planes = sampled_local_planes(view, SAMPLES)?;
    let normals = oriented_normals(&planes)?;
    let sum: Vector3<f64> = normals.iter().flatten().sum();
    let count = normals.iter().flatten().count();
    if count == 0 || sum.norm() < MIN_MEAN_LENGTH * count as f64 {
        return None;
    }
    let axis = sum.normalize();
    let (mut middle, mut rim) = ((0.0, 0usize), (0.0, 0usize));
    for (p, n) in planes.iter().zip(&normals) {
        let Some(n) = n else { continue };
        let c = n.dot(&axis);
        let along = p.point.coords.dot(&axis);
        if c > MIDDLE_COSINE {
            middle = (middle.0 + along, middle.1 + 1);
        } else if c < RIM_COSINE {
            rim = (rim.0 + along, rim.1 + 1);
        }
    }
    if middle.1 < MIN_SAMPLES_EACH || rim.1 < MIN_SAMPLES_EACH {
        return None;
    }
    let bulge = middle.0 / middle.1 as f64 - rim.0 / rim.1 as f64;
    if !bulge.is_finite() || bulge == 0.0 {
        return None;
    }
    Some(Unit::new_normalize(axis * bulge.signum()))
}

/// The planes' normals turned to agree with their neighbours', across the most nearly
/// parallel pairs first (Prim's tree over the samples' nearest neighbours, weighted by
/// `1 − |nᵢ·nⱼ|`, Hoppe et al. 1992: a fold or a thin part is crossed last), from the first
/// sample of the largest connected part; `None` for the samples outside that part.
fn oriented_normals(planes: &[LocalPlane]) -> Option<Vec<Option<Vector3<f64>>>> {
    let points: Vec<[f64; 3]> = planes
        .iter()
        .map(|p| [p.point.x, p.point.y, p.point.z])
        .collect();
    let tree = ImmutableKdTree::<f64, 3>::builder()
        .build_from_slice(&points)
        .ok()?;
    let k = std::num::NonZeroUsize::new(ORIENTATION_NEIGHBOURS + 1)?;
    let neighbours: Vec<Vec<usize>> = points
        .iter()
        .map(|p| {
            tree.query(p)
                .nearest_n::<SquaredEuclidean<f64>>(k)
                .execute()
                .iter()
                .map(|n| n.item as usize)
                .collect()
        })
        .collect();
    let mut best: Vec<Option<Vector3<f64>>> = Vec::new();
    let mut done = vec![false; planes.len()];
    for start in 0..planes.len() {
        if done[start] {
            continue;
        }
        let mut part = vec![None; planes.len()];
        // (agreement |nᵢ·nⱼ| as ordered bits, -j, i): the most parallel first, ties by index.
        let mut heap = BinaryHeap::from([(u64::MAX, std::cmp::Reverse(start), start)]);
        while let Some((_, std::cmp::Reverse(j), i)) = heap.pop() {
            if done[j] {
                continue;
            }
            done[j] = true;
            let ni = part[i].unwrap_or(planes[i].normal);
            let nj = planes[j].normal;
            part[j] = Some(if nj.dot(&ni) < 0.0 { -nj } else { nj });
            for &m in &neighbours[j] {
                if !done[m] {
                    let agreement = planes[m].normal.dot(&nj).abs();
                    heap.push((agreement.to_bits(), std::cmp::Reverse(m), j));
                }
            }
        }
        if part.iter().flatten().count() > best.iter().flatten().count() {
            best = part;
        }
    }
    Some(best)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Point3, Rotation3};
    use proptest::prelude::*;

    /// The part of a 6 × 4 × 3 cm ellipsoid a sensor at `direction` (infinitely far)
    /// sees, sampled on the sensor's image grid.
    fn seen_ellipsoid(direction: Vector3<f64>) -> PointCloud {
        let axes = Vector3::new(0.06, 0.04, 0.03);
        let d = direction.normalize();
        let to_world = Rotation3::rotation_between(&Vector3::z(), &d).unwrap_or_else(|| {
            Rotation3::from_axis_angle(&Vector3::x_axis(), std::f64::consts::PI)
        });
        let mut pts = Vec::new();
        for i in -80..=80 {
            for j in -80..=80 {
                // The ray through image point (u, v), coming from +d: x = o − s·d.
                let o = to_world * Vector3::new(i as f64 * 0.001, j as f64 * 0.001, 1.0);
                let (a, b) = (o.component_div(&axes), (-d).component_div(&axes));
                let (qa, qb, qc) = (b.dot(&b), 2.0 * a.dot(&b), a.dot(&a) - 1.0);
                let disc = qb * qb - 4.0 * qa * qc;
                if disc > 0.0 {
                    let s = (-qb - disc.sqrt()) / (2.0 * qa);
                    pts.push(Point3::from(o - d * s));
                }
            }
        }
        PointCloud::from_points(pts)
    }

    proptest! {
        /// Whichever way an elongated convex object is seen from, the estimate is within
        /// 45° of it: the side, which is what the MAP's facing test needs (it allows 84°).
        #[test]
        fn finds_the_side_a_convex_object_was_seen_from(
            x in -1.0f64..1.0, y in -1.0f64..1.0, z in -1.0f64..1.0,
        ) {
            let d = Vector3::new(x, y, z);
            prop_assume!(d.norm() > 0.2);
            let est = estimate_view_direction(&seen_ellipsoid(d)).unwrap();
            let angle = est.dot(&d.normalize()).clamp(-1.0, 1.0).acos().to_degrees();
            prop_assert!(angle < 45.0, "seen from {d:?}, estimated {est:?}: {angle:.1}°");
        }
    }

    #[test]
    fn one_flat_face_has_no_estimate() {
        let pts = (0..2500)
            .map(|i| Point3::new((i % 50) as f64 * 0.002, (i / 50) as f64 * 0.002, 0.0))
            .collect();
        assert!(estimate_view_direction(&PointCloud::from_points(pts)).is_none());
    }
}
