//! The rigid bodies MuJoCo simulates, read from the URDF's kinematics and inertials.
//!
//! Links joined by fixed (or mimic) joints move as one rigid body, so they are merged here: each
//! [`RigidBody`] is a link with an actuated joint (or the floating base) together with every link
//! welded to it, with the combined mass, centre of mass and inertia. Merging keeps massless helper
//! links (sensor mounts, an empty root link) from becoming massless moving bodies, which MuJoCo
//! rejects, and leaves MuJoCo only the degrees of freedom the kinematic model has.
//!
//! Visual and collision meshes are ignored (they are not vendored); the feet get box collision
//! geometry from the configured sole size instead (see `mjcf`).

use std::collections::HashMap;

use kinematics::model::Model;
use nalgebra::{Isometry3, Matrix3, Translation3, Unit, UnitQuaternion, Vector3};

use super::MujocoError;

/// A joint that MuJoCo simulates: one actuated joint of the kinematic model.
#[derive(Debug, Clone)]
pub(crate) struct ActuatedJoint {
    /// Model-order index (the kinematic model's joint vector).
    pub index: usize,
    /// Joint name (shared by the URDF, the kinematic model and the MuJoCo model).
    pub name: String,
    /// Hinge (true) or slide (false).
    pub revolute: bool,
    /// Unit axis in the body frame.
    pub axis: Unit<Vector3<f64>>,
}

/// Mass properties of a rigid body, in its body frame.
#[derive(Debug, Clone, Copy)]
pub(crate) struct MassProperties {
    /// Mass (kg).
    pub mass: f64,
    /// Centre of mass in the body frame.
    pub com: Vector3<f64>,
    /// Rotational inertia about the centre of mass, body-frame axes.
    pub inertia: Matrix3<f64>,
}

/// One MuJoCo body: a moving link plus the links welded to it.
#[derive(Debug, Clone)]
pub(crate) struct RigidBody {
    /// Name of the moving link (the body's frame is this link's frame).
    pub name: String,
    /// Index of the parent rigid body (`None` for the floating base).
    pub parent: Option<usize>,
    /// Pose of the body frame in the parent body frame at q = 0.
    pub origin: Isometry3<f64>,
    /// The joint that moves this body (`None` for the floating base).
    pub joint: Option<ActuatedJoint>,
    /// Combined mass properties of the welded links.
    pub mass: MassProperties,
}

/// Where a kinematic-model link sits in the MuJoCo model.
#[derive(Debug, Clone, Copy)]
pub(crate) struct LinkPlacement {
    /// Index of the rigid body the link is part of.
    pub body: usize,
    /// Pose of the link frame in that body's frame.
    pub offset: Isometry3<f64>,
}

/// The rigid bodies in parent-before-child order, and where every link ended up.
#[derive(Debug, Clone)]
pub(crate) struct RigidBodies {
    /// Bodies; index 0 is the floating base.
    pub bodies: Vec<RigidBody>,
    /// Placement of every URDF link, by link name.
    pub links: HashMap<String, LinkPlacement>,
}

