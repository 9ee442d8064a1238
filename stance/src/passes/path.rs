//! Passes 6–8: step geometry along and across the walking path, and the landing shifts pass 7
//! and the terrain pass share.

use kinematics::robot::EndEffector;
use nalgebra::{Isometry3, Vector3};

use crate::geometry::PathFrame;
use crate::poses::{FEET, HANDS, PoseSequence};

/// Pass 6, `scaleTranslation(scf)`: multiplies every along-path coordinate (roots and all
/// end-effectors) by `scf`, keeping lateral offsets and heights. The map depends on the pose
/// alone, so contacts that were static stay static, and the covered distance becomes `scf` times
/// the original.
pub fn scale_translation(poses: &mut PoseSequence, path: &PathFrame, scf: f64) {
    if scf == 1.0 {
        return;
    }
    let shrink = |p: &mut Vector3<f64>| *p -= path.direction() * ((1.0 - scf) * path.along(p));
    for i in 0..poses.len() {
        shrink(&mut poses.roots[i].translation.vector);
        for pose in &mut poses.end_effectors[i] {
            shrink(&mut pose.translation.vector);
        }
    }
}

/// The part of `step` beyond `±limit` (zero inside).
fn excess(step: f64, limit: f64) -> f64 {
    step - step.clamp(-limit, limit)
}

/// First stance at or after `from` where `e` is in contact.
fn next_contact(poses: &PoseSequence, e: EndEffector, from: usize) -> Option<usize> {
    (from..poses.len()).find(|&i| poses.in_contact(i, e))
}

/// How far the walk's first step may land ahead of (or behind) the standing foot, as a share of
/// `s_max`: half, the lead of every later step of a walk whose strides are `s_max`.
const FIRST_STEP_LEAD_SHARE: f64 = 0.5;

/// Pass 7, `limitToMaxStepSize(s_max)`: shortens every step still longer than `s_max` (the
/// along-path distance between consecutive contacts of one foot; backward steps alike) to
/// exactly `s_max`. Everything after a shortened step moves back with it (see
/// `shift_landings`): the landing and all later contact runs, the roots and free
/// end-effectors of later stances. The covered distance shrinks.
///
/// Not in the paper: the walk's first step also lands at most `FIRST_STEP_LEAD_SHARE` (½) ×
/// `s_max` ahead of the other foot. From standing, feet side by side, a step of `s_max` puts
/// the foot a whole stride ahead, twice the lead of every later step (each foot then travels a
/// stride to land half a stride ahead), and the dynamic gait's ZMP would jump that far in the
/// double support after it. People start with a shorter step too.
pub fn limit_to_max_step_size(poses: &mut PoseSequence, path: &PathFrame, s_max: f64) {
    shift_landings(
        poses,
        path,
        &mut StepLimit {
            s_max,
            last_contact_along: [None; 2],
            stepped: false,
        },
    );
}

/// Pass 7's landing rule: a landing moves back by the part of its step beyond `s_max` (and the
/// first step by the part of its lead beyond half of it).
struct StepLimit {
    s_max: f64,
    /// Shifted along-path position of each foot's last contact.
    last_contact_along: [Option<f64>; 2],
    /// Whether a foot has stepped yet (landed after a contact of its own).
    stepped: bool,
}

impl LandingRule for StepLimit {
    type Placed = ();

    fn place(&self, f: usize, along: f64, _sole: &Isometry3<f64>) -> (f64, ()) {
        let Some(previous) = self.last_contact_along[f] else {
            return (0.0, ());
        };
        let step = excess(along - previous, self.s_max);
        let lead = match self.last_contact_along[1 - f] {
            Some(other) if !self.stepped => {
                excess(along - other, FIRST_STEP_LEAD_SHARE * self.s_max)
            }
            _ => 0.0,
        };
        let correction = if lead.abs() > step.abs() { lead } else { step };
        (-correction, ())
    }

    fn landed(&mut self, f: usize, along: f64, _placed: ()) {
        self.stepped |= self.last_contact_along[f].is_some();
        self.last_contact_along[f] = Some(along);
    }
}

