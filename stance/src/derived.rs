//! Quantities derived from a sequence's world poses (DESIGN.md §3): steps `s_S`, swing heights
//! `h_S` (above the higher of the swing's lift-off and landing surfaces), orthogonal foot
//! distances `o_S`. The walking direction is [`crate::passes::path_of`]; roll/pitch/yaw is
//! [`crate::geometry::roll_pitch_yaw`]. The passes' invariants are stated in these terms.

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

/// Height of a swing foot above the surface its height is measured from
/// ([`swing_reference`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SwingHeight {
    /// The foot not in contact.
    pub foot: EndEffector,
    /// Step height `h_S` above its reference surface.
    pub height: f64,
}

/// Step height `h_S` per stance: `Some` in single support (the swing foot's height above its
/// [`swing_reference`], if it has one), `None` otherwise.
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
            let z = poses.pose(i, swing).translation.z;
            swing_reference(poses, environment, i, swing).map(|reference| SwingHeight {
                foot: swing,
                height: z - reference,
            })
        })
        .collect()
}

/// The stances around a swing of `foot` through stance `i`: its last contact before (the
/// lift-off) and its first contact after (the landing), where there are.
pub(crate) fn swing_ends(poses: &PoseSequence, i: usize, foot: EndEffector) -> [Option<usize>; 2] {
    [
        (0..i).rev().find(|&j| poses.in_contact(j, foot)),
        (i + 1..poses.len()).find(|&j| poses.in_contact(j, foot)),
    ]
}

/// The elevation a swing foot's height is measured from in stance `i`: the higher of the
/// surfaces under its lift-off and landing soles (on stairs the swing goes up to the higher
/// tread, or starts from it, so a height above the surface under the foot would let it scrape
/// the riser between them); the one of them it has at the start or end of a sequence; with
/// neither, the surface under the foot. On flat ground all of these are the ground. `None`
/// where none is over a surface.
pub fn swing_reference(
    poses: &PoseSequence,
    environment: &Environment,
    i: usize,
    foot: EndEffector,
) -> Option<f64> {
    let under = |j: usize| {
        environment
            .support_at(&poses.pose(j, foot).translation.vector)
            .map(|(_, z)| z)
    };
    let [lift, land] = swing_ends(poses, i, foot).map(|end| end.and_then(under));
    match (lift, land) {
        (Some(lift), Some(land)) => Some(lift.max(land)),
        (lift, land) => lift.or(land).or_else(|| under(i)),
    }
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
