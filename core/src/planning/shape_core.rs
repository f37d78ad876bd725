//! [`ShapeCore`]: a link's parry shape as a core — a point, a segment, a box or a cylinder —
//! grown by a radius, with the exact distance from a point to the core. It settles most of
//! the voxel tests of [`VoxelObstacles`](super::voxel_obstacles::VoxelObstacles) without
//! GJK: a voxel whose centre is farther from the shape than its half diagonal cannot touch
//! it, one whose centre is nearer than its half edge must.
//!
//! The bounds are exact geometry. parry 0.31's GJK is not, on the padded (rounded) links:
//! it reports contact with voxels up to ~8 mm beyond the shape (a padded box and a voxel
//! 4.6 mm apart: intersecting; its `distance` is off by 0.5–2.5 mm too), so before these
//! bounds the planner saw phantom contacts around every link. GJK now decides only in the
//! shell between the two bounds.

use nalgebra::{Matrix3, Point3, Quaternion, UnitQuaternion, Vector3};

use super::parry_bridge::{Bounds, ParryPose, ParryShape};

/// How far inside a bound a test must be to be settled by it (m): well beyond the
/// rounding of parry's f32 poses and shapes.
const TOLERANCE: f64 = 1e-4;

/// The inner geometry of a shape, in the shape's local frame.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Core {
    /// The origin (a ball).
    Point,
    /// The segment between two points (a capsule).
    Segment(Point3<f64>, Point3<f64>),
    /// The box of these half extents about the origin (a cuboid, rounded or not).
    Box(Vector3<f64>),
    /// The solid cylinder along y of this half height and radius (rounded or not).
    Cylinder { half_height: f64, radius: f64 },
}

/// A posed shape as the points within `radius` of its core.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ShapeCore {
    core: Core,
    radius: f64,
    /// World → local rotation and the shape's world origin.
    to_local: Matrix3<f64>,
    origin: Vector3<f64>,
}

impl ShapeCore {
    /// The core of `shape` at the origin; `None` for a kind it does not know (a mesh).
    pub fn of(shape: &ParryShape) -> Option<Self> {
        let v =
            |p: parry3d::math::Vector| Vector3::new(f64::from(p.x), f64::from(p.y), f64::from(p.z));
        let (core, radius) = if let Some(b) = shape.as_ball() {
            (Core::Point, f64::from(b.radius))
        } else if let Some(c) = shape.as_capsule() {
            let (a, b) = (v(c.segment.a), v(c.segment.b));
            (Core::Segment(a.into(), b.into()), f64::from(c.radius))
        } else if let Some(c) = shape.as_cuboid() {
            (Core::Box(v(c.half_extents)), 0.0)
        } else if let Some(c) = shape.as_round_cuboid() {
            (
                Core::Box(v(c.inner_shape.half_extents)),
                f64::from(c.border_radius),
            )
        } else if let Some(c) = shape.as_cylinder() {
            (
                Core::Cylinder {
                    half_height: f64::from(c.half_height),
                    radius: f64::from(c.radius),
                },
                0.0,
            )
        } else if let Some(c) = shape.as_round_cylinder() {
            (
                Core::Cylinder {
                    half_height: f64::from(c.inner_shape.half_height),
                    radius: f64::from(c.inner_shape.radius),
                },
                f64::from(c.border_radius),
            )
        } else {
            return None;
        };
        Some(Self {
            core,
            radius,
            to_local: Matrix3::identity(),
            origin: Vector3::zeros(),
        })
    }

    /// The same core placed at `pose` (the shape's pose in the world).
    pub fn posed(self, pose: &ParryPose) -> Self {
        let q = pose.rotation;
        let rotation = UnitQuaternion::from_quaternion(Quaternion::new(
            f64::from(q.w),
            f64::from(q.x),
            f64::from(q.y),
            f64::from(q.z),
        ));
        let t = pose.translation;
        Self {
            to_local: rotation.to_rotation_matrix().into_inner().transpose(),
            origin: Vector3::new(f64::from(t.x), f64::from(t.y), f64::from(t.z)),
            ..self
        }
    }

    /// The world axis-aligned box of the shape (exact: the core's box grown by the
    /// radius), widened by `margin` on every side.
    pub fn bounds(&self, margin: f64) -> Bounds {
        let to_world = self.to_local.transpose();
        let (centre, half) = match self.core {
            Core::Point => (Vector3::zeros(), Vector3::zeros()),
            Core::Segment(a, b) => {
                let (a, b) = (to_world * a.coords, to_world * b.coords);
                ((a + b) * 0.5, (a - b).abs() * 0.5)
            }
            Core::Box(half) => (Vector3::zeros(), to_world.abs() * half),
            Core::Cylinder {
                half_height,
                radius,
            } => {
                // The end discs' extent across world axis i: radius · √(1 − axis_i²).
                let axis = to_world.column(1).into_owned();
                let rim = axis.map(|a| radius * (1.0 - a * a).max(0.0).sqrt());
                (Vector3::zeros(), axis.abs() * half_height + rim)
            }
        };
        let grow = Vector3::repeat(self.radius + margin);
        let (lo, hi) = (
            self.origin + centre - half - grow,
            self.origin + centre + half + grow,
        );
        ([lo.x, lo.y, lo.z], [hi.x, hi.y, hi.z])
    }