impl RigidBodies {
    /// Builds the bodies from the parsed URDF and checks them against the kinematic model: every
    /// actuated joint of `model` must be a moving URDF joint of the same name and vice versa.
    pub fn from_urdf(urdf: &urdf_rs::Robot, model: &Model) -> Result<Self, MujocoError> {
        let tree = UrdfTree::new(urdf)?;
        let mut bodies: Vec<RigidBody> = Vec::new();
        let mut links: HashMap<String, LinkPlacement> = HashMap::with_capacity(urdf.links.len());
        let mut seen_joints = vec![false; model.dof()];
        // Depth-first from the root, parents before children.
        let mut stack = vec![tree.root];
        while let Some(link) = stack.pop() {
            let name = &urdf.links[link].name;
            let placement = match tree.parent_joint[link] {
                None => {
                    bodies.push(new_body(name, None, Isometry3::identity(), None));
                    LinkPlacement {
                        body: 0,
                        offset: Isometry3::identity(),
                    }
                }
                Some(j) => {
                    let joint = &urdf.joints[j];
                    let parent = links[&joint.parent.link];
                    let origin = parent.offset * urdf_pose(&joint.origin);
                    match moving_joint(joint, model, &mut seen_joints)? {
                        Some(actuated) => {
                            bodies.push(new_body(name, Some(parent.body), origin, Some(actuated)));
                            LinkPlacement {
                                body: bodies.len() - 1,
                                offset: Isometry3::identity(),
                            }
                        }
                        None => LinkPlacement {
                            body: parent.body,
                            offset: origin * mimic_offset(joint),
                        },
                    }
                }
            };
            add_inertial(
                &mut bodies[placement.body].mass,
                &urdf.links[link],
                &placement.offset,
            );
            links.insert(name.clone(), placement);
            for &j in tree.children[link].iter().rev() {
                stack.push(tree.link_index[urdf.joints[j].child.link.as_str()]);
            }
        }
        if let Some(missing) = seen_joints.iter().position(|seen| !seen) {
            return Err(MujocoError::ModelMismatch(format!(
                "joint '{}' of the kinematic model is not a moving joint of the URDF",
                model.joint_names()[missing]
            )));
        }
        for body in &bodies {
            if body.joint.is_some() && body.mass.mass <= 0.0 {
                return Err(MujocoError::ModelMismatch(format!(
                    "link '{}' moves on its own joint but it and the links welded to it have no mass",
                    body.name
                )));
            }
        }
        Ok(Self { bodies, links })
    }
}

/// Parent/child structure of the URDF by index.
struct UrdfTree<'a> {
    root: usize,
    parent_joint: Vec<Option<usize>>,
    children: Vec<Vec<usize>>,
    link_index: HashMap<&'a str, usize>,
}

impl<'a> UrdfTree<'a> {
    fn new(urdf: &'a urdf_rs::Robot) -> Result<Self, MujocoError> {
        let link_index: HashMap<&str, usize> = urdf
            .links
            .iter()
            .enumerate()
            .map(|(i, l)| (l.name.as_str(), i))
            .collect();
        let mut parent_joint = vec![None; urdf.links.len()];
        let mut children = vec![Vec::new(); urdf.links.len()];
        for (j, joint) in urdf.joints.iter().enumerate() {
            let lookup = |link: &str| {
                link_index.get(link).copied().ok_or_else(|| {
                    MujocoError::ModelMismatch(format!(
                        "joint '{}' names unknown link '{link}'",
                        joint.name
                    ))
                })
            };
            let (parent, child) = (lookup(&joint.parent.link)?, lookup(&joint.child.link)?);
            parent_joint[child] = Some(j);
            children[parent].push(j);
        }
        let mut roots = (0..urdf.links.len()).filter(|&l| parent_joint[l].is_none());
        let root = roots
            .next()
            .ok_or_else(|| MujocoError::ModelMismatch("the URDF has no root link".to_owned()))?;
        if let Some(other) = roots.next() {
            return Err(MujocoError::ModelMismatch(format!(
                "the URDF has two root links, '{}' and '{}'",
                urdf.links[root].name, urdf.links[other].name
            )));
        }
        Ok(Self {
            root,
            parent_joint,
            children,
            link_index,
        })
    }
}

fn new_body(
    name: &str,
    parent: Option<usize>,
    origin: Isometry3<f64>,
    joint: Option<ActuatedJoint>,
) -> RigidBody {
    RigidBody {
        name: name.to_owned(),
        parent,
        origin,
        joint,
        mass: MassProperties {
            mass: 0.0,
            com: Vector3::zeros(),
            inertia: Matrix3::zeros(),
        },
    }
}

