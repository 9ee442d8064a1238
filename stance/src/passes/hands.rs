//! Held hands onto the railings: the pass after the terrain pass that puts every contact run of
//! a hand on a hand affordance of the environment, the palm resting on top of the rail.

use kinematics::robot::EndEffector;
use nalgebra::Vector3;

use crate::environment::Environment;
use crate::poses::{FEET, HANDS, PoseSequence};

/// Not in Algorithm 1: puts each held hand on the railing it holds. For every contact run of a
/// hand, the hand grasps the nearest hand affordance on its side
/// ([`crate::HandAffordance::is_on_the_side_of`]) at its axis point nearest to where the hand
/// reaches from ([`crate::HandAffordance::nearest_on_axis`]): abeam the feet it stands on
/// through the run (the mean position of the soles in contact over the run's stances, at the
/// height of the run's first hand target). The grasp is raised along world +z by the
/// affordance's radius plus `palm_radius`: the palm sphere (the hand's collision geometry,
/// centred on the hand frame) rests on top of the rail and presses down on it. Every stance of
/// the run gets that position (the hand does not slide while it holds); orientations and free
/// hands are left as they are, and so is a hand with no affordance on its side
/// (`RawSequence::in_environment` refuses such a walk in a scene).
///
/// The stance source's grasp is only where the hand reaches for: a scene's railing is elsewhere
/// (its own height, its own distance from the path), and even on the source's own railing
/// (radius 0) the grasp is the axis itself, where the palm would sit inside the rail. Along the
/// path the source's grasp is where the retargeted human hand was, moved by the passes' scaling
/// and step shifts (0.02 m ahead to 0.10 m behind the run's feet on generated walks); abeam of
/// the feet the arm reaches it from every stance of the run alike. Runs after the terrain pass,
/// so on terrain it starts from the final elevations. Allocation-free.
pub fn hold_hand_affordances(
    poses: &mut PoseSequence,
    environment: &Environment,
    palm_radius: f64,
) {
    for hand in HANDS {
        // Set at the start of each run, before any stance of it is placed.
        let mut grasp = None;
        for i in 0..poses.len() {
            if poses.contact_starts(i, hand) {
                let mut from = mean_support(poses, hand, i);
                from.z = poses.pose(i, hand).translation.z;
                grasp = on_top(environment, hand, &from, palm_radius);
            }
            if let (true, Some(grasp)) = (poses.in_contact(i, hand), grasp) {
                poses.end_effectors[i][hand as usize].translation.vector = grasp;
            }
        }
    }
}

/// Mean position of the soles in contact over the contact run of `hand` that starts in stance
/// `start`.
fn mean_support(poses: &PoseSequence, hand: EndEffector, start: usize) -> Vector3<f64> {
    let (sum, count) = (start..poses.len())
        .take_while(|&i| poses.in_contact(i, hand))
        .flat_map(|i| FEET.iter().map(move |&foot| (i, foot)))
        .filter(|&(i, foot)| poses.in_contact(i, foot))
        .fold((Vector3::zeros(), 0.0), |(sum, n), (i, foot)| {
            (sum + poses.pose(i, foot).translation.vector, n + 1.0)
        });
    if count == 0.0 {
        poses.pose(start, hand).translation.vector
    } else {
        sum / count
    }
}

