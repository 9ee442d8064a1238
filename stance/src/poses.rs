//! The working form of a sequence for the passes: per stance the root pose, the world pose of
//! every end-effector and the contact flags. One forward-kinematics step fills it from a raw
//! sequence; the passes then only touch poses, so they are testable on hand-made poses.

use kinematics::robot::EndEffector;
use nalgebra::{Isometry3, Vector3};

/// The two feet, in the order of the `[left, right]` arrays the passes use.
pub const FEET: [EndEffector; 2] = [EndEffector::LeftFoot, EndEffector::RightFoot];

/// The two hands, in the order of the `[left, right]` arrays the passes use.
pub const HANDS: [EndEffector; 2] = EndEffector::HANDS;

/// World-frame poses of a sequence: `roots[i]`, `end_effectors[i][e as usize]`, `contacts[i]`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PoseSequence {
    /// Global root pose `GP_S` of each stance.
    pub roots: Vec<Isometry3<f64>>,
    /// Global end-effector poses `GP_S^e`, indexed by [`EndEffector`].
    pub end_effectors: Vec<[Isometry3<f64>; 4]>,
    /// Contact flags, indexed by [`EndEffector`]; the passes never change them.
    pub contacts: Vec<[bool; 4]>,
}

impl PoseSequence {
    /// An empty sequence with room for `stances` stances.
    pub fn with_capacity(stances: usize) -> Self {
        Self {
            roots: Vec::with_capacity(stances),
            end_effectors: Vec::with_capacity(stances),
            contacts: Vec::with_capacity(stances),
        }
    }

    /// Removes every stance, keeping the buffers.
    pub fn clear(&mut self) {
        self.roots.clear();
        self.end_effectors.clear();
        self.contacts.clear();
    }

    /// Appends one stance.
    pub fn push(&mut self, root: Isometry3<f64>, poses: [Isometry3<f64>; 4], contacts: [bool; 4]) {
        self.roots.push(root);
        self.end_effectors.push(poses);
        self.contacts.push(contacts);
    }

    /// Number of stances.
    pub fn len(&self) -> usize {
        self.roots.len()
    }

    /// Whether there is no stance.
    pub fn is_empty(&self) -> bool {
        self.roots.is_empty()
    }

    /// Pose of `e` in stance `i`.
    pub fn pose(&self, i: usize, e: EndEffector) -> &Isometry3<f64> {
        &self.end_effectors[i][e as usize]
    }

    /// Whether `e` is in contact in stance `i`.
    pub fn in_contact(&self, i: usize, e: EndEffector) -> bool {
        self.contacts[i][e as usize]
    }

    /// Whether stance `i` begins a contact run of `e` (in contact now, not in the stance before).
    pub fn contact_starts(&self, i: usize, e: EndEffector) -> bool {
        self.in_contact(i, e) && (i == 0 || !self.in_contact(i - 1, e))
    }

    /// Translates `e`'s pose in stance `i` by `offset`.
    pub fn translate(&mut self, i: usize, e: EndEffector, offset: &Vector3<f64>) {
        self.end_effectors[i][e as usize].translation.vector += offset;
    }

    /// Translates the whole stance `i` (root and every end-effector) by `offset`.
    pub fn translate_stance(&mut self, i: usize, offset: &Vector3<f64>) {
        self.roots[i].translation.vector += offset;
        for pose in &mut self.end_effectors[i] {
            pose.translation.vector += offset;
        }
    }
}
