//! The `[robot.joint_groups]` guess. Legs are the actuated joints of the two leg chains; every
//! other actuated joint goes by the first of these words its name contains (case-insensitive):
//! head [`HEAD`], arms [`ARMS`], torso [`TORSO`], legs [`LEGS`]. A joint whose name says
//! nothing takes the group of the nearest named joint above it (JVRC-1's thumb joint
//! `R_UTHUMB` under the wrist is an arm joint); one with none above is left out and listed.

use super::legs::Legs;
use super::model::UrdfModel;

/// Words of head joint names.
pub const HEAD: [&str; 4] = ["neck", "head", "eye", "jaw"];
/// Words of arm joint names (hands and fingers included).
pub const ARMS: [&str; 9] = [
    "shoulder", "elbow", "wrist", "arm", "hand", "finger", "thumb", "palm", "grip",
];
/// Words of finger joint names (arm joints that do not end the arm).
pub const FINGERS: [&str; 8] = [
    "finger", "thumb", "index", "middle", "ring", "little", "pinky", "grip",
];
/// Words of torso joint names.
pub const TORSO: [&str; 5] = ["torso", "waist", "chest", "trunk", "spine"];
/// Words of leg joint names (for joints outside the leg chains, such as toes).
pub const LEGS: [&str; 7] = ["hip", "knee", "ankle", "leg", "thigh", "foot", "toe"];

/// The four groups as joint names in model order, and the joints in none.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct JointGroups {
    /// Both legs.
    pub legs: Vec<String>,
    /// Both arms, hands included.
    pub arms: Vec<String>,
    /// Waist and chest.
    pub torso: Vec<String>,
    /// Neck and head.
    pub head: Vec<String>,
    /// Actuated joints no rule placed.
    pub unassigned: Vec<String>,
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Group {
    Legs,
    Arms,
    Torso,
    Head,
}

/// The group a joint's name puts it in, if any.
fn by_name(name: &str) -> Option<Group> {
    let name = name.to_lowercase();
    let has = |words: &[&str]| words.iter().any(|w| name.contains(w));
    if has(&HEAD) {
        Some(Group::Head)
    } else if has(&ARMS) {
        Some(Group::Arms)
    } else if has(&TORSO) {
        Some(Group::Torso)
    } else if has(&LEGS) {
        Some(Group::Legs)
    } else {
        None
    }
}

/// Groups every actuated joint of `model`.
pub fn joint_groups(model: &UrdfModel, legs: &Legs) -> JointGroups {
    let in_legs: Vec<usize> = legs.both().iter().flat_map(|l| l.joints.clone()).collect();
    let dof = model.model.dof();
    let mut groups: Vec<Option<Group>> = (0..dof)
        .map(|j| {
            if in_legs.contains(&j) {
                Some(Group::Legs)
            } else {
                by_name(model.joint_name(j))
            }
        })
        .collect();
    // Joints in model order: a parent's joint precedes its children's.
    for j in 0..dof {
        if groups[j].is_some() {
            continue;
        }
        groups[j] = model
            .ancestry(model.joint_link(j))
            .into_iter()
            .skip(1)
            .filter_map(|l| model.facts(l).actuated)
            .find_map(|above| groups[above]);
    }
    let mut result = JointGroups::default();
    for (j, group) in groups.into_iter().enumerate() {
        let name = model.joint_name(j).to_owned();
        match group {
            Some(Group::Legs) => result.legs.push(name),
            Some(Group::Arms) => result.arms.push(name),
            Some(Group::Torso) => result.torso.push(name),
            Some(Group::Head) => result.head.push(name),
            None => result.unassigned.push(name),
        }
    }
    result
}