/// Where a foot's landing goes along the walking path: the rule [`shift_landings`] applies to
/// every landing. Pass 7 shortens long steps with one, the terrain pass fits footholds to their
/// surfaces with another; the shifting itself (what moves with a landing) is the same.
pub(crate) trait LandingRule {
    /// What the rule decided about a landing besides its shift (the terrain pass: the surface
    /// it lands on), handed back to [`LandingRule::landed`].
    type Placed: Copy;

    /// The along-path move of foot `f` (0 left, 1 right) landing with its sole centre at
    /// `along` (its position after the shifts of the landings before it); `sole` is the
    /// landing's pose before those shifts (its lateral offset and rotation hold). It may be
    /// asked again for the same landing while the foot swings towards it, so it only reads the
    /// rule's state.
    fn place(&self, f: usize, along: f64, sole: &Isometry3<f64>) -> (f64, Self::Placed);

    /// Foot `f` landed at `along` (shifted, final) with what [`LandingRule::place`] decided;
    /// called after every landing of the stance was placed.
    fn landed(&mut self, f: usize, along: f64, placed: Self::Placed);
}

/// Applies `rule` to every landing in order of touchdown: a landing's along-path shift moves
/// that contact run and everything after it with it (later contact runs, the roots and free
/// end-effectors of later stances), so shifts accumulate along the walk. A contact run moves as
/// a whole (by the shift at its first stance), so no contact jumps; a swinging foot's shift is
/// interpolated (by stance index) between its lift-off shift and the shift its landing will
/// get. Heights and lateral offsets are kept.
pub(crate) fn shift_landings<R: LandingRule>(
    poses: &mut PoseSequence,
    path: &PathFrame,
    rule: &mut R,
) {
    let mut state = Running {
        path,
        rule,
        shift: 0.0,
        run_shift: [0.0; 4],
        last_run_end: [None; 4],
    };
    for i in 0..poses.len() {
        let mut placed = [None; 2];
        for (f, &foot) in FEET.iter().enumerate() {
            if poses.contact_starts(i, foot) {
                let (delta, decision) = state.place(poses, f, i);
                state.shift += delta;
                placed[f] = Some(decision);
            }
        }
        for e in EndEffector::ALL {
            let de = if poses.in_contact(i, e) {
                if poses.contact_starts(i, e) {
                    state.run_shift[e as usize] = state.shift;
                }
                state.last_run_end[e as usize] = Some(i);
                state.run_shift[e as usize]
            } else {
                state.swing_shift(poses, e, i)
            };
            if de != 0.0 {
                poses.translate(i, e, &(path.direction() * de));
            }
        }
        for (f, &foot) in FEET.iter().enumerate() {
            if let Some(decision) = placed[f] {
                let along = path.along(&poses.pose(i, foot).translation.vector);
                state.rule.landed(f, along, decision);
            }
        }
        poses.roots[i].translation.vector += path.direction() * state.shift;
    }
}

/// Running state of [`shift_landings`] (along-path shifts), so it needs no allocation.
struct Running<'p, 'r, R> {
    path: &'p PathFrame,
    rule: &'r mut R,
    /// Shift of the current stance.
    shift: f64,
    /// Shift of each end-effector's current (or last) contact run.
    run_shift: [f64; 4],
    /// Last stance each end-effector was in contact.
    last_run_end: [Option<usize>; 4],
}

impl<R: LandingRule> Running<'_, '_, R> {
    /// The rule's shift and decision for foot `f` landing in stance `land` (its raw pose moved
    /// by the current shift).
    fn place(&self, poses: &PoseSequence, f: usize, land: usize) -> (f64, R::Placed) {
        let sole = poses.pose(land, FEET[f]);
        let along = self.path.along(&sole.translation.vector) + self.shift;
        self.rule.place(f, along, sole)
    }

