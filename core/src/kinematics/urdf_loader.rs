//! Turns a parsed URDF (`urdf-rs`) into a [`SerialChain`]: checks that the links form a tree
//! whose movable joints are six revolute joints on one path from the root, folds fixed
//! joints into frame offsets, and copies the collision and visual primitives.

use super::joints::{DOF, JointLimit};
use super::link_geometry::{LinkGeometry, Shape};
use super::serial_chain::{ChainFrame, ChainJoint, SerialChain};
use super::urdf_error::UrdfError;
use crate::math::{Pose, pose_from_xyz_rpy};
use nalgebra::{Unit, Vector3};
use std::collections::HashMap;
use urdf_rs::{Geometry, JointType};

/// Builds the chain from a parsed URDF; `file` names the source in error messages.
pub(crate) fn chain_from_urdf(
    robot: &urdf_rs::Robot,
    file: &str,
) -> Result<SerialChain, UrdfError> {
    let f = || file.to_owned();

    // Links by name.
    let mut link_index: HashMap<&str, usize> = HashMap::new();
    for (i, link) in robot.links.iter().enumerate() {
        if link_index.insert(link.name.as_str(), i).is_some() {
            return Err(UrdfError::Duplicate {
                file: f(),
                kind: "link",
                name: link.name.clone(),
            });
        }
    }
    if robot.links.is_empty() {
        return Err(UrdfError::NotSerialChain {
            file: f(),
            detail: "the robot has no links".into(),
        });
    }

    // Joints: names unique, links exist, one parent per link, supported types.
    let mut joint_names: HashMap<&str, ()> = HashMap::new();
    let mut parent_joint: Vec<Option<usize>> = vec![None; robot.links.len()];
    let mut children: Vec<Vec<usize>> = vec![Vec::new(); robot.links.len()];
    let mut joint_parent: Vec<usize> = Vec::with_capacity(robot.joints.len());
    let mut joint_child: Vec<usize> = Vec::with_capacity(robot.joints.len());
    for (j, joint) in robot.joints.iter().enumerate() {
        if joint_names.insert(joint.name.as_str(), ()).is_some() {
            return Err(UrdfError::Duplicate {
                file: f(),
                kind: "joint",
                name: joint.name.clone(),
            });
        }
        match joint.joint_type {
            JointType::Revolute | JointType::Fixed => {}
            ref other => {
                return Err(UrdfError::UnsupportedJointType {
                    file: f(),
                    joint: joint.name.clone(),
                    kind: format!("{other:?}").to_lowercase(),
                });
            }
        }
        let lookup = |role: &'static str, name: &str| {
            link_index
                .get(name)
                .copied()
                .ok_or_else(|| UrdfError::MissingLink {
                    file: f(),
                    joint: joint.name.clone(),
                    role,
                    link: name.to_owned(),
                })
        };
        let parent = lookup("parent", &joint.parent.link)?;
        let child = lookup("child", &joint.child.link)?;
        if let Some(previous) = parent_joint[child] {
            return Err(UrdfError::NotSerialChain {
                file: f(),
                detail: format!(
                    "link `{}` is the child of both joint `{}` and joint `{}`",
                    joint.child.link, robot.joints[previous].name, joint.name
                ),
            });
        }
        parent_joint[child] = Some(j);
        children[parent].push(child);
        joint_parent.push(parent);
        joint_child.push(child);
    }

    // A single root, and every link reachable from it (no cycles, nothing detached).
    let roots: Vec<usize> = (0..robot.links.len())
        .filter(|&l| parent_joint[l].is_none())
        .collect();
    let root = match roots.as_slice() {
        [r] => *r,
        [] => {
            return Err(UrdfError::NotSerialChain {
                file: f(),
                detail: "no root link (the joints form a cycle)".into(),
            });
        }
        many => {
            let names: Vec<&str> = many.iter().map(|&l| robot.links[l].name.as_str()).collect();
            return Err(UrdfError::NotSerialChain {
                file: f(),
                detail: format!("several root links: {}", names.join(", ")),
            });
        }
    };
    let mut depth = vec![usize::MAX; robot.links.len()];
    depth[root] = 0;
    let mut stack = vec![root];
    while let Some(l) = stack.pop() {
        for &c in &children[l] {
            depth[c] = depth[l] + 1;
            stack.push(c);
        }
    }
    if let Some(l) = depth.iter().position(|&d| d == usize::MAX) {
        return Err(UrdfError::NotSerialChain {
            file: f(),
            detail: format!(
                "link `{}` is not connected to the root `{}` (cycle)",
                robot.links[l].name, robot.links[root].name
            ),
        });
    }

    // Joint origins, checked for finite numbers.
    let origins: Vec<Pose> = robot
        .joints
        .iter()
        .map(|joint| {
            let (xyz, rpy) = (joint.origin.xyz.0, joint.origin.rpy.0);
            if xyz.iter().chain(rpy.iter()).any(|v| !v.is_finite()) {
                return Err(UrdfError::NonFinite {
                    file: f(),
                    item: format!("joint `{}`", joint.name),
                    field: "origin",
                });
            }
            Ok(pose_from_xyz_rpy(xyz, rpy))
        })
        .collect::<Result<_, _>>()?;

    // The movable joints must all lie on the path from the root to the deepest of them.
    let movable: Vec<usize> = (0..robot.joints.len())
        .filter(|&j| robot.joints[j].joint_type == JointType::Revolute)
        .collect();
    let root_name = robot.links[root].name.clone();
    // Deepest first; ties broken by document order for determinism.
    let tip_joint = movable
        .iter()
        .copied()
        .max_by_key(|&j| (depth[joint_child[j]], usize::MAX - j));
    let Some(tip_joint) = tip_joint else {
        return Err(UrdfError::JointCount {
            file: f(),
            root: root_name,
            expected: DOF,
            found: 0,
        });
    };
    let tip = joint_child[tip_joint];
    let mut path: Vec<usize> = Vec::new();
    let mut l = tip;
    while let Some(j) = parent_joint[l] {
        if robot.joints[j].joint_type == JointType::Revolute {
            path.push(j);
        }
        l = joint_parent[j];
    }
    path.reverse();
    if let Some(&off) = movable.iter().find(|j| !path.contains(j)) {
        return Err(UrdfError::NotSerialChain {
            file: f(),
            detail: format!(
                "revolute joint `{}` is not on the path from `{}` to `{}`; only fixed joints \
                 may branch off the chain",
                robot.joints[off].name, root_name, robot.links[tip].name
            ),
        });
    }
    if path.len() != DOF {
        return Err(UrdfError::JointCount {
            file: f(),
            root: root_name,
            expected: DOF,
            found: path.len(),
        });
    }

    // Every link as a frame: walk up through fixed joints to the root or a chain link.
    let chain_index_of_joint: HashMap<usize, usize> =
        path.iter().enumerate().map(|(k, &j)| (j, k + 1)).collect();
    let attach_of = |link: usize| -> (usize, Pose) {
        let mut offset = Pose::identity();
        let mut l = link;
        while let Some(j) = parent_joint[l] {
            if let Some(&k) = chain_index_of_joint.get(&j) {
                return (k, offset);
            }
            offset = origins[j] * offset;
            l = joint_parent[j];
        }
        (0, offset)
    };
    let frames: Vec<ChainFrame> = robot
        .links
        .iter()
        .enumerate()
        .map(|(i, link)| {
            let (attach, offset) = attach_of(i);
            ChainFrame {
                name: link.name.clone(),
                attach,
                offset,
            }
        })
        .collect();

    // The six joints with fixed offsets folded into their origins.
    let mut joints = Vec::with_capacity(DOF);
    for &j in &path {
        let joint = &robot.joints[j];
        // The parent link hangs (through fixed joints) off chain link k.
        let parent_frame = &frames[joint_parent[j]];
        let axis = Vector3::from(joint.axis.xyz.0);
        if axis.iter().any(|v| !v.is_finite()) {
            return Err(UrdfError::NonFinite {
                file: f(),
                item: format!("joint `{}`", joint.name),
                field: "axis",
            });
        }
        let axis = Unit::try_new(axis, 1e-12).ok_or_else(|| UrdfError::ZeroAxis {
            file: f(),
            joint: joint.name.clone(),
        })?;
        joints.push(ChainJoint {
            name: joint.name.clone(),
            origin: parent_frame.offset * origins[j],
            axis,
            limit: limit_of(joint, file)?,
        });
    }
    let joints: [ChainJoint; DOF] = joints.try_into().map_err(|_| UrdfError::JointCount {
        file: f(),
        root: robot.links[root].name.clone(),
        expected: DOF,
        found: path.len(),
    })?;
    let limits = std::array::from_fn(|k| joints[k].limit);

    // Geometry.
    let materials: HashMap<&str, [f64; 4]> = robot
        .materials
        .iter()
        .filter_map(|m| m.color.as_ref().map(|c| (m.name.as_str(), c.rgba.0)))
        .collect();
    let mut collisions = Vec::new();
    let mut visuals = Vec::new();
    for (i, link) in robot.links.iter().enumerate() {
        for c in &link.collision {
            collisions.push(geometry_of(
                i,
                link,
                c.name.clone(),
                &c.origin,
                &c.geometry,
                None,
                file,
            )?);
        }
        for v in &link.visual {
            let rgba = v.material.as_ref().and_then(|m| {
                m.color
                    .as_ref()
                    .map(|c| c.rgba.0)
                    .or_else(|| materials.get(m.name.as_str()).copied())
            });
            visuals.push(geometry_of(
                i,
                link,
                v.name.clone(),
                &v.origin,
                &v.geometry,
                rgba,
                file,
            )?);
        }
    }

    let frame_names: Vec<String> = frames.iter().map(|fr| fr.name.clone()).collect();
    let frame_index = frame_names
        .iter()
        .enumerate()
        .map(|(i, n)| (n.clone(), i))
        .collect();
    Ok(SerialChain {
        name: robot.name.clone(),
        joints,
        limits,
        frames,
        frame_names,
        frame_index,
        collisions,
        visuals,
        root,
        tip,
    })
}

