//! [`HullSurface`]: where the unseen surface of an object standing on a table may lie, and
//! how much of it a view would see.
//!
//! The object lies inside the convex hull of its points and of their footprint on the
//! table (it stands on the table; phase 1 and the views saw its top). Samples on the hull
//! (every ~5 mm, each carrying its share of the hull's area) are unseen where no point of
//! the object lies within the report's coverage tolerance (1 cm) and the sensors have not
//! seen through the sample's voxel and the voxel behind it (a bowl's opening is no
//! surface), and more than [`TABLE_MARGIN`] above the table (the report's coverage leaves
//! the contact out). A view's score is the unseen area it would see: samples in its field
//! of view and range, facing it, weighted by the camera's return at their incidence (full
//! below 60°, none beyond 80°: the twin's grazing ramp), and not hidden behind an occupied
//! voxel of another object or obstacle (the hull's faces hide its own back). A sample a
//! taken view was placed to see in full and did not is scored no more
//! ([`HullSurface::without_missed`]).

use nalgebra::{Point3, Vector3};

use super::{NEW_SURFACE_DISTANCE, TABLE_MARGIN};
use crate::cloud::near_mask;
use crate::math::Pose;
use crate::occupancy::{OccupancyGrid, ReducedMap, VoxelState};
use crate::rig::DepthCameraSpec;
use crate::surface::PinholeIntrinsics;

/// Distance between samples on the hull (m).
const SPACING: f64 = 0.005;

/// Points nearer the table than this (m) do not make the hull.
const HULL_CLEARANCE: f64 = 0.015;

/// Incidence (degrees from the normal) up to which the camera returns fully, and beyond
/// which it returns nothing.
const GRAZING: [f64; 2] = [60.0, 80.0];

/// Points of the hull's input at most (a regular subsample beyond).
const MAX_HULL_POINTS: usize = 20_000;

/// Side (m) of the cells the points are counted in before the hull is taken.
const CELL: f64 = 0.01;

/// Points a cell must hold to take part in the hull: a stray return (a flying pixel at a
/// silhouette, a point the table filter left) would stretch the hull over space the
/// object does not fill.
const MIN_CELL_POINTS: usize = 3;

/// The centroids of the cells of side [`CELL`] holding at least [`MIN_CELL_POINTS`]
/// points and touching another such cell, in cell order. A dense cell with no dense
/// neighbour is a clump of strays, not surface: three table returns a view's pose error
/// lifted 1.6 cm, 10 cm off a mallet's handle, stretched its hull into 30 cm² of "unseen"
/// surface over bare table, which the hull's views kept looking at (docs/exploration.md,
/// "Scoring the unseen hull").
fn dense_cells(points: &[Point3<f64>]) -> Vec<Point3<f64>> {
    let key = |p: &Point3<f64>| {
        [
            (p.x / CELL).floor() as i64,
            (p.y / CELL).floor() as i64,
            (p.z / CELL).floor() as i64,
        ]
    };
    let mut cells: std::collections::BTreeMap<[i64; 3], (Vector3<f64>, usize)> =
        std::collections::BTreeMap::new();
    for p in points {
        let e = cells.entry(key(p)).or_insert((Vector3::zeros(), 0));
        e.0 += p.coords;
        e.1 += 1;
    }
    cells.retain(|_, (_, n)| *n >= MIN_CELL_POINTS);
    let touches = |k: &[i64; 3]| {
        (-1..=1).any(|dx| {
            (-1..=1).any(|dy| {
                (-1..=1).any(|dz| {
                    (dx, dy, dz) != (0, 0, 0)
                        && cells.contains_key(&[k[0] + dx, k[1] + dy, k[2] + dz])
                })
            })
        })
    };
    cells
        .iter()
        .filter(|(k, _)| touches(k))
        .map(|(_, (s, n))| Point3::from(s / *n as f64))
        .collect()
}

