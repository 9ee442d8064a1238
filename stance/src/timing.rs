//! Stance durations through post-processing. A timed stance's duration was planned for the step
//! its source made; pass 6 shortens every step by `scf` (the source planned for that), but other
//! passes change single steps: pass 7 shortens the long ones, the terrain pass moves footholds.
//! A swing whose step a pass changed keeps the pace of a dynamically similar step: its stances'
//! durations are scaled by √(new length / planned length) (time ∝ √length at equal Froude
//! number), within [`FACTOR_RANGE`]. Steps changed by less than [`TOLERANCE`] keep their
//! durations.

use kinematics::robot::EndEffector;
use nalgebra::Vector3;

use crate::poses::{FEET, PoseSequence};

/// A relative change of a step's length below this leaves its durations as they are.
pub const TOLERANCE: f64 = 0.05;

/// The factor on a swing's durations stays within this range.
pub const FACTOR_RANGE: [f64; 2] = [0.5, 2.0];

/// A swing shorter than this (m) is a foot set down again, not a step: its time is not its
/// length's.
const MIN_STEP_M: f64 = 0.01;

/// The feet's positions in every stance, `[left, right]`.
pub(crate) type FeetPositions = Vec<[Vector3<f64>; 2]>;

/// Fills `feet` with the feet's positions in every stance of `poses` (reusing its buffer).
pub(crate) fn feet_positions(poses: &PoseSequence, feet: &mut FeetPositions) {
    feet.clear();
    feet.extend(
        poses
            .end_effectors
            .iter()
            .map(|e| FEET.map(|f| e[f as usize].translation.vector)),
    );
}

/// Scales the durations of the swings whose step changed between `planned` (the feet before
/// the passes) and `processed`, the steps of `planned` being meant to shrink by `scf`.
pub(crate) fn retime_swings(
    planned: &[[Vector3<f64>; 2]],
    processed: &PoseSequence,
    scf: f64,
    durations: &mut [Option<f64>],
) {
    for (slot, foot) in FEET.into_iter().enumerate() {
        for swing in swings(&processed.contacts, foot) {
            let travel = |positions: &dyn Fn(usize) -> Vector3<f64>| {
                (positions(swing.touchdown) - positions(swing.lift_off - 1))
                    .xy()
                    .norm()
            };
            let meant = scf * travel(&|i| planned[i][slot]);
            let made = travel(&|i| processed.end_effectors[i][foot as usize].translation.vector);
            if meant < MIN_STEP_M || (made / meant - 1.0).abs() < TOLERANCE {
                continue;
            }
            let factor = (made / meant)
                .sqrt()
                .clamp(FACTOR_RANGE[0], FACTOR_RANGE[1]);
            for duration in durations[swing.lift_off..swing.touchdown]
                .iter_mut()
                .flatten()
            {
                *duration *= factor;
            }
        }
    }
}

/// One swing of a foot: the first stance it is in the air and the stance it lands in.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Swing {
    lift_off: usize,
    touchdown: usize,
}

/// The complete swings of `foot` over the stances' contacts.
fn swings(contacts: &[[bool; 4]], foot: EndEffector) -> impl Iterator<Item = Swing> + '_ {
    let down = move |i: usize| contacts[i][foot as usize];
    let mut lift_off = None;
    (1..contacts.len()).filter_map(move |i| match (down(i - 1), down(i)) {
        (true, false) => {
            lift_off = Some(i);
            None
        }
        (false, true) => lift_off.take().map(|lift_off| Swing {
            lift_off,
            touchdown: i,
        }),
        _ => None,
    })
}

#[cfg(test)]
mod tests {
    use nalgebra::{Isometry3, Translation3};

    use super::*;

    const DS: [bool; 4] = [true, true, false, false];
    const RIGHT_UP: [bool; 4] = [true, false, false, false];

    /// A walk whose right foot steps from x = 0 to `steps` in turn, one swing stance each.
    fn walk(steps: &[f64]) -> PoseSequence {
        let mut poses = PoseSequence::with_capacity(2 * steps.len() + 1);
        let at =
            |x: f64| Isometry3::from_parts(Translation3::new(x, -0.1, 0.0), Default::default());
        let mut right = 0.0;
        let mut push = |contacts: [bool; 4], x: f64| {
            let mut e = [Isometry3::identity(); 4];
            e[EndEffector::RightFoot as usize] = at(x);
            poses.push(Isometry3::identity(), e, contacts);
        };
        push(DS, right);
        for &x in steps {
            push(RIGHT_UP, right);
            right = x;
            push(DS, right);
        }
        poses
    }

    #[test]
    fn swings_run_from_lift_off_to_touchdown() {
        let poses = walk(&[0.2, 0.4]);
        let found: Vec<Swing> = swings(&poses.contacts, EndEffector::RightFoot).collect();
        assert_eq!(
            found,
            [
                Swing {
                    lift_off: 1,
                    touchdown: 2
                },
                Swing {
                    lift_off: 3,
                    touchdown: 4
                }
            ]
        );
        assert_eq!(swings(&poses.contacts, EndEffector::LeftFoot).count(), 0);
    }

    #[test]
    fn a_step_a_pass_shortened_is_retimed_by_the_square_root_and_the_others_are_not() {
        // Planned at 0.4 m steps and an scf of 0.5: 0.2 m is meant. The second step was cut
        // to 0.05 m (a quarter: factor 0.5), the first is as meant.
        let mut planned = Vec::new();
        feet_positions(&walk(&[0.4, 0.8]), &mut planned);
        let processed = walk(&[0.2, 0.25]);
        let mut durations = vec![Some(1.0), Some(0.6), Some(0.2), Some(0.6), None];
        retime_swings(&planned, &processed, 0.5, &mut durations);
        assert_eq!(
            durations,
            [Some(1.0), Some(0.6), Some(0.2), Some(0.3), None],
            "only the second swing's stance changes"
        );
    }

    #[test]
    fn the_factor_is_bounded() {
        let mut planned = Vec::new();
        feet_positions(&walk(&[0.1]), &mut planned);
        let mut durations = vec![None, Some(0.5), None];
        retime_swings(&planned, &walk(&[0.9]), 1.0, &mut durations);
        assert_eq!(durations[1], Some(0.5 * FACTOR_RANGE[1]));
    }
}