/// The `<limit>` of a revolute joint, validated.
fn limit_of(joint: &urdf_rs::Joint, file: &str) -> Result<JointLimit, UrdfError> {
    let l = &joint.limit;
    let err = |detail: String| UrdfError::InvalidLimits {
        file: file.to_owned(),
        joint: joint.name.clone(),
        detail,
    };
    // urdf-rs fills a missing <limit> with zeros.
    if l.lower == 0.0 && l.upper == 0.0 && l.velocity == 0.0 {
        return Err(UrdfError::MissingLimits {
            file: file.to_owned(),
            joint: joint.name.clone(),
        });
    }
    for (v, name) in [
        (l.lower, "lower"),
        (l.upper, "upper"),
        (l.velocity, "velocity"),
        (l.effort, "effort"),
    ] {
        if !v.is_finite() {
            return Err(err(format!("{name} is not a finite number")));
        }
    }
    if l.lower > l.upper {
        return Err(err(format!(
            "lower ({}) is above upper ({})",
            l.lower, l.upper
        )));
    }
    if l.velocity <= 0.0 {
        return Err(err(format!("velocity ({}) must be positive", l.velocity)));
    }
    Ok(JointLimit {
        lower: l.lower,
        upper: l.upper,
        velocity: l.velocity,
        effort: l.effort,
    })
}