/// The unseen part of an object's convex hull, as area samples.
///
/// ```
/// use nalgebra::{Isometry3, Point3, Vector3};
/// use nbv_core::nbv::HullSurface;
/// use nbv_core::occupancy::{GridGeometry, OccupancyGrid, OccupancyParams, ReducedMap};
/// use nbv_core::rig::DepthCameraSpec;
/// // The top of a 10 cm cube standing on a table at z = 0, as a laser saw it.
/// let top: Vec<Point3<f64>> = (0..=50)
///     .flat_map(|i| (0..=50).map(move |j| Point3::new(-0.05 + 0.002 * i as f64, -0.05 + 0.002 * j as f64, 0.1)))
///     .collect();
/// let geometry = GridGeometry::from_dims(Point3::new(-0.5, -0.5, -0.1), 0.02, [50, 50, 20])?;
/// let grid = OccupancyGrid::new(geometry, OccupancyParams::default())?;
/// let hull = HullSurface::new(&top, Some(0.0), &grid).unwrap();
/// // Its four sides are unseen but for the table's last centimetre and the centimetre
/// // below the top the laser covers: about 4 × 0.1 × 0.08 m² (the corners' sparse
/// // cells left out).
/// assert!((hull.area() - 0.031).abs() < 0.002);
/// // The whole hull above the table's 1 cm: the top and the four sides.
/// assert!((hull.total_area() - 0.043).abs() < 0.002);
/// // A camera 0.35 m in front of one side sees that side, and none of the others.
/// let pose = Isometry3::face_towards(&Point3::new(0.4, 0.0, 0.05), &Point3::new(0.0, 0.0, 0.05), &Vector3::z());
/// let seen = hull.seen_from(&pose, &DepthCameraSpec::ipa1110(), &ReducedMap::from_grid(&grid), &|_| false);
/// assert!((seen - 0.008).abs() < 0.0005);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone)]
pub struct HullSurface {
    /// Position, outward unit normal and area (m²) of each sample.
    samples: Vec<(Point3<f64>, Vector3<f64>, f64)>,
    /// The hull's area (m²) above the table's margin, seen or not.
    total: f64,
}

impl HullSurface {
    /// Height (m) above the table an object must rise to, as the laser saw it, for its
    /// hull to stand for it: twice the 1.5 cm left out of the hull at the table. A flatter
    /// object (a spatula lying on the table) leaves a hull of a few millimetres with no
    /// unseen area, and is scored without it.
    pub const FLAT_HEIGHT: f64 = 2.0 * HULL_CLEARANCE;

