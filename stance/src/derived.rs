//! Quantities derived from a sequence's world poses (DESIGN.md §3): steps `s_S`, swing heights
//! `h_S`, orthogonal foot distances `o_S`. The walking direction is [`crate::passes::path_of`];
//! roll/pitch/yaw is [`crate::geometry::roll_pitch_yaw`]. The passes' invariants are stated in
//! these terms.

use kinematics::robot::EndEffector;

use crate::environment::Environment;
use crate::geometry::PathFrame;
use crate::poses::{FEET, PoseSequence};

/// One step: a foot's move from one contact to its next contact.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Step {
    /// The stepping foot.
    pub foot: EndEffector,
    /// Last stance of the contact the foot leaves.
    pub lift_off: usize,
    /// First stance of the contact it lands in.
    pub landing: usize,
    /// Step size `s_S`: signed along-path distance between the two contacts.
    pub length: f64,
}

/// Every step of both feet, ordered by foot then time.
pub fn steps(poses: &PoseSequence, path: &PathFrame) -> Vec<Step> {
    let mut result = Vec::new();
    for foot in FEET {
        let mut last_contact: Option<usize> = None;
        for i in 0..poses.len() {
            if !poses.in_contact(i, foot) {
                continue;
            }
            if let Some(previous) = last_contact
                && previous + 1 < i
            {
                let from = path.along(&poses.pose(previous, foot).translation.vector);
                let to = path.along(&poses.pose(i, foot).translation.vector);
                result.push(Step {
                    foot,
                    lift_off: previous,
                    landing: i,
                    length: to - from,
                });
            }
            last_contact = Some(i);
        }
    }
    result
}

/// Orthogonal foot distance `o_S` of every stance: lateral offset of the left foot minus that
/// of the right foot, across the walking direction (negative = the feet cross).
pub fn orthogonal_distances(poses: &PoseSequence, path: &PathFrame) -> Vec<f64> {
    (0..poses.len())
        .map(|i| {
            path.lateral(&poses.pose(i, EndEffector::LeftFoot).translation.vector)
                - path.lateral(&poses.pose(i, EndEffector::RightFoot).translation.vector)
        })
        .collect()
}

/// Height of a swing foot above the surface below it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SwingHeight {
    /// The foot not in contact.
    pub foot: EndEffector,
    /// Step height `h_S` above its surface.
    pub height: f64,
}

/// Step height `h_S` per stance: `Some` in single support (the swing foot's height above the
/// surface under it, if any), `None` otherwise.
pub fn swing_heights(poses: &PoseSequence, environment: &Environment) -> Vec<Option<SwingHeight>> {
    (0..poses.len())
        .map(|i| {
            let swing = match (
                poses.in_contact(i, EndEffector::LeftFoot),
                poses.in_contact(i, EndEffector::RightFoot),
            ) {
                (true, false) => EndEffector::RightFoot,
                (false, true) => EndEffector::LeftFoot,
                _ => return None,
            };
            let p = poses.pose(i, swing).translation.vector;
            environment.support_at(&p).map(|(_, z)| SwingHeight {
                foot: swing,
                height: p.z - z,
            })
        })
        .collect()
}

/// Stances `i` where `e` stays in contact from `i − 1` to `i` but its pose changes by more than
/// `tolerance` (translation norm plus rotation angle): the jumping contacts of eq. 2.
pub fn jumping_contacts(poses: &PoseSequence, e: EndEffector, tolerance: f64) -> Vec<usize> {
    (1..poses.len())
        .filter(|&i| poses.in_contact(i - 1, e) && poses.in_contact(i, e))
        .filter(|&i| {
            let (a, b) = (poses.pose(i - 1, e), poses.pose(i, e));
            (a.translation.vector - b.translation.vector).norm() + a.rotation.angle_to(&b.rotation)
                > tolerance
        })
        .collect()
}
