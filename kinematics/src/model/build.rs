//! URDF (as parsed by urdf-rs, plus the raw-XML facts) → validated [`Model`].

use std::collections::{HashMap, HashSet};

use nalgebra::{Isometry3, Matrix3, Translation3, Unit, UnitQuaternion, Vector3};

use super::{Body, JointLimits, JointMotion, Model, ModelError, inertia, pose_from_xyz_rpy, raw};

fn urdf_pose(pose: &urdf_rs::Pose) -> Isometry3<f64> {
    pose_from_xyz_rpy(pose.xyz.0, pose.rpy.0)
}

/// Validates the parsed URDF and lays it out as a depth-first tree.
pub(super) fn build(robot: urdf_rs::Robot, facts: &raw::RawFacts) -> Result<Model, ModelError> {
    if robot.links.is_empty() {
        return Err(ModelError::Empty);
    }
    let mut urdf_link_index: HashMap<&str, usize> = HashMap::new();
    for (i, link) in robot.links.iter().enumerate() {
        if urdf_link_index.insert(link.name.as_str(), i).is_some() {
            return Err(ModelError::DuplicateLink(link.name.clone()));
        }
        check_link_inertia(link, facts)?;
    }
    let mut seen_joints = HashSet::new();
    // parent_joint[link] = index of the joint whose child it is.
    let mut parent_joint: Vec<Option<usize>> = vec![None; robot.links.len()];
    let mut children: Vec<Vec<usize>> = vec![Vec::new(); robot.links.len()];
    for (j, joint) in robot.joints.iter().enumerate() {
        if !seen_joints.insert(joint.name.as_str()) {
            return Err(ModelError::DuplicateJoint(joint.name.clone()));
        }
        let lookup = |role: &'static str, link: &str| {
            urdf_link_index
                .get(link)
                .copied()
                .ok_or_else(|| ModelError::UnknownLink {
                    joint: joint.name.clone(),
                    role,
                    link: link.to_owned(),
                })
        };
        let parent = lookup("parent", &joint.parent.link)?;
        let child = lookup("child", &joint.child.link)?;
        if let Some(first) = parent_joint[child] {
            return Err(ModelError::MultipleParents {
                link: joint.child.link.clone(),
                first: robot.joints[first].name.clone(),
                second: joint.name.clone(),
            });
        }
        parent_joint[child] = Some(j);
        children[parent].push(j);
    }
    let roots: Vec<usize> = (0..robot.links.len())
        .filter(|&l| parent_joint[l].is_none())
        .collect();
    let root = match roots.as_slice() {
        [] => return Err(ModelError::Cycle(robot.links[0].name.clone())),
        [root] => *root,
        [a, b, ..] => {
            return Err(ModelError::MultipleRoots(
                robot.links[*a].name.clone(),
                robot.links[*b].name.clone(),
            ));
        }
    };

    // Depth-first order from the root; `order` holds URDF link indices.
    let mut order: Vec<usize> = Vec::with_capacity(robot.links.len());
    let mut stack = vec![root];
    while let Some(link) = stack.pop() {
        order.push(link);
        for &j in children[link].iter().rev() {
            stack.push(urdf_link_index[robot.joints[j].child.link.as_str()]);
        }
    }
    if order.len() != robot.links.len() {
        let mut reached = vec![false; robot.links.len()];
        for &l in &order {
            reached[l] = true;
        }
        let stranded = (0..robot.links.len()).find(|&l| !reached[l]).unwrap_or(0);
        return Err(ModelError::Cycle(robot.links[stranded].name.clone()));
    }
    let mut model_index = vec![0usize; robot.links.len()];
    for (i, &l) in order.iter().enumerate() {
        model_index[l] = i;
    }

    let mut bodies = Vec::with_capacity(order.len());
    let mut joint_names = Vec::new();
    let mut joint_limits = Vec::new();
    let mut joint_links = Vec::new();
    for (i, &l) in order.iter().enumerate() {
        let link = &robot.links[l];
        let mass = if facts.links_with_inertial.contains(&link.name) {
            link.inertial.mass.value
        } else {
            0.0
        };
        let com = Vector3::from(link.inertial.origin.xyz.0);
        let Some(j) = parent_joint[l] else {
            bodies.push(Body {
                parent: None,
                origin: Isometry3::identity(),
                motion: JointMotion::Fixed,
                mass,
                com,
            });
            continue;
        };
        let joint = &robot.joints[j];
        let (origin, motion, limits) = joint_model(joint, facts, joint_names.len())?;
        if let Some(limits) = limits {
            joint_names.push(joint.name.clone());
            joint_limits.push(limits);
            joint_links.push(i);
        }
        bodies.push(Body {
            parent: Some(model_index[urdf_link_index[joint.parent.link.as_str()]]),
            origin,
            motion,
            mass,
            com,
        });
    }

    let mut subtree_masses: Vec<f64> = bodies.iter().map(|b| b.mass).collect();
    for i in (1..bodies.len()).rev() {
        if let Some(p) = bodies[i].parent {
            subtree_masses[p] += subtree_masses[i];
        }
    }
    let total_mass = subtree_masses[0];

    let mut support = Vec::new();
    let mut support_ranges = Vec::with_capacity(bodies.len());
    let mut chain = Vec::new();
    for i in 0..bodies.len() {
        chain.clear();
        let mut link = Some(i);
        while let Some(l) = link {
            match bodies[l].motion {
                JointMotion::Revolute { index, .. } | JointMotion::Prismatic { index, .. } => {
                    chain.push(index)
                }
                JointMotion::Fixed => {}
            }
            link = bodies[l].parent;
        }
        let start = support.len();
        support.extend(chain.iter().rev());
        support_ranges.push((start, support.len()));
    }

    let link_names: Vec<String> = order.iter().map(|&l| robot.links[l].name.clone()).collect();
    let link_lookup = link_names
        .iter()
        .enumerate()
        .map(|(i, n)| (n.clone(), i))
        .collect();
    let joint_lookup = joint_names
        .iter()
        .enumerate()
        .map(|(i, n)| (n.clone(), i))
        .collect();
    Ok(Model {
        name: robot.name,
        bodies,
        link_names,
        link_lookup,
        joint_names,
        joint_lookup,
        joint_limits,
        joint_links,
        subtree_masses,
        support,
        support_ranges,
        frames: Vec::new(),
        frame_lookup: HashMap::new(),
        total_mass,
    })
}

