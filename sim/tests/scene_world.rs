//! The twin worlds of the paper scenes: the home configuration is free, configurations
//! that touch the table, an obstacle or an object are reported with what they touch.

use nalgebra::{Point3, Vector3};
use nbv_core::kinematics::Joints;
use nbv_core::rig::TruthLabel;
use nbv_sim::world::{Contacted, TwinWorld, home_configuration};

fn paper(name: &str) -> (nbv_scenes::Scene, TwinWorld) {
    let scene = nbv_scenes::builtin::load(name).unwrap();
    let world = TwinWorld::from_scene(&scene).unwrap();
    (scene, world)
}

/// A configuration whose `dinast` frame is at `target` (world), looking straight down.
fn reach_down(world: &TwinWorld, target: Point3<f64>, home: &Joints) -> Joints {
    let pose = nalgebra::Isometry3::from_parts(
        nalgebra::Translation3::from(target.coords),
        nalgebra::UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::PI),
    );
    world
        .robot()
        .ik_nearest("dinast", &pose, home)
        .unwrap()
        .joints
}

#[test]
fn home_is_collision_free_in_both_paper_scenes() {
    for name in ["paper-env1", "paper-env2"] {
        let (scene, world) = paper(name);
        assert_eq!(world.configuration(), home_configuration(&scene));
        assert!(
            world.contacts().is_empty(),
            "{name}: {:?}",
            world.contacts()
        );
        // 1 table + obstacles + objects.
        assert_eq!(
            world.statics().len(),
            1 + scene.obstacles.len() + scene.objects.len()
        );
    }
}

#[test]
fn touching_the_table_an_object_or_an_obstacle_is_reported() {
    for name in ["paper-env1", "paper-env2"] {
        let (scene, mut world) = paper(name);
        let home = home_configuration(&scene);
        // Camera window 2 cm into the table top, in an empty spot near the front edge.
        let q = reach_down(&world, Point3::new(0.45, 0.55, 0.23), &home);
        let c = world.contacts_at(q);
        assert!(
            c.iter().any(|c| matches!(
                &c.with,
                Contacted::Static {
                    label: TruthLabel::Table,
                    ..
                }
            )),
            "{name}: {c:?}"
        );
        // Camera window inside the first object, 2 cm below its top.
        let meshes = scene.object_meshes().unwrap();
        let (lo, hi) = meshes[0].bounds().unwrap();
        let centre = Point3::new(0.5 * (lo.x + hi.x), 0.5 * (lo.y + hi.y), hi.z - 0.02);
        let q = reach_down(&world, centre, &home);
        let c = world.contacts_at(q);
        assert!(
            c.iter().any(|c| matches!(
                &c.with,
                Contacted::Static {
                    label: TruthLabel::Object(0),
                    ..
                }
            )),
            "{name}: {c:?}"
        );
        // Camera window inside the first obstacle, 5 cm below its top.
        let obstacle = &scene.obstacles[0];
        let size = obstacle.box_size.unwrap();
        let top = obstacle.pose.to_pose() * Point3::new(0.0, 0.0, size[2] - 0.05);
        let q = reach_down(&world, top, &home);
        let c = world.contacts_at(q);
        assert!(
            c.iter().any(|c| matches!(
                &c.with,
                Contacted::Static {
                    label: TruthLabel::Obstacle(0),
                    ..
                }
            )),
            "{name}: {c:?}"
        );
        world.set_configuration(home);
        assert!(!world.in_collision());
    }
}