    /// The distance from the world point `p` to the shape (negative inside, down to minus
    /// the radius).
    pub fn distance(&self, p: &Point3<f64>) -> f64 {
        self.core_distance(p) - self.radius
    }

    /// The distance from the world point `p` to the core.
    fn core_distance(&self, p: &Point3<f64>) -> f64 {
        let local = self.to_local * (p.coords - self.origin);
        match self.core {
            Core::Point => local.norm(),
            Core::Segment(a, b) => {
                let ab = b - a;
                let t = (local - a.coords).dot(&ab) / ab.norm_squared().max(f64::MIN_POSITIVE);
                (local - (a.coords + ab * t.clamp(0.0, 1.0))).norm()
            }
            Core::Box(half) => local.abs().zip_map(&half, |l, h| (l - h).max(0.0)).norm(),
            Core::Cylinder {
                half_height,
                radius,
            } => {
                let radial = (local.x.hypot(local.z) - radius).max(0.0);
                let axial = (local.y.abs() - half_height).max(0.0);
                radial.hypot(axial)
            }
        }
    }

    /// Whether the axis-aligned cube of half edge `half` centred at `centre` touches the
    /// shape, when the bounds settle it: `Some(false)` when the centre is farther from the
    /// shape than the cube's half diagonal, `Some(true)` when the ball inscribed in the
    /// cube reaches into it, `None` in the shell between (each with [`TOLERANCE`] to
    /// spare).
    pub fn touches_cube(&self, centre: &Point3<f64>, half: f64) -> Option<bool> {
        let outside = self.distance(centre);
        if outside > half * 3f64.sqrt() + TOLERANCE {
            Some(false)
        } else if outside < half - TOLERANCE {
            Some(true)
        } else {
            None
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::parry_bridge::{link_shape, to_parry, world_bounds};
    use super::*;
    use crate::kinematics::Shape;
    use crate::math::Pose;
    use nalgebra::Translation3;
    use proptest::prelude::*;

    fn shapes() -> Vec<Shape> {
        vec![
            Shape::Box {
                size: [0.3, 0.1, 0.2],
            },
            Shape::Cylinder {
                radius: 0.06,
                length: 0.4,
            },
            Shape::Capsule {
                radius: 0.05,
                length: 0.3,
            },
            Shape::Sphere { radius: 0.08 },
        ]
    }

    /// A posed link shape of kind `kind` (box, cylinder, capsule, sphere) padded by
    /// `padding`, and the unpadded one at the same pose.
    fn posed(
        kind: usize,
        padding: f64,
        rpy: [f64; 3],
        at: [f64; 3],
    ) -> (ParryShape, ParryShape, ParryPose) {
        let (shape, fix) = link_shape(&shapes()[kind], padding).unwrap();
        let (inner, _) = link_shape(&shapes()[kind], 0.0).unwrap();
        let pose = to_parry(
            &(Pose::from_parts(
                Translation3::new(at[0], at[1], at[2]),
                UnitQuaternion::from_euler_angles(rpy[0], rpy[1], rpy[2]),
            ) * fix),
        );
        (shape, inner, pose)
    }

    proptest! {
        /// The distance to the core, less the rounding, is parry's exact point distance to
        /// the unpadded primitive (analytic for these four; parry's queries on the padded,
        /// rounded shapes go through GJK, which is off by millimetres on them).
        #[test]
        fn the_core_distance_is_the_primitives_point_distance(
            kind in 0usize..4,
            rpy in prop::array::uniform3(-3.2f64..3.2),
            at in prop::array::uniform3(-0.1f64..0.1),
            point in prop::array::uniform3(-0.4f64..0.4),
        ) {
            let (_, inner, pose) = posed(kind, 0.0, rpy, at);
            let core = ShapeCore::of(&inner).unwrap().posed(&pose);
            let p = Point3::from(point);
            let exact = f64::from(inner.distance_to_point(
                &pose,
                parry3d::math::Vector::new(p.x as f32, p.y as f32, p.z as f32),
                true,
            ));
            // A capsule's and a ball's radius is their rounding about the core.
            let ours = (core.core_distance(&p) - core.radius).max(0.0);
            prop_assert!((ours - exact).abs() < 1e-5, "ours {} exact {}", ours, exact);
        }

        /// The box is parry's own bounding box of the shape (to f32 rounding).
        #[test]
        fn the_bounds_are_parrys_bounding_box(
            kind in 0usize..4,
            padded in any::<bool>(),
            rpy in prop::array::uniform3(-3.2f64..3.2),
            at in prop::array::uniform3(-0.5f64..0.5),
        ) {
            let (shape, _, pose) = posed(kind, if padded { 0.02 } else { 0.0 }, rpy, at);
            let ours = ShapeCore::of(&shape).unwrap().posed(&pose).bounds(0.0);
            let parrys = world_bounds(&pose, &shape, 0.0);
            for a in 0..3 {
                prop_assert!((ours.0[a] - parrys.0[a]).abs() < 1e-5, "{:?} {:?}", ours, parrys);
                prop_assert!((ours.1[a] - parrys.1[a]).abs() < 1e-5, "{:?} {:?}", ours, parrys);
            }
        }

        /// What a bound settles is what a dense sampling of the cube says: a cube said to
        /// touch has a sample within the shape (to the sampling's spacing), a cube said
        /// apart has none.
        #[test]
        fn settled_cubes_agree_with_a_sampling_of_the_cube(
            kind in 0usize..4,
            padded in any::<bool>(),
            rpy in prop::array::uniform3(-3.2f64..3.2),
            at in prop::array::uniform3(-0.1f64..0.1),
            voxel in prop::array::uniform3(-0.35f64..0.35),
            half in 0.002f64..0.02,
        ) {
            let padding = if padded { 0.02 } else { 0.0 };
            let (shape, _, pose) = posed(kind, padding, rpy, at);
            let core = ShapeCore::of(&shape).unwrap().posed(&pose);
            let centre = Point3::from(voxel);
            const N: i32 = 8;
            let nearest = (0..=N)
                .flat_map(|i| (0..=N).flat_map(move |j| (0..=N).map(move |k| [i, j, k])))
                .map(|ijk| {
                    let offset = Vector3::from(ijk.map(|c| half * (2.0 * f64::from(c) / f64::from(N) - 1.0)));
                    core.core_distance(&(centre + offset)) - core.radius
                })
                .fold(f64::INFINITY, f64::min);
            let spacing = 2.0 * half / f64::from(N) * 3f64.sqrt() / 2.0;
            match core.touches_cube(&centre, half) {
                Some(true) => prop_assert!(nearest <= spacing, "{nearest} > {spacing}"),
                Some(false) => prop_assert!(nearest > 0.0, "{nearest}"),
                None => {}
            }
        }
    }

    /// parry 0.31's GJK reports a padded box touching a voxel 4.6 mm away (its `distance`
    /// says so too); the bounds settle that voxel as apart. This is why the planner asks
    /// GJK only in the thin shell the bounds leave open.
    #[test]
    fn the_bounds_settle_a_voxel_gjk_gets_wrong() {
        let shape = ParryShape::round_cuboid(0.08, 0.05, 0.05, 0.005);
        let pose = ParryPose::from_parts(
            parry3d::math::Vector::new(0.388_450_6, 0.128_415_67, 0.789_666_7),
            parry3d::math::Rotation::from_xyzw(
                0.564_862_55,
                0.806_707_26,
                0.142_244_26,
                0.099_600_5,
            )
            .normalize(),
        );
        let voxel = [0.47, 0.05, 0.74];
        let core = ShapeCore::of(&shape).unwrap().posed(&pose);
        assert_eq!(core.touches_cube(&Point3::from(voxel), 0.01), Some(false));
        let gap = core.core_distance(&Point3::from(voxel)) - core.radius - 0.01 * 3f64.sqrt();
        assert!(gap > 0.0, "{gap}");
    }

    #[test]
    fn a_cube_at_the_core_touches_and_one_far_off_does_not() {
        for shape in shapes() {
            let (shape, fix) = link_shape(&shape, 0.01).unwrap();
            let pose = to_parry(&fix);
            let core = ShapeCore::of(&shape).unwrap().posed(&pose);
            assert_eq!(core.touches_cube(&Point3::origin(), 0.005), Some(true));
            assert_eq!(
                core.touches_cube(&Point3::new(1.0, 0.0, 0.0), 0.005),
                Some(false)
            );
        }
    }

    #[test]
    fn the_cylinders_distance_is_radial_beside_it_and_axial_beyond_its_end() {
        let (shape, fix) = link_shape(
            &Shape::Cylinder {
                radius: 0.1,
                length: 0.4,
            },
            0.0,
        )
        .unwrap();
        let core = ShapeCore::of(&shape).unwrap().posed(&to_parry(&fix));
        // URDF cylinders run along z: 0.3 m beside the axis, 0.1 m past the end cap.
        let beside = core.core_distance(&Point3::new(0.3, 0.0, 0.0));
        let beyond = core.core_distance(&Point3::new(0.0, 0.0, 0.3));
        assert!((beside - 0.2).abs() < 1e-6, "{beside}");
        assert!((beyond - 0.1).abs() < 1e-6, "{beyond}");
    }
}