    /// Shift of a free end-effector in stance `i`: for a foot between two contacts, interpolated
    /// (by stance index) from its lift-off shift to the shift its landing will get — only the
    /// swinging foot can land before then, as the other one must stay in support; otherwise the
    /// stance's shift.
    fn swing_shift(&self, poses: &PoseSequence, e: EndEffector, i: usize) -> f64 {
        let Some(f) = FEET.iter().position(|&f| f == e) else {
            return self.shift;
        };
        let Some(lift) = self.last_run_end[e as usize] else {
            return self.shift;
        };
        let Some(land) = next_contact(poses, e, i) else {
            return self.shift;
        };
        let landing_shift = self.shift + self.place(poses, f, land).0;
        let lifted = self.run_shift[e as usize];
        lifted + (landing_shift - lifted) * (i - lift) as f64 / (land - lift) as f64
    }
}

/// Pass 8, `limitOrthogonalFeetDistance(o_min, o_max)`: keeps the lateral distance between the
/// feet, `o = (p_left − p_right) · lateral`, within `[o_min, o_max]` in every stance — which also
/// removes the human gait's interlocking (feet crossing the midline). A foot that lands while
/// the other stands is moved sideways (its whole contact run) to satisfy the limits against the
/// standing foot; feet that land together are moved symmetrically; a swing foot is moved
/// against the foot in support. Feet already inside the limits are not touched.
///
/// Hands in contact move with the feet: a hand's contact run shifts sideways (as a whole, so no
/// contact jumps) by the mean shift of the feet in contact at its first stance. Otherwise the
/// corrections, which accumulate over a long walk, would carry the feet away from a railing the
/// hand holds until it is out of the arm's reach.
pub fn limit_orthogonal_feet_distance(
    poses: &mut PoseSequence,
    path: &PathFrame,
    o_min: f64,
    o_max: f64,
) {
    let [left, right] = FEET;
    let mut run_offset = [0.0; 2];
    let mut hand_offset = [0.0; 2];
    let lateral = |poses: &PoseSequence, i: usize, e: EndEffector| {
        path.lateral(&poses.pose(i, e).translation.vector)
    };
    for i in 0..poses.len() {
        let starts = [
            poses.contact_starts(i, left),
            poses.contact_starts(i, right),
        ];
        for (f, &start) in starts.iter().enumerate() {
            if start {
                run_offset[f] = 0.0;
            }
        }
        if poses.in_contact(i, left) && poses.in_contact(i, right) {
            let distance = (lateral(poses, i, left) + run_offset[0])
                - (lateral(poses, i, right) + run_offset[1]);
            let correction = distance.clamp(o_min, o_max) - distance;
            match starts {
                [true, true] => run_offset = [correction / 2.0, -correction / 2.0],
                [true, false] => run_offset[0] += correction,
                [false, true] => run_offset[1] -= correction,
                [false, false] => {}
            }
        }
        for (f, &foot) in FEET.iter().enumerate() {
            if poses.in_contact(i, foot) && run_offset[f] != 0.0 {
                poses.translate(i, foot, &(path.lateral_axis() * run_offset[f]));
            }
        }
        for (h, &hand) in HANDS.iter().enumerate() {
            if poses.contact_starts(i, hand) {
                hand_offset[h] = mean_support_offset(poses, i, &run_offset);
            }
            if poses.in_contact(i, hand) && hand_offset[h] != 0.0 {
                poses.translate(i, hand, &(path.lateral_axis() * hand_offset[h]));
            }
        }
        let swing = match (poses.in_contact(i, left), poses.in_contact(i, right)) {
            (true, false) => Some((right, -1.0)),
            (false, true) => Some((left, 1.0)),
            _ => None,
        };
        if let Some((foot, side)) = swing {
            let distance = lateral(poses, i, left) - lateral(poses, i, right);
            let correction = distance.clamp(o_min, o_max) - distance;
            if correction != 0.0 {
                poses.translate(i, foot, &(path.lateral_axis() * (side * correction)));
            }
        }
    }
}

