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
    let link_index = links_by_name(robot, file)?;
    let tree = LinkTree::of(robot, &link_index, file)?;
    let (root, depth) = tree.root_and_depths(robot, file)?;
    let origins = joint_origins(robot, file)?;
    let (path, tip) = tree.movable_path(robot, root, &depth, file)?;
    let frames = tree.link_frames(robot, &path, &origins);
    let joints = chain_joints(robot, &tree, &path, &frames, &origins, root, file)?;
    let limits = std::array::from_fn(|k| joints[k].limit);
    let (collisions, visuals) = link_geometries(robot, file)?;

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

/// Each link's index by name: names unique, at least one link.
fn links_by_name<'a>(
    robot: &'a urdf_rs::Robot,
    file: &str,
) -> Result<HashMap<&'a str, usize>, UrdfError> {
    let mut link_index: HashMap<&str, usize> = HashMap::new();
    for (i, link) in robot.links.iter().enumerate() {
        if link_index.insert(link.name.as_str(), i).is_some() {
            return Err(UrdfError::Duplicate {
                file: file.to_owned(),
                kind: "link",
                name: link.name.clone(),
            });
        }
    }
    if robot.links.is_empty() {
        return Err(UrdfError::NotSerialChain {
            file: file.to_owned(),
            detail: "the robot has no links".into(),
        });
    }
    Ok(link_index)
}

/// The links and joints of a URDF as a tree of indices (links and joints in document
/// order): each link's parent joint and children, each joint's parent and child link.
struct LinkTree {
    /// The joint whose child each link is (`None` for the root).
    parent_joint: Vec<Option<usize>>,
    /// The child links of each link.
    children: Vec<Vec<usize>>,
    /// Each joint's parent link.
    joint_parent: Vec<usize>,
    /// Each joint's child link.
    joint_child: Vec<usize>,
}