/// Where a palm of `palm_radius` of `hand` reaching from `point` rests on the nearest affordance
/// on its side: on top of its nearest axis point; `None` without one.
fn on_top(
    environment: &Environment,
    hand: EndEffector,
    point: &Vector3<f64>,
    palm_radius: f64,
) -> Option<Vector3<f64>> {
    let (railing, nearest) = environment
        .hand_affordances
        .iter()
        .filter(|railing| railing.is_on_the_side_of(hand))
        .map(|railing| (railing, railing.nearest_on_axis(point)))
        .min_by(|(_, a), (_, b)| (a - point).norm().total_cmp(&(b - point).norm()))?;
    Some(nearest + Vector3::z() * (railing.radius + palm_radius))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::environment::{HandAffordance, SupportSurface};
    use crate::passes::fixtures::{BOTH, CONTACT, LEFT, RIGHT, stance, walk};
    use kinematics::robot::EndEffector::{LeftHand, RightHand};

    /// JVRC-1's palm radius, 0.04 m.
    const PALM: f64 = CONTACT.palm_radius;

    /// A railing along x at `y`, 0.8 m high, 0.02 m thick.
    fn railing(name: &str, y: f64) -> HandAffordance {
        HandAffordance {
            name: name.into(),
            start: Vector3::new(-1.0, y, 0.8),
            end: Vector3::new(5.0, y, 0.8),
            radius: 0.02,
            available: [0.0, 4.0],
        }
    }

    fn with_railings(railings: Vec<HandAffordance>) -> Environment {
        Environment {
            surfaces: vec![SupportSurface::ground()],
            hand_affordances: railings,
        }
    }

    /// Four stances walking along x; the right hand (0.3 m right of the root, 0.8 m up) held in
    /// stances 1 and 2, then free, then held again in stance 4.
    fn held_walk() -> crate::PoseSequence {
        let held = |feet: [bool; 4]| [feet[0], feet[1], false, true];
        walk(&[
            stance([0.0, 0.1, 0.0], [0.0, -0.1, 0.0], BOTH),
            stance([0.0, 0.1, 0.0], [0.0, -0.1, 0.0], held(BOTH)),
            stance([0.2, 0.1, 0.05], [0.0, -0.1, 0.0], held(RIGHT)),
            stance([0.2, 0.1, 0.0], [0.0, -0.1, 0.0], LEFT),
            stance([0.2, 0.1, 0.0], [0.4, -0.1, 0.0], held(BOTH)),
        ])
    }

    #[test]
    fn a_held_hand_rests_on_top_of_the_nearest_railing() {
        let mut p = held_walk();
        let env = with_railings(vec![railing("left", 0.45), railing("right", -0.45)]);
        hold_hand_affordances(&mut p, &env, PALM);
        // Stance 1: the hand reached from (0, −0.3, 0.8); the right railing's axis is 0.15 m
        // away, the left one's 0.75 m. On top: 0.8 + 0.02 + 0.04.
        let placed = p.pose(1, RightHand).translation.vector;
        assert!(
            (placed - Vector3::new(0.0, -0.45, 0.86)).norm() < 1e-12,
            "{placed}"
        );
        // The second run from (0.3, −0.3, 0.8).
        let placed = p.pose(4, RightHand).translation.vector;
        assert!(
            (placed - Vector3::new(0.3, -0.45, 0.86)).norm() < 1e-12,
            "{placed}"
        );
        // Past the railing's end: its end point.
        let mut short = railing("right", -0.45);
        short.start.x = 0.5;
        let mut far = held_walk();
        hold_hand_affordances(&mut far, &with_railings(vec![short]), PALM);
        let placed = far.pose(1, RightHand).translation.vector;
        assert!(
            (placed - Vector3::new(0.5, -0.45, 0.86)).norm() < 1e-12,
            "{placed}"
        );
    }

    #[test]
    fn a_hand_grasps_abeam_of_the_feet_it_stands_on() {
        // The source's hand reached 0.3 m ahead of the feet and 0.1 m low; the run's soles stand
        // at x = 0 throughout, so it grasps the railing beside them, at its own height.
        let mut p = held_walk();
        p.translate(1, RightHand, &Vector3::new(0.3, 0.0, -0.1));
        p.translate(2, RightHand, &Vector3::new(0.3, 0.0, -0.1));
        hold_hand_affordances(&mut p, &with_railings(vec![railing("right", -0.45)]), PALM);
        for i in [1, 2] {
            let placed = p.pose(i, RightHand).translation.vector;
            assert!(
                (placed - Vector3::new(0.0, -0.45, 0.86)).norm() < 1e-12,
                "{i}: {placed}"
            );
        }
    }

    #[test]
    fn free_hands_and_orientations_are_untouched() {
        let mut p = held_walk();
        p.end_effectors[1][RightHand as usize].rotation =
            nalgebra::UnitQuaternion::from_euler_angles(0.1, 0.2, 0.3);
        let before = p.clone();
        hold_hand_affordances(&mut p, &with_railings(vec![railing("right", -0.45)]), PALM);
        for i in 0..p.len() {
            assert_eq!(p.pose(i, LeftHand), before.pose(i, LeftHand), "left, {i}");
            assert_eq!(p.roots[i], before.roots[i]);
            for foot in crate::poses::FEET {
                assert_eq!(p.pose(i, foot), before.pose(i, foot));
            }
            assert_eq!(
                p.pose(i, RightHand).rotation,
                before.pose(i, RightHand).rotation
            );
        }
        for i in [0, 3] {
            assert_eq!(
                p.pose(i, RightHand),
                before.pose(i, RightHand),
                "free in {i}"
            );
        }
        // Nothing to hold: nothing moves.
        let mut bare = before.clone();
        hold_hand_affordances(&mut bare, &Environment::default(), PALM);
        assert_eq!(bare, before);
    }

    #[test]
    fn a_hand_does_not_reach_across_the_body_for_a_railing() {
        let mut p = held_walk();
        let before = p.clone();
        hold_hand_affordances(&mut p, &with_railings(vec![railing("left", 0.45)]), PALM);
        assert_eq!(p, before);
    }

    #[test]
    fn a_run_keeps_the_position_of_its_first_stance() {
        let mut p = held_walk();
        // The hand slid 0.1 m forward within the run: it is put back where the run began.
        p.translate(2, RightHand, &Vector3::new(0.1, 0.0, 0.0));
        let first = p.pose(1, RightHand).translation.vector;
        let env = with_railings(vec![railing("right", -0.45)]);
        hold_hand_affordances(&mut p, &env, PALM);
        assert_eq!(
            p.pose(2, RightHand).translation,
            p.pose(1, RightHand).translation
        );
        let expected = env.hand_affordances[0].nearest_on_axis(&first) + Vector3::z() * 0.06;
        assert!((p.pose(2, RightHand).translation.vector - expected).norm() < 1e-12);
        // A second pass keeps it there (a level railing: its top is above the same axis point).
        let once = p.clone();
        hold_hand_affordances(&mut p, &env, PALM);
        assert_eq!(p, once);
    }
}