    /// The unseen samples of the hull of `points` (world frame) and their footprint at
    /// `table` (its height, when known), read against `points` and `grid`. `None` when
    /// the points span no volume.
    pub fn new(points: &[Point3<f64>], table: Option<f64>, grid: &OccupancyGrid) -> Option<Self> {
        // Points near the table are left out of the hull (their footprint is its base):
        // with the views' pose error the table's own points reach a few millimetres above
        // it all round the object.
        let above: Vec<Point3<f64>> = match table {
            Some(t) => points
                .iter()
                .filter(|p| p.z > t + HULL_CLEARANCE)
                .copied()
                .collect(),
            None => points.to_vec(),
        };
        let dense = dense_cells(&above);
        let step = dense.len().div_ceil(MAX_HULL_POINTS).max(1);
        let mut input = Vec::new();
        for p in dense.iter().step_by(step) {
            input.push(parry3d::math::Vector::new(
                p.x as f32, p.y as f32, p.z as f32,
            ));
            if let Some(t) = table {
                input.push(parry3d::math::Vector::new(p.x as f32, p.y as f32, t as f32));
            }
        }
        if input.len() < 4 {
            return None;
        }
        let (vertices, triangles) = parry3d::transformation::convex_hull(&input);
        if triangles.is_empty() {
            return None;
        }
        let vertex = |i: u32| {
            let v = vertices[i as usize];
            Point3::new(f64::from(v.x), f64::from(v.y), f64::from(v.z))
        };
        let centre = vertices.iter().fold(Vector3::zeros(), |s, v| {
            s + Vector3::new(f64::from(v.x), f64::from(v.y), f64::from(v.z))
        }) / vertices.len() as f64;
        let geometry = grid.geometry();
        let floor = table.map_or(f64::NEG_INFINITY, |t| t + TABLE_MARGIN);
        let mut samples = Vec::new();
        let mut total = 0.0;
        for t in &triangles {
            let (a, b, c) = (vertex(t[0]), vertex(t[1]), vertex(t[2]));
            let cross = (b - a).cross(&(c - a));
            let area = 0.5 * cross.norm();
            if area <= 0.0 {
                continue;
            }
            let mut normal = cross.normalize();
            if normal.dot(&(a.coords - centre)) < 0.0 {
                normal = -normal;
            }
            let longest = (b - a).norm().max((c - a).norm()).max((c - b).norm());
            let k = (longest / SPACING).ceil().max(1.0) as usize;
            let count = k * (k + 1) / 2;
            let share = area / count as f64;
            for i in 0..k {
                for j in 0..k - i {
                    let (s, r) = (
                        (i as f64 + 1.0 / 3.0) / k as f64,
                        (j as f64 + 1.0 / 3.0) / k as f64,
                    );
                    let p = a + (b - a) * s + (c - a) * r;
                    if p.z < floor {
                        continue;
                    }
                    total += share;
                    // Seen through: empty at the sample and a voxel deeper (a 2 cm voxel
                    // the surface crosses is often empty in front of it).
                    let empty = |q: &Point3<f64>| {
                        geometry
                            .voxel_of(q)
                            .is_some_and(|v| grid.state(v) == Some(VoxelState::Empty))
                    };
                    let free = empty(&p) && empty(&(p - normal * geometry.resolution()));
                    if !free {
                        samples.push((p, normal, share));
                    }
                }
            }
        }
        // Seen: a point of the object lies within the report's coverage tolerance.
        let at: Vec<Point3<f64>> = samples.iter().map(|s| s.0).collect();
        let seen = near_mask(points, &at, NEW_SURFACE_DISTANCE);
        let samples = samples
            .into_iter()
            .zip(seen)
            .filter(|(_, seen)| !seen)
            .map(|(s, _)| s)
            .collect();
        Some(Self { samples, total })
    }

    /// The hull without the samples a view saw through: where a camera saw empty space
    /// (`free`, e.g. [`DepthImageFreeSpace::contains`]) 1 cm — the report's coverage
    /// tolerance — inside the hull, the object's surface lies farther in than that, and
    /// that part of the hull is no surface to look for (a bowl's opening, the gap under a
    /// jug's handle). Sharper than the grid's 2 cm voxels, which a rim or a handle fills.
    ///
    /// [`DepthImageFreeSpace::contains`]: crate::registration::DepthImageFreeSpace::contains
    pub fn without_seen_through(mut self, free: impl Fn(&Point3<f64>) -> bool) -> Self {
        self.samples
            .retain(|(p, n, _)| !free(&(p - n * NEW_SURFACE_DISTANCE)));
        self
    }

    /// The unseen area (m²) left on the hull.
    pub fn area(&self) -> f64 {
        self.samples.iter().map(|s| s.2).sum()
    }

    /// The hull's area (m²) above the table's margin, seen or not.
    pub fn total_area(&self) -> f64 {
        self.total
    }

    /// The unseen area (m²) a camera `spec` at `pose` (optical frame: z forward) would see,
    /// each sample weighted by the return at its incidence, hidden by the occupied voxels
    /// of `map` that are not the object's `own` (linear indices).
    pub fn seen_from(
        &self,
        pose: &Pose,
        spec: &DepthCameraSpec,
        map: &ReducedMap,
        own: &dyn Fn(usize) -> bool,
    ) -> f64 {
        let sight = Sight::new(pose, spec, map);
        self.samples
            .iter()
            .map(|(p, n, area)| area * sight.return_of(p, n, own))
            .sum()
    }

