//! The phases of one transition `S_i → S_{i+1}`, derived from which contacts are made and broken.
//!
//! Contacts are added before any is released, so support never shrinks before the new one is
//! confirmed: for an added foot `Swing` (to just above the contact) then `Lower`; for an added
//! hand `Reach`; for a released foot `ShiftCom` (over the remaining support), `Unload`, `Lift`,
//! `Swing` (to the stance's swing pose). A released hand is unloaded (`Unload`: its load handed
//! back to the feet, `hand_support`) and let go before a foot is released. A transition with no foot released re-centres the CoM.
//! The last transition ends with `Settle`.

use kinematics::robot::EndEffector;

use super::status::Phase;

/// Most steps a transition can have (two feet, two hands, settle).
const MAX_STEPS: usize = 10;

/// One phase and the end-effector it moves (none for CoM-only phases).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Step {
    pub phase: Phase,
    pub end_effector: Option<EndEffector>,
}

/// The ordered steps of one transition (fixed capacity, built on the real-time path).
#[derive(Clone, Copy, Debug)]
pub(crate) struct TransitionPlan {
    steps: [Step; MAX_STEPS],
    len: usize,
}

impl TransitionPlan {
    /// The plan from the live contact set `live` to the stance contact flags `next`.
    pub fn new(live: [bool; 4], next: [bool; 4], is_last: bool) -> Self {
        let mut plan = Self::empty();
        let added = |e: EndEffector| next[e as usize] && !live[e as usize];
        let released = |e: EndEffector| live[e as usize] && !next[e as usize];
        for e in EndEffector::ALL {
            if added(e) && e.is_foot() {
                plan.push(Phase::Swing, Some(e));
                plan.push(Phase::Lower, Some(e));
            } else if added(e) {
                plan.push(Phase::Reach, Some(e));
            }
        }
        for hand in EndEffector::HANDS {
            if released(hand) {
                plan.push(Phase::Unload, Some(hand));
            }
        }
        let mut foot_released = false;
        for e in [EndEffector::LeftFoot, EndEffector::RightFoot] {
            if released(e) {
                foot_released = true;
                plan.push(Phase::ShiftCom, Some(e));
                plan.push(Phase::Unload, Some(e));
                plan.push(Phase::Lift, Some(e));
                plan.push(Phase::Swing, Some(e));
            }
        }
        if !foot_released && !is_last {
            plan.push(Phase::ShiftCom, None);
        }
        if is_last {
            plan.push(Phase::Settle, None);
        }
        plan
    }

    /// A catch (`StateMachine::catch_swing_foot`): `foot` brought down over the ground, then
    /// lowered until it touches down.
    pub fn catch(foot: EndEffector) -> Self {
        let mut plan = Self::empty();
        plan.push(Phase::Swing, Some(foot));
        plan.push(Phase::Lower, Some(foot));
        plan
    }

    /// A step taken back (`StateMachine::take_step_back`): `foot` lifted clear, swung back over
    /// where it lifted off, then lowered until it touches down.
    pub fn step_back(foot: EndEffector) -> Self {
        let mut plan = Self::empty();
        plan.push(Phase::Lift, Some(foot));
        plan.push(Phase::Swing, Some(foot));
        plan.push(Phase::Lower, Some(foot));
        plan
    }

    fn empty() -> Self {
        Self {
            steps: [Step {
                phase: Phase::None,
                end_effector: None,
            }; MAX_STEPS],
            len: 0,
        }
    }

    fn push(&mut self, phase: Phase, end_effector: Option<EndEffector>) {
        self.steps[self.len] = Step {
            phase,
            end_effector,
        };
        self.len += 1;
    }

    /// The steps in order.
    pub fn steps(&self) -> &[Step] {
        &self.steps[..self.len]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Contact sets (left foot, right foot, left hand, right hand).
    const BOTH_FEET: [bool; 4] = [true, true, false, false];
    const LEFT_FOOT: [bool; 4] = [true, false, false, false];
    const RIGHT_FOOT_LEFT_HAND: [bool; 4] = [false, true, true, false];

    /// The plan from `live` to `next` (the last stance if `is_last`) and its phases in order.
    fn plan(live: [bool; 4], next: [bool; 4], is_last: bool) -> (TransitionPlan, Vec<Phase>) {
        let plan = TransitionPlan::new(live, next, is_last);
        let phases = plan.steps().iter().map(|s| s.phase).collect();
        (plan, phases)
    }

    #[test]
    fn double_to_single_support_releases_the_foot_after_shifting_the_com() {
        let (plan, phases) = plan(BOTH_FEET, LEFT_FOOT, false);
        assert_eq!(
            phases,
            [Phase::ShiftCom, Phase::Unload, Phase::Lift, Phase::Swing]
        );
        assert!(
            plan.steps()
                .iter()
                .all(|s| s.end_effector == Some(EndEffector::RightFoot))
        );
    }

    #[test]
    fn a_released_hand_is_unloaded_before_a_foot_is_released() {
        const BOTH_FEET_RIGHT_HAND: [bool; 4] = [true, true, false, true];
        let (plan, phases) = plan(BOTH_FEET_RIGHT_HAND, LEFT_FOOT, false);
        assert_eq!(
            phases,
            [
                Phase::Unload,
                Phase::ShiftCom,
                Phase::Unload,
                Phase::Lift,
                Phase::Swing
            ]
        );
        assert_eq!(plan.steps()[0].end_effector, Some(EndEffector::RightHand));
        assert_eq!(plan.steps()[2].end_effector, Some(EndEffector::RightFoot));
    }

    /// A put-down plan's (phase, end-effector) pairs in order.
    fn moves(plan: &TransitionPlan) -> Vec<(Phase, Option<EndEffector>)> {
        plan.steps()
            .iter()
            .map(|s| (s.phase, s.end_effector))
            .collect()
    }

    #[test]
    fn a_catch_brings_the_foot_over_the_ground_then_lowers_it() {
        let foot = Some(EndEffector::RightFoot);
        assert_eq!(
            moves(&TransitionPlan::catch(EndEffector::RightFoot)),
            [(Phase::Swing, foot), (Phase::Lower, foot)]
        );
    }

    #[test]
    fn a_step_taken_back_lifts_swings_and_lowers_the_foot() {
        let foot = Some(EndEffector::LeftFoot);
        assert_eq!(
            moves(&TransitionPlan::step_back(EndEffector::LeftFoot)),
            [
                (Phase::Lift, foot),
                (Phase::Swing, foot),
                (Phase::Lower, foot)
            ]
        );
    }

    #[test]
    fn contacts_are_added_before_any_is_released() {
        let (_, phases) = plan(LEFT_FOOT, RIGHT_FOOT_LEFT_HAND, true);
        assert_eq!(
            phases,
            [
                Phase::Swing,
                Phase::Lower,
                Phase::Reach,
                Phase::ShiftCom,
                Phase::Unload,
                Phase::Lift,
                Phase::Swing,
                Phase::Settle
            ]
        );
    }
}
