//! [`SurfaceSides`]: which sides of an object's occupied voxels the views have seen — per
//! voxel, the directions (26 bins: the faces, edges and corners of a cube) from which it
//! was hit. A 2 cm voxel holds surface facing several ways (a handle's inner and outer
//! side, a thin rim, the back of a bottle's neck); eq. (4) counts it as known once any ray
//! hit it, so views that would see its unseen sides score as overlap only, while views of
//! sides already seen keep scoring. With the sides recorded, an occupied voxel seen from a
//! new direction counts as new surface ([`SurfaceSides::unseen_from`]), and each view
//! taken is recorded ([`SurfaceSides::record`]). What the new-surface stop rule reads is
//! measured on the points instead ([`new_surface_share`](super::new_surface_share)).

use crate::occupancy::GridGeometry;
use nalgebra::{Point3, Vector3};
use std::collections::HashMap;

/// The 26 unit directions to a voxel's neighbours, in a fixed order.
fn directions() -> [Vector3<f64>; 26] {
    let mut out = [Vector3::zeros(); 26];
    let mut k = 0;
    for x in -1i32..=1 {
        for y in -1i32..=1 {
            for z in -1i32..=1 {
                if (x, y, z) != (0, 0, 0) {
                    out[k] = Vector3::new(f64::from(x), f64::from(y), f64::from(z)).normalize();
                    k += 1;
                }
            }
        }
    }
    out
}

/// The bin of direction `d` (not necessarily unit): the nearest of the 26.
fn bin(dirs: &[Vector3<f64>; 26], d: &Vector3<f64>) -> usize {
    let mut best = (0, f64::NEG_INFINITY);
    for (k, u) in dirs.iter().enumerate() {
        let dot = u.dot(d);
        if dot > best.1 {
            best = (k, dot);
        }
    }
    best.0
}

/// What one [`SurfaceSides::record`] saw first.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct NewlySeen {
    /// Voxels no earlier record had.
    pub voxels: usize,
    /// (Voxel, side) pairs no earlier record had (a new voxel's side included).
    pub sides: usize,
}

/// Per occupied voxel, the direction bins it was seen from.
///
/// ```
/// use nbv_core::nbv::SurfaceSides;
/// use nbv_core::occupancy::GridGeometry;
/// use nalgebra::Point3;
/// let g = GridGeometry::new(Point3::new(0.0, 0.0, 0.0), Point3::new(1.0, 1.0, 1.0), 0.02).unwrap();
/// let mut sides = SurfaceSides::default();
/// let p = Point3::new(0.5, 0.5, 0.5);
/// // Seen from above: a new voxel and side; from above again: nothing new; from below: a
/// // new side of the same voxel.
/// let first = sides.record(&g, &Point3::new(0.5, 0.5, 0.9), &[p]);
/// assert_eq!((first.voxels, first.sides), (1, 1));
/// assert_eq!(sides.record(&g, &Point3::new(0.5, 0.51, 0.9), &[p]).sides, 0);
/// let v = g.linear(g.voxel_of(&p).unwrap()).unwrap();
/// assert!(sides.unseen_from(&g, v, &Point3::new(0.5, 0.5, 0.1)));
/// assert!(!sides.unseen_from(&g, v, &Point3::new(0.5, 0.5, 0.95)));
/// let below = sides.record(&g, &Point3::new(0.5, 0.5, 0.1), &[p]);
/// assert_eq!((below.voxels, below.sides), (0, 1));
/// assert_eq!((sides.voxels(), sides.total()), (1, 2));
/// ```
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct SurfaceSides {
    seen: HashMap<usize, u32>,
    total: usize,
}

impl SurfaceSides {
    /// Records `points` (world frame) seen from `origin`: each point's voxel seen from the
    /// direction back to the origin. Returns what was new.
    pub fn record(
        &mut self,
        geometry: &GridGeometry,
        origin: &Point3<f64>,
        points: &[Point3<f64>],
    ) -> NewlySeen {
        let dirs = directions();
        let mut new = NewlySeen::default();
        for p in points {
            let Some(v) = geometry.voxel_of(p).and_then(|i| geometry.linear(i)) else {
                continue;
            };
            let bit = 1u32 << bin(&dirs, &(origin - p));
            let mask = self.seen.entry(v).or_insert_with(|| {
                new.voxels += 1;
                0
            });
            if *mask & bit == 0 {
                *mask |= bit;
                new.sides += 1;
            }
        }
        self.total += new.sides;
        new
    }

    /// Voxels seen so far.
    pub fn voxels(&self) -> usize {
        self.seen.len()
    }

    /// The sides `cloud` shows, each point seen from its own sensor origin (a cloud
    /// without origins shows none).
    pub fn of_cloud(geometry: &GridGeometry, cloud: &crate::cloud::PointCloud) -> Self {
        let mut sides = Self::default();
        if let Some(origins) = &cloud.origins {
            for (p, o) in cloud.points.iter().zip(origins) {
                sides.record(geometry, o, std::slice::from_ref(p));
            }
        }
        sides
    }

    /// Whether voxel `v` (linear index) was never seen from the direction of `from`
    /// (a voxel never seen at all counts as unseen).
    pub fn unseen_from(&self, geometry: &GridGeometry, v: usize, from: &Point3<f64>) -> bool {
        let Some(idx) = geometry.unlinear(v) else {
            return false;
        };
        let bit = 1u32 << bin(&directions(), &(from - geometry.center(idx)));
        self.seen.get(&v).is_none_or(|m| m & bit == 0)
    }

    /// (Voxel, side) pairs recorded so far.
    pub fn total(&self) -> usize {
        self.total
    }
}
