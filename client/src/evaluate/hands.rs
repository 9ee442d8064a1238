//! How much of the robot's weight its held hands carried: `hand_support_share`, from the
//! simulator's contact forces (never from the controller's estimate).

use kinematics::robot::EndEffector;
use shm_types::SimTruth;

use super::telemetry::AskedForce;
use super::truth::state_at;

/// The mean vertical force of the environment on both palms, divided by the robot's weight
/// (`weight_n`), over the statuses at which a hand is planned in contact and the simulator's
/// state pairs. Each status is its stance index (the stance the daemon moved towards, into
/// `contacts`, the sequence's contact flags per stance) and the time it was written. A hand is
/// planned in contact while the walk moves towards a stance that holds it from one that held it
/// too: a hand reaching for the rail is not yet meant to carry. `None` when no paired status
/// plans a hand in contact.
pub(crate) fn support_share(
    contacts: &[[bool; 4]],
    statuses: impl IntoIterator<Item = (u32, u64)>,
    states: &[SimTruth],
    weight_n: f64,
) -> Option<f64> {
    let (mut sum, mut count) = (0.0, 0_usize);
    for (index, time) in statuses {
        if !hand_planned_held(contacts, index as usize) {
            continue;
        }
        let Some(state) = state_at(states, time) else {
            continue;
        };
        sum += state.hand_forces.iter().map(|force| force[2]).sum::<f64>();
        count += 1;
    }
    (count > 0).then(|| sum / count as f64 / weight_n)
}

/// The mean vertical force walkd asked of the held hands (`asked`, per stance index, from its
/// telemetry), divided by the robot's weight (`weight_n`), over the stances in which a hand is
/// planned in contact ([`hand_planned_held`], as [`support_share`] counts): the desired split
/// beside the measured one. `None` when walkd held no hand in those stances.
pub(crate) fn asked_share(
    contacts: &[[bool; 4]],
    asked: &[AskedForce],
    weight_n: f64,
) -> Option<f64> {
    let (sum, ticks) = asked
        .iter()
        .enumerate()
        .filter(|(index, _)| hand_planned_held(contacts, *index))
        .fold((0.0, 0), |(sum, ticks), (_, a)| {
            (sum + a.sum_n, ticks + a.ticks)
        });
    (ticks > 0).then(|| sum / ticks as f64 / weight_n)
}

/// Whether a hand is planned to carry while the walk moves towards stance `index` of `contacts`
/// (the sequence's flags per stance): that stance holds it and the one before held it too, so a
/// hand reaching for the rail is not yet meant to carry. Towards stance 0 the walk leaves its
/// standing start, hands free, so a hand the first stance holds is reaching too. An index past
/// the end is the last stance; false without stances.
pub fn hand_planned_held(contacts: &[[bool; 4]], index: usize) -> bool {
    let (Some(last), Some(before)) = (contacts.len().checked_sub(1), index.checked_sub(1)) else {
        return false;
    };
    let (now, before) = (contacts[index.min(last)], contacts[before.min(last)]);
    EndEffector::HANDS
        .iter()
        .any(|&h| now[h as usize] && before[h as usize])
}

