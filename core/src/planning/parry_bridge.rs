//! The boundary with parry3d (f32, glam math types): every conversion from the project's
//! nalgebra f64 types and every parry query the planner makes goes through this module.
//!
//! URDF cylinders run along their local z axis, parry's along y: [`link_shape`] returns the
//! extra local rotation (x by +90°, which maps y onto z) to compose with the URDF origin.

use nalgebra::{Isometry3, UnitQuaternion, Vector3};
use parry3d::bounding_volume::Aabb;
use parry3d::math::{Pose as PPose, Rotation as PRot, Vector as PVec};
use parry3d::query;
use parry3d::shape::SharedShape;

use super::ObstacleShape;
use crate::kinematics::Shape;
use crate::math::Pose;

/// A parry pose (f32).
pub(crate) type ParryPose = PPose;

/// A parry shape.
pub(crate) type ParryShape = SharedShape;

/// An axis-aligned box in f64: `(min, max)`.
pub(crate) type Bounds = ([f64; 3], [f64; 3]);

/// The f32 parry pose of a nalgebra pose.
pub(crate) fn to_parry(pose: &Pose) -> ParryPose {
    let t = pose.translation.vector;
    let q = pose.rotation.quaternion();
    PPose::from_parts(
        PVec::new(t.x as f32, t.y as f32, t.z as f32),
        PRot::from_xyzw(q.i as f32, q.j as f32, q.k as f32, q.w as f32).normalize(),
    )
}

/// A parry shape for a URDF primitive grown by `padding` metres in every direction (its
/// Minkowski sum with a ball: rounded boxes and cylinders), and the local pose to put after
/// the URDF origin (`T_origin_parryshape`). `Err` names the unsupported kind.
pub(crate) fn link_shape(shape: &Shape, padding: f64) -> Result<(ParryShape, Pose), &'static str> {
    let id = Pose::identity();
    let positive = |v: f64| v.is_finite() && v > 0.0;
    let pad = padding as f32;
    let rounded = padding > 0.0;
    match *shape {
        Shape::Box { size } if size.iter().all(|&s| positive(s)) => {
            let [hx, hy, hz] = size.map(|s| (0.5 * s) as f32);
            let shape = if rounded {
                SharedShape::round_cuboid(hx, hy, hz, pad)
            } else {
                SharedShape::cuboid(hx, hy, hz)
            };
            Ok((shape, id))
        }
        Shape::Cylinder { radius, length } if positive(radius) && positive(length) => {
            let (h, r) = ((0.5 * length) as f32, radius as f32);
            let shape = if rounded {
                SharedShape::round_cylinder(h, r, pad)
            } else {
                SharedShape::cylinder(h, r)
            };
            Ok((
                shape,
                Isometry3::from_parts(
                    Default::default(),
                    UnitQuaternion::from_axis_angle(
                        &Vector3::x_axis(),
                        std::f64::consts::FRAC_PI_2,
                    ),
                ),
            ))
        }
        Shape::Capsule { radius, length } if positive(radius) && length >= 0.0 => Ok((
            SharedShape::capsule_z((0.5 * length) as f32, (radius + padding) as f32),
            id,
        )),
        Shape::Sphere { radius } if positive(radius) => {
            Ok((SharedShape::ball((radius + padding) as f32), id))
        }
        Shape::Mesh { .. } => Err("mesh (not loaded by the planner)"),
        _ => Err("non-positive or non-finite dimension"),
    }
}

/// Radius of a sphere centred on the shape's origin enclosing a URDF primitive.
pub(crate) fn bounding_radius(shape: &Shape) -> f64 {
    match *shape {
        Shape::Box { size } => 0.5 * Vector3::from(size).norm(),
        Shape::Cylinder { radius, length } => radius.hypot(0.5 * length),
        Shape::Capsule { radius, length } => radius + 0.5 * length,
        Shape::Sphere { radius } => radius,
        Shape::Mesh { .. } => f64::INFINITY,
    }
}

/// A parry shape for an obstacle. `Err` says what is wrong.
pub(crate) fn obstacle_shape(shape: &ObstacleShape) -> Result<ParryShape, String> {
    match shape {
        ObstacleShape::Cuboid { half_extents: h } => {
            if h.iter().all(|v| v.is_finite() && *v > 0.0) {
                Ok(SharedShape::cuboid(h[0] as f32, h[1] as f32, h[2] as f32))
            } else {
                Err(format!("half extents {h:?} must be finite and > 0"))
            }
        }
        ObstacleShape::TriMesh(mesh) => {
            if mesh.triangles.is_empty() {
                return Err("mesh has no triangle".into());
            }
            let n = mesh.vertices.len();
            if mesh.triangles.iter().flatten().any(|&i| i as usize >= n) {
                return Err("a triangle refers to a missing vertex".into());
            }
            if mesh
                .vertices
                .iter()
                .any(|p| !p.iter().all(|v| v.is_finite()))
            {
                return Err("a vertex is not finite".into());
            }
            let vertices = mesh
                .vertices
                .iter()
                .map(|p| PVec::new(p.x as f32, p.y as f32, p.z as f32))
                .collect();
            SharedShape::trimesh(vertices, mesh.triangles.clone()).map_err(|e| e.to_string())
        }
    }
}

/// A cube of half edge `half` (a voxel).
pub(crate) fn cube(half: f64) -> ParryShape {
    SharedShape::cuboid(half as f32, half as f32, half as f32)
}