    /// The hull without the samples a taken view (at `poses`) was placed to see and did
    /// not: in its field of view and range, at an incidence of full return, and in plain
    /// sight — no occupied voxel of `map` on the way, the object's own included. Such a
    /// sample, still 1 cm from every point of the object, is hull off the object's surface
    /// (the hull's face over a lying mallet head's undercut, 1–2 cm above the table) or a
    /// surface the camera does not resolve; scored on, it drew view after view to the same
    /// side (paper-env1's mallet at seed 2: 11 cm² of it on one side, three views there,
    /// 90 % of its ceiling). The hull's counterpart of eq. (4)'s [`MissedVoxels`].
    ///
    /// [`MissedVoxels`]: super::MissedVoxels
    pub fn without_missed(
        mut self,
        poses: &[Pose],
        spec: &DepthCameraSpec,
        map: &ReducedMap,
    ) -> Self {
        let sights: Vec<Sight<'_>> = poses
            .iter()
            .map(|pose| Sight::new(pose, spec, map))
            .collect();
        self.samples
            .retain(|(p, n, _)| !sights.iter().any(|s| s.return_of(p, n, &|_| false) >= 1.0));
        self
    }
}

/// What a camera at one pose sees of a hull's samples.
struct Sight<'a> {
    eye: Point3<f64>,
    to_sensor: nalgebra::UnitQuaternion<f64>,
    camera: PinholeIntrinsics,
    range: [f64; 2],
    map: &'a ReducedMap,
    /// Occupied voxels this close to the sample (m) along the ray are its own surface's.
    near: f64,
}

impl<'a> Sight<'a> {
    fn new(pose: &Pose, spec: &DepthCameraSpec, map: &'a ReducedMap) -> Self {
        Self {
            eye: Point3::from(pose.translation.vector),
            to_sensor: pose.rotation.inverse(),
            camera: PinholeIntrinsics::of_camera(spec),
            range: spec.range,
            map,
            near: 1.5 * map.geometry().resolution(),
        }
    }