/// The planned hand contact runs (a hand in contact through consecutive stances of `contacts`,
/// the sequence's flags) that walkd went on without: no tick of the run's stances had the hand
/// in its contact set (`hands_held`, per stance index, from its telemetry). Only runs the walk
/// got to the end of (their last stance at most `reached`, the stance walkd last moved towards)
/// count, so a walk that stopped mid-run is not counted as having given up its hand.
pub(crate) fn reaches_given_up(
    contacts: &[[bool; 4]],
    hands_held: &[[bool; 2]],
    reached: usize,
) -> u32 {
    let held = |i: usize, k: usize| hands_held.get(i).is_some_and(|held| held[k]);
    let mut given_up = 0;
    for (k, hand) in EndEffector::HANDS.iter().enumerate() {
        let mut run_start = None;
        for i in 0..=contacts.len() {
            let planned = contacts.get(i).is_some_and(|c| c[*hand as usize]);
            match (planned, run_start) {
                (true, None) => run_start = Some(i),
                (false, Some(start)) => {
                    run_start = None;
                    if i - 1 <= reached && !(start..i).any(|s| held(s, k)) {
                        given_up += 1;
                    }
                }
                _ => {}
            }
        }
    }
    given_up
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_planned_hand_run_never_held_counts_as_given_up_once_walked_past() {
        let feet = [true, true, false, false];
        let left = [true, true, true, false];
        let right = [true, true, false, true];
        // Left held in stances 1-2, right planned in 4-5, left again in 7.
        let contacts = [feet, left, left, feet, right, right, feet, left];
        let mut held = vec![[false; 2]; 8];
        held[2][0] = true;
        // The right run was never held, the last left one neither.
        assert_eq!(reaches_given_up(&contacts, &held, 7), 2);
        // A walk that stopped in the right run has not given it up (yet).
        assert_eq!(reaches_given_up(&contacts, &held, 4), 0);
        assert_eq!(reaches_given_up(&contacts, &held, 5), 1);
        // Held in one stance of each run: none given up.
        held[5][1] = true;
        held[7][0] = true;
        assert_eq!(reaches_given_up(&contacts, &held, 7), 0);
        // No telemetry at all: every run walked past counts.
        assert_eq!(reaches_given_up(&contacts, &[], 7), 3);
    }

    fn state(seq: u64, right_hand_z: f64) -> SimTruth {
        SimTruth {
            seq,
            timestamp_ns: seq * 1000,
            hand_forces: [[0.0; 3], [0.0, 0.0, right_hand_z]],
            ..SimTruth::ZERO
        }
    }

    #[test]
    fn the_share_averages_the_palm_forces_while_a_hand_is_held_through_a_transition() {
        let feet = [true, true, false, false];
        let held = [true, true, false, true];
        // Stance 1 grasps, stance 2 holds on, stance 3 lets go.
        let contacts = [feet, held, held, feet];
        let states: Vec<_> = (1..=4).map(|seq| state(seq, 100.0 * seq as f64)).collect();
        // Towards stance 1 (reaching): not counted; towards 2: 200 N and 300 N; towards 3: no.
        let statuses = [(1, 1000), (2, 2000), (2, 3000), (3, 4000)];
        let share = support_share(&contacts, statuses, &states, 1000.0).unwrap();
        assert!((share - 0.25).abs() < 1e-12, "{share}");
    }

    #[test]
    fn the_asked_share_averages_the_force_asked_over_the_planned_held_stances() {
        let (feet, right) = ([true, true, false, false], [true, true, false, true]);
        // Stance 1 reaches for the rail (not yet meant to carry), stances 2 and 3 hold it.
        let contacts = [feet, right, right, right, feet];
        let asked = |sum_n, ticks| AskedForce { sum_n, ticks };
        let per_stance = [
            asked(0.0, 0),
            asked(50.0, 5),
            asked(300.0, 2),
            asked(500.0, 2),
        ];
        let share = asked_share(&contacts, &per_stance, 100.0).unwrap();
        assert!((share - 2.0).abs() < 1e-12, "{share}");
        assert_eq!(asked_share(&contacts, &per_stance[..2], 100.0), None);
    }

    #[test]
    fn a_hand_the_first_stance_holds_is_reached_from_the_standing_start() {
        let (feet, left) = ([true, true, false, false], [true, true, true, false]);
        let contacts = [left, left, feet];
        assert!(!hand_planned_held(&contacts, 0));
        assert!(hand_planned_held(&contacts, 1));
        assert!(!hand_planned_held(&contacts, 2));
        assert!(!hand_planned_held(&[], 1));
    }

    #[test]
    fn without_a_held_hand_there_is_no_share() {
        let feet = [true, true, false, false];
        let states = [state(1, 50.0)];
        assert_eq!(
            support_share(&[feet, feet], [(1, 1000)], &states, 1000.0),
            None
        );
        assert_eq!(support_share(&[], [(1, 1000)], &states, 1000.0), None);
    }
}