/// Mean lateral shift of the feet in contact in stance `i` (zero when none is).
fn mean_support_offset(poses: &PoseSequence, i: usize, run_offset: &[f64; 2]) -> f64 {
    let (sum, count) = FEET
        .iter()
        .zip(run_offset)
        .filter(|(foot, _)| poses.in_contact(i, **foot))
        .fold((0.0, 0.0), |(sum, n), (_, offset)| (sum + offset, n + 1.0));
    if count == 0.0 { 0.0 } else { sum / count }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::derived::{orthogonal_distances, steps};
    use crate::passes::fixtures::{BOTH, LEFT, RIGHT, stance, walk, x_path};
    use kinematics::robot::EndEffector::{LeftFoot, LeftHand, RightFoot, RightHand};

    /// DS, SS(right swings), DS, SS(left swings), DS with the given landing x positions.
    fn gait(right_land: f64, left_land: f64) -> PoseSequence {
        walk(&[
            stance([0.0, 0.1, 0.0], [0.0, -0.1, 0.0], BOTH),
            stance([0.0, 0.1, 0.0], [right_land / 2.0, -0.1, 0.1], LEFT),
            stance([0.0, 0.1, 0.0], [right_land, -0.1, 0.0], BOTH),
            stance([left_land / 2.0, 0.1, 0.1], [right_land, -0.1, 0.0], RIGHT),
            stance([left_land, 0.1, 0.0], [right_land, -0.1, 0.0], BOTH),
        ])
    }

    #[test]
    fn scaling_keeps_lateral_and_height() {
        let mut p = gait(0.6, 1.2);
        scale_translation(&mut p, &x_path(), 0.5);
        let foot = p.pose(4, LeftFoot).translation.vector;
        assert!((foot - Vector3::new(0.6, 0.1, 0.0)).norm() < 1e-12);
        let swing = p.pose(1, RightFoot).translation.vector;
        assert!((swing - Vector3::new(0.15, -0.1, 0.1)).norm() < 1e-12);
    }

    #[test]
    fn long_step_is_shortened_and_later_stances_follow() {
        let mut p = gait(0.6, 1.2);
        limit_to_max_step_size(&mut p, &x_path(), 0.4);
        let mut s = steps(&p, &x_path());
        s.sort_by_key(|step| step.landing);
        let lengths: Vec<f64> = s.iter().map(|step| step.length).collect();
        // The first step from standing leads by half of s_max, the next one is s_max long.
        assert!(
            (lengths[0] - 0.2).abs() < 1e-12 && (lengths[1] - 0.4).abs() < 1e-12,
            "{lengths:?}"
        );
        assert!((p.pose(4, LeftFoot).translation.x - 0.4).abs() < 1e-12);
        // The swing foot lies between its lift-off and landing.
        assert!((p.pose(1, RightFoot).translation.x - 0.1).abs() < 1e-12);
        assert_eq!(
            p.pose(3, RightFoot),
            p.pose(2, RightFoot),
            "contact run static"
        );
    }

    #[test]
    fn steps_exactly_at_their_limits_are_untouched() {
        // The first step leads by exactly half of s_max, the second is exactly s_max long.
        let mut p = gait(0.2, 0.4);
        let before = p.clone();
        limit_to_max_step_size(&mut p, &x_path(), 0.4);
        assert_eq!(p, before);
    }

    #[test]
    fn only_the_first_step_is_held_to_half_a_stride() {
        // The second step leads the standing foot by 0.3 m, more than half of s_max, within it.
        let mut p = gait(0.1, 0.4);
        let before = p.clone();
        limit_to_max_step_size(&mut p, &x_path(), 0.4);
        assert_eq!(p, before);
        // From staggered feet the first step may be s_max long (0.4 m), landing 0.2 m ahead.
        let mut staggered = walk(&[
            stance([0.2, 0.1, 0.0], [0.0, -0.1, 0.0], BOTH),
            stance([0.2, 0.1, 0.0], [0.2, -0.1, 0.1], LEFT),
            stance([0.2, 0.1, 0.0], [0.4, -0.1, 0.0], BOTH),
        ]);
        let before = staggered.clone();
        limit_to_max_step_size(&mut staggered, &x_path(), 0.4);
        assert_eq!(staggered, before);
    }

    #[test]
    fn interlocking_landing_is_moved_sideways_against_the_standing_foot() {
        let mut p = walk(&[
            stance([0.0, 0.1, 0.0], [0.0, -0.1, 0.0], BOTH),
            stance([0.0, 0.1, 0.0], [0.2, 0.05, 0.1], LEFT),
            stance([0.0, 0.1, 0.0], [0.4, 0.12, 0.0], BOTH),
            stance([0.0, 0.1, 0.0], [0.4, 0.12, 0.0], BOTH),
        ]);
        limit_orthogonal_feet_distance(&mut p, &x_path(), 0.18, 0.3);
        assert_eq!(
            p.pose(0, LeftFoot).translation.y,
            0.1,
            "standing foot stays"
        );
        assert!((p.pose(2, RightFoot).translation.y + 0.08).abs() < 1e-12);
        assert_eq!(p.pose(3, RightFoot), p.pose(2, RightFoot));
        assert!(
            (p.pose(1, RightFoot).translation.y + 0.08).abs() < 1e-12,
            "swing foot too"
        );
        for o in orthogonal_distances(&p, &x_path()) {
            assert!((0.18 - 1e-12..=0.3 + 1e-12).contains(&o), "{o}");
        }
    }

    #[test]
    fn a_held_railing_moves_with_the_feet() {
        const BOTH_RIGHT_HAND: [bool; 4] = [true, true, false, true];
        let mut p = walk(&[
            stance([0.0, 0.1, 0.0], [0.0, -0.1, 0.0], BOTH),
            stance([0.0, 0.1, 0.0], [0.2, 0.05, 0.1], LEFT),
            stance([0.0, 0.1, 0.0], [0.4, 0.12, 0.0], BOTH_RIGHT_HAND),
            stance([0.0, 0.1, 0.0], [0.4, 0.12, 0.0], BOTH_RIGHT_HAND),
        ]);
        let before = p.pose(2, RightHand).translation.y;
        let free_hand = *p.pose(2, LeftHand);
        limit_orthogonal_feet_distance(&mut p, &x_path(), 0.18, 0.3);
        // The right foot moved 0.2 m to the right, the left one stayed: the mean is 0.1 m.
        assert!((p.pose(2, RightHand).translation.y - (before - 0.1)).abs() < 1e-12);
        assert_eq!(
            p.pose(3, RightHand),
            p.pose(2, RightHand),
            "contact run static"
        );
        assert_eq!(*p.pose(2, LeftHand), free_hand, "free hands untouched");
    }

    #[test]
    fn feet_landing_together_move_symmetrically() {
        let mut p = walk(&[stance([0.0, 0.3, 0.0], [0.0, -0.3, 0.0], BOTH)]);
        limit_orthogonal_feet_distance(&mut p, &x_path(), 0.18, 0.4);
        assert!((p.pose(0, LeftFoot).translation.y - 0.2).abs() < 1e-12);
        assert!((p.pose(0, RightFoot).translation.y + 0.2).abs() < 1e-12);
    }

    #[test]
    fn feet_inside_the_limits_are_untouched() {
        let mut p = gait(0.3, 0.6);
        let before = p.clone();
        limit_orthogonal_feet_distance(&mut p, &x_path(), 0.18, 0.3);
        assert_eq!(p, before);
    }

    #[test]
    fn right_swing_after_left_step() {
        let mut p = walk(&[
            stance([0.0, 0.1, 0.0], [0.0, -0.1, 0.0], BOTH),
            stance([0.3, 0.0, 0.1], [0.0, -0.1, 0.0], RIGHT),
        ]);
        limit_orthogonal_feet_distance(&mut p, &x_path(), 0.15, 0.3);
        assert!((p.pose(1, LeftFoot).translation.y - 0.05).abs() < 1e-12);
    }
}