/// Origin, motion and (for actuated joints) limits of one URDF joint.
fn joint_model(
    joint: &urdf_rs::Joint,
    facts: &raw::RawFacts,
    next_index: usize,
) -> Result<(Isometry3<f64>, JointMotion, Option<JointLimits>), ModelError> {
    use urdf_rs::JointType;
    let origin = urdf_pose(&joint.origin);
    let kind = match joint.joint_type {
        JointType::Fixed => return Ok((origin, JointMotion::Fixed, None)),
        JointType::Revolute => "revolute",
        JointType::Continuous => "continuous",
        JointType::Prismatic => "prismatic",
        ref other => {
            return Err(ModelError::UnsupportedJoint {
                joint: joint.name.clone(),
                kind: format!("{other:?}").to_lowercase(),
            });
        }
    };
    let axis = Unit::try_new(Vector3::from(joint.axis.xyz.0), 1e-12)
        .ok_or_else(|| ModelError::ZeroAxis(joint.name.clone()))?;
    let has_limit = facts.joints_with_limit.contains(&joint.name);
    let limits = if kind == "continuous" {
        JointLimits {
            lower: f64::NEG_INFINITY,
            upper: f64::INFINITY,
            velocity: if has_limit {
                joint.limit.velocity
            } else {
                f64::INFINITY
            },
            effort: if has_limit {
                joint.limit.effort
            } else {
                f64::INFINITY
            },
        }
    } else {
        if !has_limit {
            return Err(ModelError::MissingLimit(joint.name.clone(), kind));
        }
        JointLimits {
            lower: joint.limit.lower,
            upper: joint.limit.upper,
            velocity: joint.limit.velocity,
            effort: joint.limit.effort,
        }
    };
    if limits.lower > limits.upper || limits.velocity < 0.0 || limits.effort < 0.0 {
        return Err(ModelError::InvalidLimits {
            joint: joint.name.clone(),
            lower: limits.lower,
            upper: limits.upper,
            velocity: limits.velocity,
            effort: limits.effort,
        });
    }
    let prismatic = kind == "prismatic";
    if let Some(mimic) = &joint.mimic {
        // Mimic joints are fixed at the value they take when the joint they follow is at zero.
        let offset = mimic.offset.unwrap_or(0.0);
        let motion = if prismatic {
            Isometry3::from_parts(
                Translation3::from(axis.into_inner() * offset),
                UnitQuaternion::identity(),
            )
        } else {
            Isometry3::from_parts(
                Translation3::identity(),
                UnitQuaternion::from_axis_angle(&axis, offset),
            )
        };
        return Ok((origin * motion, JointMotion::Fixed, None));
    }
    if limits.velocity.is_nan() || limits.velocity <= 0.0 {
        // The controller moves a joint at most at its velocity limit: 0 would freeze it.
        return Err(ModelError::ZeroVelocityLimit {
            joint: joint.name.clone(),
            velocity: limits.velocity,
        });
    }
    let motion = if prismatic {
        JointMotion::Prismatic {
            axis,
            index: next_index,
        }
    } else {
        JointMotion::Revolute {
            axis,
            index: next_index,
        }
    };
    Ok((origin, motion, Some(limits)))
}

fn check_link_inertia(link: &urdf_rs::Link, facts: &raw::RawFacts) -> Result<(), ModelError> {
    if !facts.links_with_inertial.contains(&link.name) {
        return Ok(());
    }
    let mass = link.inertial.mass.value;
    if mass < 0.0 {
        return Err(ModelError::NegativeMass {
            link: link.name.clone(),
            mass,
        });
    }
    if mass == 0.0 {
        return Ok(());
    }
    let i = &link.inertial.inertia;
    let tensor = Matrix3::new(
        i.ixx, i.ixy, i.ixz, i.ixy, i.iyy, i.iyz, i.ixz, i.iyz, i.izz,
    );
    inertia::check(&tensor).map_err(|defect| ModelError::InvalidInertia {
        link: link.name.clone(),
        defect,
    })
}