    /// The return (0–1) of the sample at `p` with outward normal `n`: 0 out of range, out
    /// of the field of view, beyond the grazing cut or behind an occupied voxel that is not
    /// `own`; else the grazing ramp at its incidence.
    fn return_of(&self, p: &Point3<f64>, n: &Vector3<f64>, own: &dyn Fn(usize) -> bool) -> f64 {
        let d = p - self.eye;
        let dist = d.norm();
        if dist < self.range[0] || dist > self.range[1] {
            return 0.0;
        }
        let cos = -n.dot(&d) / dist;
        if cos <= GRAZING[1].to_radians().cos() {
            return 0.0;
        }
        if self
            .camera
            .pixel_of(&Point3::from(self.to_sensor * d))
            .is_none()
        {
            return 0.0;
        }
        let hidden = self
            .map
            .geometry()
            .traverse_segment(&self.eye, p)
            .ok()
            .and_then(|t| {
                t.find_map_linear(|l, at| {
                    (at < dist - self.near
                        && self.map.state(l) == Some(VoxelState::Occupied)
                        && !own(l))
                    .then_some(())
                })
            })
            .is_some();
        if hidden {
            return 0.0;
        }
        let angle = cos.clamp(-1.0, 1.0).acos().to_degrees();
        ((GRAZING[1] - angle) / (GRAZING[1] - GRAZING[0])).clamp(0.0, 1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::occupancy::{GridGeometry, OccupancyParams};
    use nalgebra::Isometry3;

    /// A 10 cm cube on a table at z = 0: its top face as points (2 mm apart), a grid
    /// around it, a camera 0.35 m in front of its +x side.
    fn cube() -> (Vec<Point3<f64>>, OccupancyGrid, Pose) {
        let top = (0..=50)
            .flat_map(|i| {
                (0..=50).map(move |j| {
                    Point3::new(
                        -0.05 + 0.002 * f64::from(i),
                        -0.05 + 0.002 * f64::from(j),
                        0.1,
                    )
                })
            })
            .collect();
        let geometry =
            GridGeometry::from_dims(Point3::new(-0.5, -0.5, -0.1), 0.02, [50, 50, 20]).unwrap();
        let grid = OccupancyGrid::new(geometry, OccupancyParams::default()).unwrap();
        let pose = Isometry3::face_towards(
            &Point3::new(0.4, 0.0, 0.05),
            &Point3::new(0.0, 0.0, 0.05),
            &Vector3::z(),
        );
        (top, grid, pose)
    }

    fn with_log_odds(grid: &OccupancyGrid, at: &[Point3<f64>], value: f32) -> OccupancyGrid {
        let mut log_odds = grid.log_odds().to_vec();
        for p in at {
            let v = grid.geometry().voxel_of(p).unwrap();
            log_odds[grid.geometry().linear(v).unwrap()] = value;
        }
        OccupancyGrid::from_log_odds(*grid.geometry(), *grid.params(), log_odds).unwrap()
    }

    #[test]
    fn space_seen_through_one_centimetre_inside_the_hull_is_no_surface() {
        let (points, grid, _) = cube();
        let hull = HullSurface::new(&points, Some(0.0), &grid).unwrap();
        let full = hull.area();
        // A camera saw empty space in the upper half of the cube: the sides' upper halves
        // (tested 1 cm inside) go, their lower halves stay.
        let half = hull.clone().without_seen_through(|q| q.z > 0.05).area();
        assert!((0.3 * full..0.7 * full).contains(&half), "{full} → {half}");
        // Seen empty 1 cm inside a side only where the side lies 1 cm off the object: a
        // free space ending 5 mm inside every side keeps them (but for their edges, where
        // 1 cm inside one side is within 5 mm of the next).
        let shell = |q: &Point3<f64>| q.x.abs().max(q.y.abs()) > 0.045;
        let kept = hull.clone().without_seen_through(shell).area();
        assert!(kept > 0.95 * full, "{full} → {kept}");
        assert_eq!(hull.clone().without_seen_through(|_| true).area(), 0.0);
        assert_eq!(
            hull.total_area(),
            hull.without_seen_through(|_| true).total_area()
        );
    }

    #[test]
    fn a_clump_of_strays_off_the_object_does_not_stretch_the_hull() {
        let (points, grid, _) = cube();
        let hull = HullSurface::new(&points, Some(0.0), &grid).unwrap();
        // Three returns in one 1 cm cell, 10 cm off the cube's +x side and 2 cm above the
        // table: a dense cell, but alone.
        let mut strays = points.clone();
        strays.extend([0.151, 0.153, 0.155].map(|x| Point3::new(x, 0.005, 0.025)));
        let with = HullSurface::new(&strays, Some(0.0), &grid).unwrap();
        assert!(
            (with.total_area() - hull.total_area()).abs() < 1e-9,
            "{} → {}",
            hull.total_area(),
            with.total_area()
        );
        // Two such cells side by side are surface: the hull reaches out to them.
        strays.extend([0.161, 0.163, 0.165].map(|x| Point3::new(x, 0.005, 0.025)));
        let reached = HullSurface::new(&strays, Some(0.0), &grid).unwrap();
        assert!(reached.total_area() > hull.total_area() + 0.005);
    }

    #[test]
    fn a_side_a_view_was_placed_to_see_and_did_not_is_no_longer_scored() {
        let (points, grid, pose) = cube();
        let (spec, map) = (DepthCameraSpec::ipa1110(), ReducedMap::from_grid(&grid));
        let hull = HullSurface::new(&points, Some(0.0), &grid).unwrap();
        let before = hull.area();
        // The camera in front of the +x side took a view, and no point came of the side:
        // its unseen 10 × 8 cm (between the table's margin and 1 cm under the top's
        // points) go, and the view would see nothing now.
        let after = hull.clone().without_missed(&[pose], &spec, &map);
        assert!(
            (before - after.area() - 0.008).abs() < 0.0005,
            "{before} → {}",
            after.area()
        );
        assert_eq!(after.seen_from(&pose, &spec, &map, &|_| false), 0.0);
        assert_eq!(after.total_area(), hull.total_area());
        // No view taken: nothing goes.
        assert_eq!(hull.clone().without_missed(&[], &spec, &map).area(), before);
        // A wall between the camera and the side: the view could not see it, it stays.
        let wall: Vec<Point3<f64>> = (-4..=4)
            .flat_map(|j| {
                (0..=6).map(move |k| Point3::new(0.21, 0.02 * f64::from(j), 0.02 * f64::from(k)))
            })
            .collect();
        let blocked = ReducedMap::from_grid(&with_log_odds(&grid, &wall, 2.0));
        assert_eq!(hull.without_missed(&[pose], &spec, &blocked).area(), before);
    }

    #[test]
    fn a_side_seen_by_a_view_is_no_longer_unseen() {
        let (mut points, grid, _) = cube();
        let before = HullSurface::new(&points, Some(0.0), &grid).unwrap().area();
        // The +x side seen: points on it, 2 mm apart.
        for j in 0..=50 {
            for k in 0..=45 {
                points.push(Point3::new(
                    0.05,
                    -0.05 + 0.002 * f64::from(j),
                    0.01 + 0.002 * f64::from(k),
                ));
            }
        }
        let after = HullSurface::new(&points, Some(0.0), &grid).unwrap().area();
        assert!((before - after - 0.009).abs() < 0.001, "{before} → {after}");
    }

    #[test]
    fn space_seen_through_is_no_surface() {
        // The sensors saw through the hull's +x side and a voxel behind it: a concave
        // object (a bowl's opening), not a surface there.
        let (points, grid, _) = cube();
        let mut through = Vec::new();
        for j in 0..5 {
            for k in 0..5 {
                for d in [0.05, 0.03] {
                    through.push(Point3::new(
                        d,
                        -0.05 + 0.02 * f64::from(j) + 0.01,
                        0.02 * f64::from(k) + 0.01,
                    ));
                }
            }
        }
        let carved = with_log_odds(&grid, &through, -2.0);
        let full = HullSurface::new(&points, Some(0.0), &grid).unwrap().area();
        let area = HullSurface::new(&points, Some(0.0), &carved)
            .unwrap()
            .area();
        // The side, and the neighbouring sides' strips in the same carved voxels.
        assert!((0.008..0.0105).contains(&(full - area)), "{full} → {area}");
    }

    #[test]
    fn another_objects_voxels_hide_what_lies_behind_them_and_its_own_do_not() {
        let (points, grid, pose) = cube();
        let hull = HullSurface::new(&points, Some(0.0), &grid).unwrap();
        let spec = DepthCameraSpec::ipa1110();
        let clear = hull.seen_from(&pose, &spec, &ReducedMap::from_grid(&grid), &|_| false);
        assert!((clear - 0.008).abs() < 0.0005, "{clear}");
        // A wall of occupied voxels at x = 0.2 between the camera and the side.
        let wall: Vec<Point3<f64>> = (0..15)
            .flat_map(|j| {
                (0..10).map(move |k| {
                    Point3::new(
                        0.21,
                        -0.15 + 0.02 * f64::from(j),
                        -0.05 + 0.02 * f64::from(k),
                    )
                })
            })
            .collect();
        let walled = ReducedMap::from_grid(&with_log_odds(&grid, &wall, 3.0));
        assert_eq!(hull.seen_from(&pose, &spec, &walled, &|_| false), 0.0);
        // The same voxels taken as the object's own (its region) hide nothing.
        let own = hull.seen_from(&pose, &spec, &walled, &|_| true);
        assert!((own - clear).abs() < 1e-12);
    }

    #[test]
    fn out_of_range_and_behind_see_nothing() {
        let (points, grid, _) = cube();
        let hull = HullSurface::new(&points, Some(0.0), &grid).unwrap();
        let spec = DepthCameraSpec::ipa1110();
        let map = ReducedMap::from_grid(&grid);
        let far = Isometry3::face_towards(
            &Point3::new(1.0, 0.0, 0.05),
            &Point3::new(0.0, 0.0, 0.05),
            &Vector3::z(),
        );
        assert_eq!(hull.seen_from(&far, &spec, &map, &|_| false), 0.0);
        let away = Isometry3::face_towards(
            &Point3::new(0.4, 0.0, 0.05),
            &Point3::new(1.0, 0.0, 0.05),
            &Vector3::z(),
        );
        assert_eq!(hull.seen_from(&away, &spec, &map, &|_| false), 0.0);
    }
}