/// The actuated joint a URDF joint becomes, or `None` when it is welded (fixed or mimic).
fn moving_joint(
    joint: &urdf_rs::Joint,
    model: &Model,
    seen: &mut [bool],
) -> Result<Option<ActuatedJoint>, MujocoError> {
    use urdf_rs::JointType;
    let revolute = match joint.joint_type {
        JointType::Revolute | JointType::Continuous => true,
        JointType::Prismatic => false,
        JointType::Fixed => return Ok(None),
        ref other => {
            return Err(MujocoError::ModelMismatch(format!(
                "joint '{}': type {other:?} is not supported",
                joint.name
            )));
        }
    };
    if joint.mimic.is_some() {
        return Ok(None);
    }
    let index = model.joint_index(&joint.name).ok_or_else(|| {
        MujocoError::ModelMismatch(format!(
            "URDF joint '{}' moves but is not an actuated joint of the kinematic model",
            joint.name
        ))
    })?;
    seen[index] = true;
    let axis = Unit::try_new(Vector3::from(joint.axis.xyz.0), 1e-9).ok_or_else(|| {
        MujocoError::ModelMismatch(format!("joint '{}': axis is zero", joint.name))
    })?;
    Ok(Some(ActuatedJoint {
        index,
        name: joint.name.clone(),
        revolute,
        axis,
    }))
}

/// Pose of a welded joint's child: a mimic joint is held at its offset (as the kinematic model
/// does), a fixed joint adds nothing.
fn mimic_offset(joint: &urdf_rs::Joint) -> Isometry3<f64> {
    let offset = joint.mimic.as_ref().and_then(|m| m.offset).unwrap_or(0.0);
    let axis = Vector3::from(joint.axis.xyz.0);
    match joint.joint_type {
        urdf_rs::JointType::Prismatic => Translation3::from(axis * offset).into(),
        urdf_rs::JointType::Revolute | urdf_rs::JointType::Continuous => Isometry3::from_parts(
            Translation3::identity(),
            UnitQuaternion::from_scaled_axis(axis * offset),
        ),
        _ => Isometry3::identity(),
    }
}

/// Adds a link's inertial, placed at `offset` in the body frame, to the body's mass properties.
fn add_inertial(total: &mut MassProperties, link: &urdf_rs::Link, offset: &Isometry3<f64>) {
    let inertial = &link.inertial;
    let mass = inertial.mass.value;
    if mass <= 0.0 {
        return;
    }
    let frame = offset * urdf_pose(&inertial.origin);
    let i = &inertial.inertia;
    let local = Matrix3::new(
        i.ixx, i.ixy, i.ixz, i.ixy, i.iyy, i.iyz, i.ixz, i.iyz, i.izz,
    );
    let rotation = frame.rotation.to_rotation_matrix();
    let part = MassProperties {
        mass,
        com: frame.translation.vector,
        inertia: rotation.matrix() * local * rotation.matrix().transpose(),
    };
    *total = combine(total, &part);
}

/// Mass properties of two rigid parts as one (parallel-axis theorem about the joint CoM).
fn combine(a: &MassProperties, b: &MassProperties) -> MassProperties {
    let mass = a.mass + b.mass;
    let com = (a.com * a.mass + b.com * b.mass) / mass;
    let shift = |p: &MassProperties| {
        let d = p.com - com;
        p.inertia + (Matrix3::identity() * d.norm_squared() - d * d.transpose()) * p.mass
    };
    MassProperties {
        mass,
        com,
        inertia: shift(a) + shift(b),
    }
}

fn urdf_pose(pose: &urdf_rs::Pose) -> Isometry3<f64> {
    let [x, y, z] = pose.xyz.0;
    let [roll, pitch, yaw] = pose.rpy.0;
    Isometry3::from_parts(
        Translation3::new(x, y, z),
        UnitQuaternion::from_euler_angles(roll, pitch, yaw),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn combining_two_point_masses_gives_the_parallel_axis_inertia() {
        let point = |x: f64| MassProperties {
            mass: 1.0,
            com: Vector3::new(x, 0.0, 0.0),
            inertia: Matrix3::zeros(),
        };
        let both = combine(&point(-1.0), &point(1.0));
        assert_eq!(both.mass, 2.0);
        assert!(both.com.norm() < 1e-15);
        // Two unit masses at x = ±1: Ixx = 0, Iyy = Izz = 2.
        let expected = Matrix3::from_diagonal(&Vector3::new(0.0, 2.0, 2.0));
        assert!((both.inertia - expected).norm() < 1e-12, "{}", both.inertia);
    }
}
