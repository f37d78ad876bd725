//! [`RobotLinks`]: the robot in a recording — each link's meshes logged once in the
//! link's frame, then only the links' poses per reported joint sample.

use super::entity;
use super::palette::rgba;
use nbv_core::kinematics::{Joints, Robot};
use nbv_core::math::Pose;
use nbv_sim::render::robot_items;
use rerun::RecordingStream;
use std::path::Path;

/// The robot's kinematic model and base, and which links have meshes.
pub struct RobotLinks {
    robot: Robot,
    base: Pose,
    /// Links (by frame index) that carry a mesh, with their entity paths.
    links: Vec<(usize, String)>,
}

impl RobotLinks {
    /// Logs the meshes of `robot` (URDF visuals; meshes read relative to `urdf_dir`) as
    /// static data under [`entity::ROBOT`].
    pub fn log_static(
        rec: &RecordingStream,
        robot: Robot,
        base: Pose,
        urdf_dir: &Path,
    ) -> crate::Result<Self> {
        use crate::error::Context;
        let q = Joints::zeros();
        let poses = robot.link_poses(&q);
        let items = robot_items(&robot, &base, &q, urdf_dir).context("the robot's meshes")?;
        let geometry = if robot.visual_geometry().is_empty() {
            robot.collision_geometry()
        } else {
            robot.visual_geometry()
        };
        let names = robot.frame_names();
        let mut links: Vec<(usize, String)> = Vec::new();
        for (k, (g, item)) in geometry.iter().zip(&items).enumerate() {
            let Some(link_pose) = poses.get(g.frame) else {
                continue;
            };
            // The item is placed in the world; its mesh in the link's frame:
            let in_link = (base * link_pose).inverse() * item.pose;
            let mesh = item.mesh.transformed(&in_link);
            let path = format!("{}/{}", entity::ROBOT, names[g.frame]);
            let vertices: Vec<[f32; 3]> = mesh.vertices.iter().map(|p| f32x3(p.coords)).collect();
            rec.log_static(
                format!("{path}/visual_{k}"),
                &rerun::Mesh3D::new(vertices)
                    .with_triangle_indices(mesh.triangles.iter().copied())
                    .with_albedo_factor(rgba(item.color)),
            )
            .context("logging the robot")?;
            if !links.iter().any(|(f, _)| *f == g.frame) {
                links.push((g.frame, path));
            }
        }
        Ok(Self { robot, base, links })
    }

    /// The kinematic model.
    pub fn robot(&self) -> &Robot {
        &self.robot
    }

    /// The base pose.
    pub fn base(&self) -> &Pose {
        &self.base
    }

    /// Logs every link's world pose at `q` (at the stream's current time).
    pub fn log_joints(&self, rec: &RecordingStream, q: &Joints) -> crate::Result<()> {
        use crate::error::Context;
        let poses = self.robot.link_poses(q);
        for (frame, path) in &self.links {
            let pose = self.base * poses[*frame];
            rec.log(path.as_str(), &transform(&pose))
                .context("logging the robot's pose")?;
        }
        Ok(())
    }
}

/// A pose as a Rerun transform (translation and rotation, replacing the previous one).
pub fn transform(pose: &Pose) -> rerun::Transform3D {
    let q = pose.rotation.quaternion();
    rerun::Transform3D::from_translation_rotation(
        f32x3(pose.translation.vector),
        rerun::Quaternion::from_xyzw([q.i as f32, q.j as f32, q.k as f32, q.w as f32]),
    )
}

/// A vector as `f32`s.
pub fn f32x3(v: nalgebra::Vector3<f64>) -> [f32; 3] {
    [v.x as f32, v.y as f32, v.z as f32]
}