/// One primitive, validated.
fn geometry_of(
    frame: usize,
    link: &urdf_rs::Link,
    name: Option<String>,
    origin: &urdf_rs::Pose,
    geometry: &Geometry,
    rgba: Option<[f64; 4]>,
    file: &str,
) -> Result<LinkGeometry, UrdfError> {
    let bad = |detail: String| UrdfError::InvalidGeometry {
        file: file.to_owned(),
        link: link.name.clone(),
        detail,
    };
    let positive = |v: f64, what: &str| {
        if v.is_finite() && v > 0.0 {
            Ok(v)
        } else {
            Err(bad(format!("{what} must be a positive number, got {v}")))
        }
    };
    let shape = match geometry {
        Geometry::Box { size } => {
            for &s in size.0.iter() {
                positive(s, "box size")?;
            }
            Shape::Box { size: size.0 }
        }
        Geometry::Cylinder { radius, length } => Shape::Cylinder {
            radius: positive(*radius, "cylinder radius")?,
            length: positive(*length, "cylinder length")?,
        },
        Geometry::Capsule { radius, length } => Shape::Capsule {
            radius: positive(*radius, "capsule radius")?,
            length: positive(*length, "capsule length")?,
        },
        Geometry::Sphere { radius } => Shape::Sphere {
            radius: positive(*radius, "sphere radius")?,
        },
        Geometry::Mesh { filename, scale } => {
            let scale = scale.map_or([1.0; 3], |s| s.0);
            if scale.iter().any(|v| !v.is_finite()) {
                return Err(bad(format!("mesh `{filename}` has a non-finite scale")));
            }
            Shape::Mesh {
                filename: filename.clone(),
                scale,
            }
        }
    };
    let (xyz, rpy) = (origin.xyz.0, origin.rpy.0);
    if xyz.iter().chain(rpy.iter()).any(|v| !v.is_finite()) {
        return Err(bad("non-finite origin".into()));
    }
    Ok(LinkGeometry {
        frame,
        link: link.name.clone(),
        name,
        origin: pose_from_xyz_rpy(xyz, rpy),
        shape,
        rgba,
    })
}