impl LinkTree {
    /// The tree of the joints: names unique, links exist, one parent per link, supported
    /// types (revolute and fixed).
    fn of(
        robot: &urdf_rs::Robot,
        link_index: &HashMap<&str, usize>,
        file: &str,
    ) -> Result<Self, UrdfError> {
        let f = || file.to_owned();
        let mut joint_names: HashMap<&str, ()> = HashMap::new();
        let mut tree = Self {
            parent_joint: vec![None; robot.links.len()],
            children: vec![Vec::new(); robot.links.len()],
            joint_parent: Vec::with_capacity(robot.joints.len()),
            joint_child: Vec::with_capacity(robot.joints.len()),
        };
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
            if let Some(previous) = tree.parent_joint[child] {
                return Err(UrdfError::NotSerialChain {
                    file: f(),
                    detail: format!(
                        "link `{}` is the child of both joint `{}` and joint `{}`",
                        joint.child.link, robot.joints[previous].name, joint.name
                    ),
                });
            }
            tree.parent_joint[child] = Some(j);
            tree.children[parent].push(child);
            tree.joint_parent.push(parent);
            tree.joint_child.push(child);
        }
        Ok(tree)
    }

    /// The single root, and each link's depth below it: every link reachable from the
    /// root (no cycles, nothing detached).
    fn root_and_depths(
        &self,
        robot: &urdf_rs::Robot,
        file: &str,
    ) -> Result<(usize, Vec<usize>), UrdfError> {
        let f = || file.to_owned();
        let roots: Vec<usize> = (0..robot.links.len())
            .filter(|&l| self.parent_joint[l].is_none())
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
            for &c in &self.children[l] {
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
        Ok((root, depth))
    }

    /// The movable joints in order from the root, and the tip link: they must all lie on
    /// the path from the root to the deepest of them, and be [`DOF`].
    fn movable_path(
        &self,
        robot: &urdf_rs::Robot,
        root: usize,
        depth: &[usize],
        file: &str,
    ) -> Result<(Vec<usize>, usize), UrdfError> {
        let f = || file.to_owned();
        let movable: Vec<usize> = (0..robot.joints.len())
            .filter(|&j| robot.joints[j].joint_type == JointType::Revolute)
            .collect();
        let root_name = robot.links[root].name.clone();
        // Deepest first; ties broken by document order for determinism.
        let tip_joint = movable
            .iter()
            .copied()
            .max_by_key(|&j| (depth[self.joint_child[j]], usize::MAX - j));
        let Some(tip_joint) = tip_joint else {
            return Err(UrdfError::JointCount {
                file: f(),
                root: root_name,
                expected: DOF,
                found: 0,
            });
        };
        let tip = self.joint_child[tip_joint];
        let mut path: Vec<usize> = Vec::new();
        let mut l = tip;
        while let Some(j) = self.parent_joint[l] {
            if robot.joints[j].joint_type == JointType::Revolute {
                path.push(j);
            }
            l = self.joint_parent[j];
        }
        path.reverse();
        if let Some(&off) = movable.iter().find(|j| !path.contains(j)) {
            return Err(UrdfError::NotSerialChain {
                file: f(),
                detail: format!(
                    "revolute joint `{}` is not on the path from `{}` to `{}`; only fixed \
                     joints may branch off the chain",
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
        Ok((path, tip))
    }

    /// Every link as a frame: walked up through fixed joints to the root or a chain link
    /// (the chain's `k`-th joint's child is chain link `k + 1`).
    fn link_frames(
        &self,
        robot: &urdf_rs::Robot,
        path: &[usize],
        origins: &[Pose],
    ) -> Vec<ChainFrame> {
        let chain_index_of_joint: HashMap<usize, usize> =
            path.iter().enumerate().map(|(k, &j)| (j, k + 1)).collect();
        let attach_of = |link: usize| -> (usize, Pose) {
            let mut offset = Pose::identity();
            let mut l = link;
            while let Some(j) = self.parent_joint[l] {
                if let Some(&k) = chain_index_of_joint.get(&j) {
                    return (k, offset);
                }
                offset = origins[j] * offset;
                l = self.joint_parent[j];
            }
            (0, offset)
        };
        robot
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
            .collect()
    }
}

/// Each joint's origin, checked for finite numbers.
fn joint_origins(robot: &urdf_rs::Robot, file: &str) -> Result<Vec<Pose>, UrdfError> {
    robot
        .joints
        .iter()
        .map(|joint| {
            let (xyz, rpy) = (joint.origin.xyz.0, joint.origin.rpy.0);
            if xyz.iter().chain(rpy.iter()).any(|v| !v.is_finite()) {
                return Err(UrdfError::NonFinite {
                    file: file.to_owned(),
                    item: format!("joint `{}`", joint.name),
                    field: "origin",
                });
            }
            Ok(pose_from_xyz_rpy(xyz, rpy))
        })
        .collect()
}

/// The chain's six joints (`path`) with the fixed offsets of their parent links folded
/// into their origins; axes finite and non-zero, limits valid.
fn chain_joints(
    robot: &urdf_rs::Robot,
    tree: &LinkTree,
    path: &[usize],
    frames: &[ChainFrame],
    origins: &[Pose],
    root: usize,
    file: &str,
) -> Result<[ChainJoint; DOF], UrdfError> {
    let f = || file.to_owned();
    let mut joints = Vec::with_capacity(DOF);
    for &j in path {
        let joint = &robot.joints[j];
        // The parent link hangs (through fixed joints) off chain link k.
        let parent_frame = &frames[tree.joint_parent[j]];
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
    joints.try_into().map_err(|_| UrdfError::JointCount {
        file: f(),
        root: robot.links[root].name.clone(),
        expected: DOF,
        found: path.len(),
    })
}

/// The collision and visual primitives of every link, in document order; a visual's
/// colour is its own material's or the named robot-level material's.
fn link_geometries(
    robot: &urdf_rs::Robot,
    file: &str,
) -> Result<(Vec<LinkGeometry>, Vec<LinkGeometry>), UrdfError> {
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
    Ok((collisions, visuals))
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