/// A translation-only parry pose.
pub(crate) fn translation(p: [f64; 3]) -> ParryPose {
    PPose::from_translation(PVec::new(p[0] as f32, p[1] as f32, p[2] as f32))
}

/// Whether two posed shapes intersect (touching counts). A pair parry cannot test is
/// reported as intersecting (conservative).
pub(crate) fn intersects(p1: &ParryPose, s1: &ParryShape, p2: &ParryPose, s2: &ParryShape) -> bool {
    query::intersection_test(p1, s1.as_ref(), p2, s2.as_ref())
        .map(|r| r.intersecting)
        .unwrap_or(true)
}

/// The world AABB of a posed shape in f64, widened by `margin` on every side.
pub(crate) fn world_bounds(pose: &ParryPose, shape: &ParryShape, margin: f64) -> Bounds {
    let aabb: Aabb = shape.compute_aabb(pose);
    (
        [aabb.mins.x, aabb.mins.y, aabb.mins.z].map(|v| f64::from(v) - margin),
        [aabb.maxs.x, aabb.maxs.y, aabb.maxs.z].map(|v| f64::from(v) + margin),
    )
}

/// Whether two boxes overlap (closed).
pub(crate) fn bounds_overlap(a: &Bounds, b: &Bounds) -> bool {
    (0..3).all(|k| a.0[k] <= b.1[k] && b.0[k] <= a.1[k])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::pose_from_xyz_rpy;

    #[test]
    fn cylinder_axis_is_urdf_z() {
        let (shape, local) = link_shape(
            &Shape::Cylinder {
                radius: 0.1,
                length: 1.0,
            },
            0.0,
        )
        .unwrap();
        let b = world_bounds(&to_parry(&local), &shape, 0.0);
        assert!((b.0[2] + 0.5).abs() < 1e-6 && (b.1[2] - 0.5).abs() < 1e-6);
        assert!((b.1[0] - 0.1).abs() < 1e-6 && (b.1[1] - 0.1).abs() < 1e-6);
        let (capsule, local) = link_shape(
            &Shape::Capsule {
                radius: 0.1,
                length: 1.0,
            },
            0.0,
        )
        .unwrap();
        let b = world_bounds(&to_parry(&local), &capsule, 0.0);
        assert!((b.1[2] - 0.6).abs() < 1e-6);
        let mesh = Shape::Mesh {
            filename: "x.stl".into(),
            scale: [1.0; 3],
        };
        assert!(link_shape(&mesh, 0.0).is_err());
        assert!(
            link_shape(
                &Shape::Box {
                    size: [0.0, 1.0, 1.0]
                },
                0.0
            )
            .is_err()
        );
    }

    #[test]
    fn padding_grows_every_primitive() {
        let pad = 0.005;
        for (shape, half) in [
            (
                Shape::Box {
                    size: [0.2, 0.4, 0.6],
                },
                [0.1, 0.2, 0.3],
            ),
            (
                Shape::Cylinder {
                    radius: 0.1,
                    length: 0.6,
                },
                [0.1, 0.1, 0.3],
            ),
            (
                Shape::Capsule {
                    radius: 0.1,
                    length: 0.4,
                },
                [0.1, 0.1, 0.3],
            ),
            (Shape::Sphere { radius: 0.1 }, [0.1, 0.1, 0.1]),
        ] {
            let (s, local) = link_shape(&shape, pad).unwrap();
            let b = world_bounds(&to_parry(&local), &s, 0.0);
            for (a, h) in half.iter().enumerate() {
                assert!((b.1[a] - (h + pad)).abs() < 1e-6, "{shape:?} {b:?}");
                assert!((b.0[a] + (h + pad)).abs() < 1e-6, "{shape:?} {b:?}");
            }
            // A voxel 4 mm from the face touches the padded shape only.
            let (plain, _) = link_shape(&shape, 0.0).unwrap();
            let probe = translation([half[0] + 0.004 + 0.01, 0.0, 0.0]);
            let cube = cube(0.01);
            assert!(intersects(&to_parry(&local), &s, &probe, &cube));
            assert!(!intersects(&to_parry(&local), &plain, &probe, &cube));
        }
    }

    #[test]
    fn poses_convert_and_shapes_intersect() {
        let pose = pose_from_xyz_rpy([0.3, -0.2, 1.1], [0.4, -0.3, 2.0]);
        let p = to_parry(&pose);
        let v = nalgebra::Vector3::new(0.1, 0.2, -0.3);
        let expect = pose * nalgebra::Point3::from(v);
        let got = p.transform_point(PVec::new(0.1, 0.2, -0.3));
        assert!((f64::from(got.x) - expect.x).abs() < 1e-6);
        assert!((f64::from(got.y) - expect.y).abs() < 1e-6);
        assert!((f64::from(got.z) - expect.z).abs() < 1e-6);
        let a = cube(0.5);
        assert!(intersects(
            &translation([0.0; 3]),
            &a,
            &translation([0.99, 0.0, 0.0]),
            &a
        ));
        assert!(!intersects(
            &translation([0.0; 3]),
            &a,
            &translation([1.01, 0.0, 0.0]),
            &a
        ));
        let bad = obstacle_shape(&ObstacleShape::Cuboid {
            half_extents: [1.0, f64::NAN, 1.0],
        });
        assert!(bad.is_err());
        let empty = obstacle_shape(&ObstacleShape::TriMesh(crate::mesh::TriMesh::default()));
        assert!(empty.is_err());
    }
}
