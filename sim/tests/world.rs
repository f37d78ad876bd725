//! The twin world on a hand-built scene: poses of the Rapier colliders, contacts with the
//! table and obstacles, and ray casts.

use nalgebra::{Isometry3, Point3, Vector3};
use nbv_core::kinematics::{Joints, Robot, Shape};
use nbv_core::mesh::TriMesh;
use nbv_core::rig::TruthLabel;
use nbv_sim::world::{Contacted, StaticBody, StaticShape, TwinWorld};
use std::path::PathBuf;

fn urdf() -> PathBuf {
    PathBuf::from(nbv_core::kinematics::COMAU_URDF)
}

fn deg(q: [f64; 6]) -> Joints {
    Joints::from_iterator(q.iter().map(|d| d.to_radians()))
}

fn home() -> Joints {
    deg([0.0, 0.0, -90.0, 0.0, 90.0, 0.0])
}

fn world() -> TwinWorld {
    let robot = Robot::from_urdf_file(urdf()).unwrap();
    let statics = vec![
        StaticBody {
            name: "table".into(),
            label: TruthLabel::Table,
            shape: StaticShape::Cuboid {
                half_extents: [0.5, 0.7, 0.125],
                pose: Isometry3::translation(0.85, 0.0, 0.125),
            },
        },
        StaticBody {
            name: "panel".into(),
            label: TruthLabel::Obstacle(0),
            shape: StaticShape::Cuboid {
                half_extents: [0.02, 0.5, 0.2],
                pose: Isometry3::translation(1.27, 0.0, 0.45),
            },
        },
        StaticBody {
            name: "cube".into(),
            label: TruthLabel::Object(0),
            shape: StaticShape::Mesh(
                TriMesh::cuboid([0.05, 0.05, 0.05])
                    .transformed(&Isometry3::translation(0.8, 0.3, 0.30)),
            ),
        },
    ];
    TwinWorld::new(robot, &urdf(), Isometry3::identity(), statics, home()).unwrap()
}

#[test]
fn every_urdf_collision_primitive_becomes_a_collider() {
    let w = world();
    let n = w.robot().collision_geometry().len();
    assert!(n >= 8, "only {n} collision primitives");
    assert!(w.contacts().is_empty(), "home touches: {:?}", w.contacts());
}

#[test]
fn home_is_free_and_a_pose_into_the_table_collides_with_the_table() {
    let mut w = world();
    assert!(!w.in_collision());
    // Lower the wrist into the table top by tilting the upper arm forward.
    let mut found = None;
    for j2 in (0..=80).step_by(5) {
        let q = deg([0.0, j2 as f64, -90.0, 0.0, 90.0, 0.0]);
        let flange = w.robot().fk(&q, "tool0").unwrap().translation.vector;
        if flange.z < 0.15 && flange.x > 0.5 {
            found = Some(q);
            break;
        }
    }
    let q = found.expect("a configuration with the flange below the table top");
    let contacts = w.contacts_at(q);
    assert!(
        contacts.iter().any(|c| matches!(
            &c.with,
            Contacted::Static {
                label: TruthLabel::Table,
                ..
            }
        )),
        "{contacts:?}"
    );
    w.set_configuration(home());
    assert!(!w.in_collision());
}

#[test]
fn reaching_into_the_back_panel_is_reported() {
    let mut w = world();
    // Arm stretched forward at panel height: the flange beyond the panel's front face.
    let q = (0..=90)
        .step_by(5)
        .flat_map(|j2| {
            (0..=34).map(move |k| deg([0.0, j2 as f64, -170.0 + 5.0 * k as f64, 0.0, 0.0, 0.0]))
        })
        .find(|q| {
            let t = w.robot().fk(q, "tool0").unwrap().translation.vector;
            t.x > 1.27 && t.z > 0.35 && t.z < 0.6
        })
        .expect("a configuration reaching the panel");
    let contacts = w.contacts_at(q);
    assert!(
        contacts
            .iter()
            .any(|c| matches!(&c.with, Contacted::Static { name, .. } if name == "panel")),
        "{contacts:?}"
    );
}

#[test]
fn folding_the_wrist_onto_the_upper_arm_is_a_self_collision() {
    let mut w = world();
    // Forearm folded down against the upper arm.
    let q = deg([0.0, 0.0, -170.0, 0.0, -120.0, 0.0]);
    let contacts = w.contacts_at(q);
    assert!(
        contacts
            .iter()
            .any(|c| matches!(c.with, Contacted::Link(_))),
        "{contacts:?}"
    );
}

#[test]
fn rays_hit_table_object_and_robot_with_labels_and_distances() {
    let w = world();
    let caster = w.ray_caster();
    let down = -Vector3::z();
    let table = caster
        .cast(&Point3::new(0.6, -0.4, 1.0), &down, 5.0, None)
        .unwrap();
    assert_eq!(table.label, TruthLabel::Table);
    assert!((table.distance - 0.75).abs() < 1e-5, "{}", table.distance);
    assert!((table.normal - Vector3::z()).norm() < 1e-5);
    let cube = caster
        .cast(&Point3::new(0.8, 0.3, 1.0), &down, 5.0, None)
        .unwrap();
    assert_eq!(cube.label, TruthLabel::Object(0));
    assert!((cube.point.z - 0.35).abs() < 1e-5);
    // Beyond max range: nothing.
    assert!(
        caster
            .cast(&Point3::new(0.6, -0.4, 1.0), &down, 0.5, None)
            .is_none()
    );
    // A ray across the upper arm at home (vertical upper arm at x = 0.15) hits the robot.
    let arm = caster
        .cast(&Point3::new(0.15, -1.0, 0.8), &Vector3::y(), 5.0, None)
        .unwrap();
    assert_eq!(arm.label, TruthLabel::Robot);
}

#[test]
fn collider_poses_follow_the_kinematic_model() {
    let mut w = world();
    let q = deg([20.0, 10.0, -80.0, 30.0, 45.0, -60.0]);
    w.set_configuration(q);
    // The dinast housing box sits right behind the dinast frame: a ray shot backwards along
    // the optical axis from 5 cm in front of the window hits the housing's front face.
    let cam = w.frame_pose("dinast").unwrap();
    let axis = cam.rotation * Vector3::z();
    let start = Point3::from(cam.translation.vector + axis * 0.05);
    let hit = w.ray_caster().cast(&start, &-axis, 1.0, None).unwrap();
    assert_eq!(hit.label, TruthLabel::Robot);
    assert!((hit.distance - 0.05).abs() < 2e-3, "{}", hit.distance);
    // The same ray ignoring the dinast frame's own colliders goes further.
    let dinast = w.robot().frame_index("dinast").unwrap();
    let beyond = w.ray_caster().cast(&start, &-axis, 1.0, Some(dinast));
    assert!(beyond.is_none_or(|h| h.distance > 0.05));
    assert!(
        w.robot()
            .collision_geometry()
            .iter()
            .any(|g| matches!(g.shape, Shape::Box { .. }))
    );
}
