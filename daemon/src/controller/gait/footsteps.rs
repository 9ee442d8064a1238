//! The footstep plan: a sequence's foot-contact changes as timed support phases.
//!
//! Walking the stances in order from both feet standing, every change of the feet in contact
//! becomes phases:
//! - a foot released (double → single support): a double-support phase (the ZMP crosses to the
//!   foot that stays), at whose end the foot lifts off; it lasts `double_support_s`, the first
//!   one `initial_double_support_s`, so the CoM can start from rest, and one next to a step up
//!   or down (after its touchdown or before its lift-off) `step_double_support_s`, next to a
//!   stair climbed (level soles) with no other step on its other side `climb_double_support_s`,
//!   and between stairs taken past the other foot (one foot per stair, up or down)
//!   `past_double_support_s`;
//! - a foot added (single → double support): the single-support phase in which it swings, from
//!   lift-off through the highest post-processed swing pose of its flight to its contact pose;
//!   it lasts `single_support_s` (a stair climbed: `climb_single_support_s`, past the other
//!   foot, one foot per stair: `climb_past_single_support_s`, no shorter than its riser at
//!   `climb_past_speed`; a stair descended past the other foot: `descent_past_single_support_s`,
//!   no shorter than its riser at `descent_past_speed`; any other step up or down:
//!   `step_single_support_s`, down no shorter than its drop at `step_down_speed`);
//! - a foot added and the other released at once (single support on one foot, then on the
//!   other): that swing, then a double support of `double_support_s` before the lift-off;
//! - only hands change: a double support of `hand_transition_s` while they reach;
//! - nothing changes (repeated stances, or a swing passing another swing pose): no phase.
//!
//! A timed sequence sets the pace instead: a double support before a lift-off lasts the summed
//! durations of the stances the walk stood in on both feet since the support's previous phase,
//! a single support those of the stances its foot was in the air, each clamped into
//! `timed_double_support_s` / `timed_single_support_s` (the first lift-off, a step up or down
//! and the double support next to it no shorter than their configured durations). A span with
//! an untimed stance, and every other phase, keeps the configured duration; each phase records
//! where its duration came from ([`PhaseTiming`]).
//!
//! The walk ends with `final_double_support_s` of double support after the last touchdown; a
//! sequence ending with a foot in the air is refused. The phases of each stance form a
//! [`Transition`]: its posture is the reference and its hands reach within it.

use std::ops::Range;

use kinematics::robot::EndEffector;
use nalgebra::{Isometry3, Vector3};

use super::config::DynamicGaitConfig;
use crate::controller::machine::STEP_HEIGHT_M;
use crate::controller::sequence::{PreparedStance, Refusal};
use crate::controller::status::PhaseTiming;

/// The feet, in the order of the `[_; 2]` arrays of this module (left, right).
pub(crate) const FEET: [EndEffector; 2] = [EndEffector::LeftFoot, EndEffector::RightFoot];

/// A swing as planned (sequence frame): the pose it passes at mid-swing and where it lands.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct SwingPlan {
    /// The swinging foot.
    pub foot: EndEffector,
    /// The post-processed swing pose: its height is the apex, its orientation the foot's there.
    pub apex: Isometry3<f64>,
    /// The contact pose of the stance it lands in.
    pub landing: Isometry3<f64>,
}

/// Which feet carry the robot during a phase.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Support {
    /// Both feet on the ground; `lift_off` leaves it at the phase's end.
    Double { lift_off: Option<EndEffector> },
    /// One foot on the ground while the other swings to its landing, at the phase's end.
    Single(SwingPlan),
}

/// One timed phase of the plan.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct SupportPhase {
    /// What carries the robot.
    pub support: Support,
    /// Start on the plan clock (s).
    pub start_s: f64,
    /// Duration (s).
    pub duration_s: f64,
    /// Planned sole poses of the feet on the ground (left, right; `None` in the air).
    pub feet: [Option<Isometry3<f64>>; 2],
    /// Where `duration_s` came from: the config or the sequence's stance durations.
    pub timing: PhaseTiming,
}

impl SupportPhase {
    /// End on the plan clock (s).
    pub fn end_s(&self) -> f64 {
        self.start_s + self.duration_s
    }
}

/// The phases that lead to one stance: within them its hands reach, and its posture is the
/// posture reference.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Transition {
    /// Index of the stance.
    pub stance: usize,
    /// Its phases, indices into [`FootstepPlan::phases`].
    pub phases: Range<usize>,
}

/// The timed phases of a sequence and their grouping by stance.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct FootstepPlan {
    /// Back to back from the plan clock's zero.
    pub phases: Vec<SupportPhase>,
    /// In stance order; stances without any change have none.
    pub transitions: Vec<Transition>,
}

/// Builds the plan while walking the stances.
struct Builder<'a> {
    timing: &'a DynamicGaitConfig,
    plan: FootstepPlan,
    clock: f64,
    /// Planned poses of the feet on the ground.
    feet: [Option<Isometry3<f64>>; 2],
    /// The swing under way: its foot, the highest swing pose so far and its lift-off pose.
    swing: Option<(EndEffector, Isometry3<f64>, Isometry3<f64>)>,
    stepped: bool,
    /// How the last touchdown's swing changed height.
    after_step: Rise,
    /// The sequence's time in the current support since its previous phase.
    dwell: Dwell,
}

/// How long the sequence stays in the stances of a span, as far as it says.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Dwell {
    /// No stance in the span.
    Empty,
    /// Every stance of the span is timed: their summed durations (s).
    Timed(f64),
    /// A stance of the span is untimed.
    Untimed,
}

impl Dwell {
    /// The span with one more stance, of duration `duration_s`.
    fn and(self, duration_s: Option<f64>) -> Self {
        match (self, duration_s) {
            (Self::Untimed, _) | (_, None) => Self::Untimed,
            (Self::Empty, Some(duration)) => Self::Timed(duration),
            (Self::Timed(sum), Some(duration)) => Self::Timed(sum + duration),
        }
    }
}

impl FootstepPlan {
    /// The plan of `stances` for a robot standing on both feet at `standing` (left, right sole
    /// poses in the sequence's frame).
    pub fn new(
        stances: &[PreparedStance],
        standing: [Isometry3<f64>; 2],
        timing: &DynamicGaitConfig,
    ) -> Result<Self, Refusal> {
        let mut builder = Builder {
            timing,
            plan: FootstepPlan {
                phases: Vec::with_capacity(2 * stances.len() + 1),
                transitions: Vec::with_capacity(stances.len()),
            },
            clock: 0.0,
            feet: standing.map(Some),
            swing: None,
            stepped: false,
            after_step: Rise::Level,
            dwell: Dwell::Empty,
        };
        let mut hands = [false; 2];
        for (i, stance) in stances.iter().enumerate() {
            let first_phase = builder.plan.phases.len();
            let next_hands = [
                stance.contacts[EndEffector::LeftHand as usize],
                stance.contacts[EndEffector::RightHand as usize],
            ];
            builder.stance(stance, &stances[i + 1..], next_hands != hands);
            hands = next_hands;
            let phases = first_phase..builder.plan.phases.len();
            if !phases.is_empty() {
                builder
                    .plan
                    .transitions
                    .push(Transition { stance: i, phases });
            }
        }
        if builder.swing.is_some() {
            return Err(Refusal(format!(
                "stance {}: the dynamic gait comes to rest on both feet, but the sequence ends \
                 with a foot in the air",
                stances.len() - 1
            )));
        }
        let last = builder.plan.phases.len();
        builder.double_support(
            (timing.final_double_support_s, PhaseTiming::Configured),
            None,
        );
        match builder.plan.transitions.last_mut() {
            Some(transition) if transition.stance == stances.len() - 1 => {
                transition.phases.end = last + 1;
            }
            _ => builder.plan.transitions.push(Transition {
                stance: stances.len() - 1,
                phases: last..last + 1,
            }),
        }
        Ok(builder.plan)
    }

    /// Ends the plan with phase `current` of transition `transition` (a controlled stop) and
    /// returns the final double support: after a single support, its swing lands as planned and
    /// both feet then carry the robot for `duration_s`; in a double support (at plan time
    /// `now_s`) no foot lifts off and it lasts until `now_s + duration_s`. The current transition
    /// becomes the last, so its stance stays the posture reference. Allocation-free.
    pub fn end_early(
        &mut self,
        current: usize,
        transition: usize,
        now_s: f64,
        duration_s: f64,
    ) -> SupportPhase {
        let phase = self.phases[current];
        self.phases.truncate(current + 1);
        let last = match phase.support {
            Support::Single(swing) => {
                let mut feet = phase.feet;
                feet[slot(swing.foot)] = Some(swing.landing);
                let last = SupportPhase {
                    support: Support::Double { lift_off: None },
                    start_s: phase.end_s(),
                    duration_s,
                    feet,
                    timing: PhaseTiming::Configured,
                };
                self.phases.push(last);
                last
            }
            Support::Double { .. } => {
                let last = SupportPhase {
                    support: Support::Double { lift_off: None },
                    duration_s: now_s + duration_s - phase.start_s,
                    timing: PhaseTiming::Configured,
                    ..phase
                };
                self.phases[current] = last;
                last
            }
        };
        self.transitions.truncate(transition + 1);
        if let Some(ending) = self.transitions.last_mut() {
            ending.phases.end = self.phases.len();
        }
        last
    }

    /// Planned duration of the whole walk (s).
    #[cfg(test)]
    pub fn duration_s(&self) -> f64 {
        self.phases.last().map_or(0.0, SupportPhase::end_s)
    }
}

impl Builder<'_> {
    /// Adds the phases that lead from the current support to `stance`'s; `upcoming` are the
    /// stances after it.
    fn stance(&mut self, stance: &PreparedStance, upcoming: &[PreparedStance], hands_change: bool) {
        let in_contact = FEET.map(|f| stance.contacts[f as usize]);
        let added = [0, 1].map(|f| in_contact[f] && self.feet[f].is_none());
        let released = [0, 1].map(|f| !in_contact[f] && self.feet[f].is_some());
        if let Some((foot, apex, _)) = &mut self.swing {
            let candidate = stance.targets[*foot as usize];
            if !in_contact[slot(*foot)] && candidate.translation.z > apex.translation.z {
                *apex = candidate;
            }
        }
        for f in 0..2 {
            if added[f] {
                self.touchdown(FEET[f], stance.targets[FEET[f] as usize]);
            }
        }
        for f in 0..2 {
            if released[f] {
                let lift_off = self.feet[f].unwrap_or_else(Isometry3::identity);
                let standing = self.feet[1 - f];
                let step_ahead = upcoming
                    .iter()
                    .find(|s| s.contacts[FEET[f] as usize])
                    .map_or(Rise::Level, |s| {
                        Rise::of(&lift_off, &s.targets[FEET[f] as usize], standing.as_ref())
                    });
                let duration = self.lift_off_double_support(step_ahead);
                self.double_support(duration, Some(FEET[f]));
                self.feet[f] = None;
                self.swing = Some((FEET[f], stance.targets[FEET[f] as usize], lift_off));
            }
        }
        let feet_change = added.iter().chain(&released).any(|c| *c);
        if hands_change && !feet_change && self.swing.is_none() {
            // The configured reach stands for the stances before it.
            self.dwell = Dwell::Empty;
            self.double_support(
                (self.timing.hand_transition_s, PhaseTiming::Configured),
                None,
            );
        }
        self.dwell = self.dwell.and(stance.duration_s);
    }

    /// The double support that ends with a lift-off: the stances on both feet since the
    /// support's previous phase, if all timed, else `double_support_s`; the first lift-off from
    /// standing no shorter than `initial_double_support_s` (the CoM starts from rest), and one
    /// after a step up or down or before one (`step_ahead`) no shorter than
    /// `past_double_support()` when each is level or a stair taken past the other foot (up or
    /// down), or the step ahead is a stair climbed past it after one climbed beside it,
    /// `climb_double_support()` when each is level or a stair climbed (past the other foot or
    /// not), else `step_double_support()`.
    fn lift_off_double_support(&mut self, step_ahead: Rise) -> (f64, PhaseTiming) {
        let limits = self.timing.timed_double_support();
        let dwell = std::mem::replace(&mut self.dwell, Dwell::Empty);
        let sides = [step_ahead, self.after_step];
        if self.stepped && sides.iter().any(|r| *r != Rise::Level) {
            let step = if sides.contains(&Rise::Step) {
                self.timing.step_double_support()
            } else if sides.contains(&Rise::Stair) && step_ahead != Rise::ClimbPast {
                self.timing.climb_double_support()
            } else {
                self.timing.past_double_support()
            };
            timed(dwell, step, limits, step)
        } else if self.stepped {
            timed(dwell, self.timing.double_support_s, limits, 0.0)
        } else {
            let initial = self.timing.initial_double_support_s;
            timed(dwell, initial, limits, initial)
        }
    }

    /// The single support of a swing from `lift_off` to `landing` while the other foot stands
    /// at `standing`: the stances its foot was in the air, if all timed, else
    /// `single_support_s`; a stair climbed no shorter than `climb_single_support()` (past the
    /// standing foot, one foot per stair: `climb_past_single_support()` of its riser), a stair
    /// descended past it no shorter than `descent_past_single_support()` of its riser, any other
    /// step up or down no shorter than `step_single_support()` (down, than
    /// `step_down_single_support()` of its drop).
    fn swing_single_support(
        &mut self,
        lift_off: &Isometry3<f64>,
        landing: &Isometry3<f64>,
        standing: Option<&Isometry3<f64>>,
    ) -> (f64, PhaseTiming) {
        let limits = self.timing.timed_single_support();
        let dwell = std::mem::replace(&mut self.dwell, Dwell::Empty);
        // A stair taken past the standing foot: its riser is the landing's height above that
        // sole (a past stair has one: `standing` is set).
        let riser = standing.map_or(0.0, |s| (landing.translation.z - s.translation.z).abs());
        let step = match Rise::of(lift_off, landing, standing) {
            Rise::Level => return timed(dwell, self.timing.single_support_s, limits, 0.0),
            Rise::ClimbPast => self.timing.climb_past_single_support(riser),
            Rise::Stair => self.timing.climb_single_support(),
            Rise::DescentPast => self.timing.descent_past_single_support(riser),
            Rise::Step => {
                let drop = lift_off.translation.z - landing.translation.z;
                self.timing.step_down_single_support(drop)
            }
        };
        timed(dwell, step, limits, step)
    }

    /// The single support in which the swing under way lands `foot` at `landing`.
    fn touchdown(&mut self, foot: EndEffector, landing: Isometry3<f64>) {
        let (swinging, apex, lift_off) = self
            .swing
            .take()
            .expect("a foot is added only while it is in the air");
        debug_assert_eq!(swinging, foot);
        let standing = self.feet[1 - slot(foot)];
        let duration = self.swing_single_support(&lift_off, &landing, standing.as_ref());
        self.push(
            Support::Single(SwingPlan {
                foot,
                apex,
                landing,
            }),
            duration,
        );
        self.feet[slot(foot)] = Some(landing);
        self.stepped = true;
        self.after_step = Rise::of(&lift_off, &landing, standing.as_ref());
    }

    fn double_support(&mut self, duration: (f64, PhaseTiming), lift_off: Option<EndEffector>) {
        self.push(Support::Double { lift_off }, duration);
    }

    fn push(&mut self, support: Support, (duration_s, timing): (f64, PhaseTiming)) {
        self.plan.phases.push(SupportPhase {
            support,
            start_s: self.clock,
            duration_s,
            feet: self.feet,
            timing,
        });
        self.clock += duration_s;
    }
}

/// A phase's duration and its source: `configured` unless every stance of its span is timed
/// (`dwell`); then their sum clamped into `[min, max]` and raised to `floor` (0: none), marked
/// [`PhaseTiming::Clamped`] when that changed it.
fn timed(dwell: Dwell, configured: f64, [min, max]: [f64; 2], floor: f64) -> (f64, PhaseTiming) {
    let Dwell::Timed(sum) = dwell else {
        return (configured, PhaseTiming::Configured);
    };
    let planned = sum.clamp(min, max).max(floor);
    if planned == sum {
        (planned, PhaseTiming::Sequence)
    } else {
        (planned, PhaseTiming::Clamped)
    }
}

/// How a swing changes height.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Rise {
    /// Its heights differ by no more than [`STEP_HEIGHT_M`].
    Level,
    /// Up from a level sole to a level sole: a stair climbed (`climb_*` timing).
    Stair,
    /// A stair climbed past the foot standing: from below it to above it, one foot per stair
    /// (`climb_past_single_support_s`, `past_double_support_s`).
    ClimbPast,
    /// A stair descended past the foot standing: from above it to below it, level soles, one
    /// foot per stair (`descent_past_single_support_s`, `past_double_support_s`).
    DescentPast,
    /// Any other step: down, or up or onto a slope (`step_*` timing).
    Step,
}

/// A sole tilted less than this from horizontal is level (rad): a stair's tread, not a ramp.
const LEVEL_SOLE_RAD: f64 = 0.02;

impl Rise {
    /// A swing from `lift_off` landing at `landing` while the other foot stands at `standing`.
    fn of(
        lift_off: &Isometry3<f64>,
        landing: &Isometry3<f64>,
        standing: Option<&Isometry3<f64>>,
    ) -> Self {
        let rise = landing.translation.z - lift_off.translation.z;
        let level = |pose: &Isometry3<f64>| {
            (pose.rotation * Vector3::z()).angle(&Vector3::z()) < LEVEL_SOLE_RAD
        };
        let past = standing.is_some_and(|s| passes(lift_off, landing, s));
        if rise.abs() <= STEP_HEIGHT_M {
            Self::Level
        } else if !(level(lift_off) && level(landing)) {
            Self::Step
        } else if rise > 0.0 {
            if past { Self::ClimbPast } else { Self::Stair }
        } else if past {
            Self::DescentPast
        } else {
            Self::Step
        }
    }
}

/// Whether a swing from `lift_off` to `landing` passes the foot standing at `standing`, one foot
/// per stair: the standing sole is more than [`STEP_HEIGHT_M`] above one end and below the other.
fn passes(lift_off: &Isometry3<f64>, landing: &Isometry3<f64>, standing: &Isometry3<f64>) -> bool {
    let height = standing.translation.z;
    let (a, b) = (lift_off.translation.z, landing.translation.z);
    a.min(b) < height - STEP_HEIGHT_M && a.max(b) > height + STEP_HEIGHT_M
}

/// Index of a foot in the `[_; 2]` arrays.
fn slot(foot: EndEffector) -> usize {
    match foot {
        EndEffector::LeftFoot => 0,
        EndEffector::RightFoot => 1,
        hand => unreachable!("{hand:?} is not a foot"),
    }
}

#[cfg(test)]
mod tests {
    use nalgebra::{DVector, Translation3};

    use super::*;
    use crate::controller::gait::config::CLIMB_DOUBLE_SUPPORT_FACTOR;

    const LF: usize = EndEffector::LeftFoot as usize;
    const RF: usize = EndEffector::RightFoot as usize;
    const LH: usize = EndEffector::LeftHand as usize;

    fn at(x: f64, y: f64, z: f64) -> Isometry3<f64> {
        Isometry3::from_parts(Translation3::new(x, y, z), Default::default())
    }

    fn stance(contacts: [bool; 4], left: Isometry3<f64>, right: Isometry3<f64>) -> PreparedStance {
        let mut targets = [Isometry3::identity(); 4];
        targets[LF] = left;
        targets[RF] = right;
        PreparedStance {
            posture: DVector::zeros(1),
            contacts,
            targets,
            duration_s: None,
        }
    }

    const DS: [bool; 4] = [true, true, false, false];
    const LEFT_UP: [bool; 4] = [false, true, false, false];
    const RIGHT_UP: [bool; 4] = [true, false, false, false];

    fn standing() -> [Isometry3<f64>; 2] {
        [at(0.0, 0.1, 0.0), at(0.0, -0.1, 0.0)]
    }

    /// The durations of the plan's single supports (`single`) or double supports.
    fn durations(plan: &FootstepPlan, single: bool) -> Vec<f64> {
        plan.phases
            .iter()
            .filter(|p| matches!(p.support, Support::Single(_)) == single)
            .map(|p| p.duration_s)
            .collect()
    }

    fn kinds(plan: &FootstepPlan) -> Vec<&'static str> {
        plan.phases
            .iter()
            .map(|p| match p.support {
                Support::Double { lift_off: None } => "ds",
                Support::Double { lift_off: Some(_) } => "ds+lift",
                Support::Single(_) => "ss",
            })
            .collect()
    }

    #[test]
    fn a_stair_climbed_takes_the_climb_single_support() {
        let timing = DynamicGaitConfig::default();
        let stances = [
            stance(DS, standing()[0], standing()[1]),
            stance(LEFT_UP, at(0.15, 0.1, 0.13), standing()[1]),
            stance(DS, at(0.3, 0.1, 0.1), standing()[1]),
            stance(RIGHT_UP, at(0.3, 0.1, 0.1), at(0.15, -0.1, 0.04)),
            stance(DS, at(0.3, 0.1, 0.1), at(0.3, -0.1, 0.005)),
        ];
        let plan = FootstepPlan::new(&stances, standing(), &timing).unwrap();
        let singles = durations(&plan, true);
        // The left foot up 0.10 m: a stair; the right up 0.005 m: a flat step (its swing pose's
        // height does not count).
        assert_eq!(
            singles,
            [timing.climb_single_support(), timing.single_support_s]
        );
        assert!(timing.climb_single_support() > timing.single_support_s);
    }

    /// One foot per stair of `riser` (m; negative: down): the left onto the first tread, beside
    /// the right; then each foot from the tread beyond the other's to the one past it. Each
    /// swing's apex is 3 cm above the higher of its ends.
    fn one_foot_per_stair(riser: f64) -> [PreparedStance; 7] {
        let apex = |a: f64, b: f64| a.max(b) + 0.03;
        [
            stance(DS, standing()[0], standing()[1]),
            stance(LEFT_UP, at(0.15, 0.1, apex(0.0, riser)), standing()[1]),
            stance(DS, at(0.3, 0.1, riser), standing()[1]),
            stance(
                RIGHT_UP,
                at(0.3, 0.1, riser),
                at(0.3, -0.1, apex(0.0, 2.0 * riser)),
            ),
            stance(DS, at(0.3, 0.1, riser), at(0.6, -0.1, 2.0 * riser)),
            stance(
                LEFT_UP,
                at(0.6, 0.1, apex(riser, 3.0 * riser)),
                at(0.6, -0.1, 2.0 * riser),
            ),
            stance(DS, at(0.9, 0.1, 3.0 * riser), at(0.6, -0.1, 2.0 * riser)),
        ]
    }

    /// The double supports of [`one_foot_per_stair`]'s plan: the first lift-off's, the one
    /// `beside` the first stair (taken next to the other foot), then between two stairs taken past
    /// the other foot, and the final rest.
    fn past_doubles(timing: &DynamicGaitConfig, beside: f64) -> [f64; 4] {
        [
            timing.initial_double_support_s,
            beside,
            timing.past_double_support(),
            timing.final_double_support_s,
        ]
    }

    #[test]
    fn a_stair_climbed_past_the_other_foot_takes_the_past_supports() {
        let timing = DynamicGaitConfig::default();
        let plan = FootstepPlan::new(&one_foot_per_stair(0.1), standing(), &timing).unwrap();
        let past = timing.climb_past_single_support(0.1);
        assert_eq!(
            durations(&plan, true),
            [timing.climb_single_support(), past, past]
        );
        assert!(past > timing.climb_single_support());
        // A 0.10 m riser at `climb_past_speed` would be quicker: the configured duration holds.
        assert_eq!(past, timing.climb_past_single_support(0.0));
        // The double support before the first stair climbed past the other foot is a past one
        // too: its feet stand one riser apart, as between any two.
        assert_eq!(
            durations(&plan, false),
            past_doubles(&timing, timing.past_double_support())
        );
        assert!(timing.past_double_support() < timing.climb_double_support());
    }

    #[test]
    fn a_stair_descended_past_the_other_foot_takes_the_past_supports() {
        let timing = DynamicGaitConfig::default();
        let plan = FootstepPlan::new(&one_foot_per_stair(-0.1), standing(), &timing).unwrap();
        let (step, past) = (
            timing.step_single_support(),
            timing.descent_past_single_support(0.1),
        );
        assert_eq!(durations(&plan, true), [step, past, past]);
        assert!(past < step);
        assert_eq!(past, timing.descent_past_single_support(0.0));
        assert_eq!(
            durations(&plan, false),
            past_doubles(&timing, timing.step_double_support())
        );
        assert!(timing.past_double_support() < timing.step_double_support());
    }

    #[test]
    fn a_high_stair_taken_past_the_other_foot_lasts_its_riser_at_the_past_speed() {
        let timing = DynamicGaitConfig::default();
        let riser = 0.15;
        let up = FootstepPlan::new(&one_foot_per_stair(riser), standing(), &timing).unwrap();
        let climb = riser / timing.climb_past_speed;
        assert!(climb > timing.climb_past_single_support(0.0));
        assert_close(
            &durations(&up, true),
            &[timing.climb_single_support(), climb, climb],
        );
        let down = FootstepPlan::new(&one_foot_per_stair(-riser), standing(), &timing).unwrap();
        let descent = riser / timing.descent_past_speed;
        assert!(descent > timing.descent_past_single_support(0.0));
        assert_close(
            &durations(&down, true),
            &[timing.step_down_single_support(riser), descent, descent],
        );
    }

    /// `actual` and `expected` agree to rounding (the risers are differences of heights).
    fn assert_close(actual: &[f64], expected: &[f64]) {
        assert_eq!(actual.len(), expected.len(), "{actual:?} {expected:?}");
        let close = actual
            .iter()
            .zip(expected)
            .all(|(a, e)| (a - e).abs() < 1e-9);
        assert!(close, "{actual:?} {expected:?}");
    }

    #[test]
    fn a_step_down_or_up_a_slope_takes_the_step_timing() {
        let timing = DynamicGaitConfig::default();
        let pitched = |x: f64, y: f64, z: f64| {
            Isometry3::new(
                nalgebra::Vector3::new(x, y, z),
                nalgebra::Vector3::y() * -0.17,
            )
        };
        let stances = [
            stance(DS, standing()[0], standing()[1]),
            // Left down 0.10 m, then right up 0.05 m onto a 10 degree slope.
            stance(LEFT_UP, at(0.15, 0.1, 0.0), standing()[1]),
            stance(DS, at(0.3, 0.1, -0.1), standing()[1]),
            stance(RIGHT_UP, at(0.3, 0.1, -0.1), at(0.15, -0.1, 0.1)),
            stance(DS, at(0.3, 0.1, -0.1), pitched(0.3, -0.1, 0.05)),
        ];
        let plan = FootstepPlan::new(&stances, standing(), &timing).unwrap();
        let step = timing.step_single_support();
        assert_eq!(durations(&plan, true), [step, step]);
        let step = timing.step_double_support();
        assert_eq!(
            durations(&plan, false),
            [
                timing.initial_double_support_s,
                step,
                timing.final_double_support_s
            ]
        );
        assert!(timing.step_single_support() > timing.climb_single_support());
    }

    #[test]
    fn a_deep_step_down_lowers_the_body_no_faster_than_the_step_down_speed() {
        let timing = DynamicGaitConfig::default();
        let drop = 0.185;
        let stances = [
            stance(DS, standing()[0], standing()[1]),
            stance(LEFT_UP, at(0.15, 0.1, 0.0), standing()[1]),
            stance(DS, at(0.3, 0.1, -drop), standing()[1]),
        ];
        let plan = FootstepPlan::new(&stances, standing(), &timing).unwrap();
        let slow = drop / timing.step_down_speed;
        assert!(slow > timing.step_single_support());
        assert_eq!(durations(&plan, true), [slow]);
    }

    #[test]
    fn a_double_support_next_to_a_step_takes_the_step_double_support() {
        let timing = DynamicGaitConfig::default();
        let stances = [
            stance(DS, standing()[0], standing()[1]),
            // Left: a flat step; right, then left up 0.10 m; right, then left flat again.
            stance(LEFT_UP, at(0.1, 0.1, 0.05), standing()[1]),
            stance(DS, at(0.2, 0.1, 0.0), standing()[1]),
            stance(RIGHT_UP, at(0.2, 0.1, 0.0), at(0.2, -0.1, 0.13)),
            stance(DS, at(0.2, 0.1, 0.0), at(0.4, -0.1, 0.1)),
            stance(LEFT_UP, at(0.4, 0.1, 0.13), at(0.4, -0.1, 0.1)),
            stance(DS, at(0.6, 0.1, 0.1), at(0.4, -0.1, 0.1)),
            stance(RIGHT_UP, at(0.6, 0.1, 0.1), at(0.6, -0.1, 0.13)),
            stance(DS, at(0.6, 0.1, 0.1), at(0.8, -0.1, 0.1)),
            stance(LEFT_UP, at(0.8, 0.1, 0.13), at(0.8, -0.1, 0.1)),
            stance(DS, at(1.0, 0.1, 0.1), at(0.8, -0.1, 0.1)),
        ];
        let plan = FootstepPlan::new(&stances, standing(), &timing).unwrap();
        let doubles = durations(&plan, false);
        let (climb, flat) = (timing.climb_double_support(), timing.double_support_s);
        // The first lift-off from standing; before the right's step up; between the two steps
        // up; after the left's step up; between two flat steps; the final rest.
        assert_eq!(
            doubles,
            [
                timing.initial_double_support_s,
                climb,
                climb,
                climb,
                flat,
                timing.final_double_support_s
            ]
        );
        assert!((climb - CLIMB_DOUBLE_SUPPORT_FACTOR * flat).abs() < 1e-12);
    }

    #[test]
    fn alternating_stances_become_timed_steps() {
        let timing = DynamicGaitConfig::default();
        let stances = [
            stance(DS, standing()[0], standing()[1]),
            stance(LEFT_UP, at(0.1, 0.1, 0.05), standing()[1]),
            stance(DS, at(0.2, 0.1, 0.0), standing()[1]),
            stance(RIGHT_UP, at(0.2, 0.1, 0.0), at(0.2, -0.1, 0.06)),
            stance(DS, at(0.2, 0.1, 0.0), at(0.4, -0.1, 0.0)),
        ];
        let plan = FootstepPlan::new(&stances, standing(), &timing).unwrap();
        assert_eq!(kinds(&plan), ["ds+lift", "ss", "ds+lift", "ss", "ds"]);
        let durations: Vec<f64> = plan.phases.iter().map(|p| p.duration_s).collect();
        assert_eq!(
            durations,
            [
                timing.initial_double_support_s,
                timing.single_support_s,
                timing.double_support_s,
                timing.single_support_s,
                timing.final_double_support_s
            ]
        );
        for pair in plan.phases.windows(2) {
            assert!((pair[0].end_s() - pair[1].start_s).abs() < 1e-12);
        }
        let Support::Single(swing) = plan.phases[1].support else {
            panic!("phase 1 swings");
        };
        assert_eq!(swing.foot, EndEffector::LeftFoot);
        assert_eq!(swing.apex, at(0.1, 0.1, 0.05));
        assert_eq!(swing.landing, at(0.2, 0.1, 0.0));
        assert_eq!(plan.phases[1].feet, [None, Some(standing()[1])]);
        assert_eq!(
            plan.phases[4].feet,
            [Some(at(0.2, 0.1, 0.0)), Some(at(0.4, -0.1, 0.0))]
        );
        let stances_of: Vec<usize> = plan.transitions.iter().map(|t| t.stance).collect();
        assert_eq!(stances_of, [1, 2, 3, 4]);
        assert_eq!(plan.transitions[3].phases, 3..5);
    }

    #[test]
    fn single_support_on_one_foot_then_the_other_gets_a_double_support_between() {
        let timing = DynamicGaitConfig::default();
        let stances = [
            stance(RIGHT_UP, standing()[0], at(0.1, -0.1, 0.05)),
            stance(LEFT_UP, at(0.0, 0.1, 0.05), at(0.2, -0.1, 0.0)),
            stance(DS, at(0.3, 0.1, 0.0), at(0.2, -0.1, 0.0)),
        ];
        let plan = FootstepPlan::new(&stances, standing(), &timing).unwrap();
        assert_eq!(kinds(&plan), ["ds+lift", "ss", "ds+lift", "ss", "ds"]);
        assert_eq!(plan.transitions[1].stance, 1);
        assert_eq!(plan.transitions[1].phases, 1..3);
    }

    #[test]
    fn repeated_stances_add_nothing_and_a_swing_takes_its_highest_pose() {
        let timing = DynamicGaitConfig::default();
        let stances = [
            stance(DS, standing()[0], standing()[1]),
            stance(DS, standing()[0], standing()[1]),
            stance(LEFT_UP, at(0.05, 0.1, 0.04), standing()[1]),
            stance(LEFT_UP, at(0.1, 0.1, 0.07), standing()[1]),
            stance(DS, at(0.2, 0.1, 0.0), standing()[1]),
            stance(DS, at(0.2, 0.1, 0.0), standing()[1]),
        ];
        let plan = FootstepPlan::new(&stances, standing(), &timing).unwrap();
        assert_eq!(kinds(&plan), ["ds+lift", "ss", "ds"]);
        let Support::Single(swing) = plan.phases[1].support else {
            panic!("phase 1 swings");
        };
        assert_eq!(swing.apex, at(0.1, 0.1, 0.07));
        let stances_of: Vec<usize> = plan.transitions.iter().map(|t| t.stance).collect();
        assert_eq!(stances_of, [2, 4, 5]);
    }

    #[test]
    fn hand_only_changes_get_a_reach_phase() {
        let timing = DynamicGaitConfig::default();
        let mut with_hand = DS;
        with_hand[LH] = true;
        let stances = [
            stance(with_hand, standing()[0], standing()[1]),
            stance(DS, standing()[0], standing()[1]),
        ];
        let plan = FootstepPlan::new(&stances, standing(), &timing).unwrap();
        assert_eq!(kinds(&plan), ["ds", "ds", "ds"]);
        assert_eq!(plan.phases[0].duration_s, timing.hand_transition_s);
        assert_eq!(plan.transitions[1].phases, 1..3);
    }

    /// `stance` as a timed stance of `duration_s`.
    fn lasting(duration_s: f64, mut stance: PreparedStance) -> PreparedStance {
        stance.duration_s = Some(duration_s);
        stance
    }

    fn timings(plan: &FootstepPlan) -> Vec<(f64, PhaseTiming)> {
        plan.phases
            .iter()
            .map(|p| (p.duration_s, p.timing))
            .collect()
    }

    /// Two steps, the first swing spanning two stances (durations exact in binary).
    fn timed_walk() -> Vec<PreparedStance> {
        vec![
            lasting(1.5, stance(DS, standing()[0], standing()[1])),
            lasting(0.25, stance(LEFT_UP, at(0.05, 0.1, 0.04), standing()[1])),
            lasting(0.5, stance(LEFT_UP, at(0.1, 0.1, 0.06), standing()[1])),
            lasting(0.125, stance(DS, at(0.2, 0.1, 0.0), standing()[1])),
            lasting(0.25, stance(DS, at(0.2, 0.1, 0.0), standing()[1])),
            lasting(
                0.875,
                stance(RIGHT_UP, at(0.2, 0.1, 0.0), at(0.2, -0.1, 0.06)),
            ),
            lasting(5.0, stance(DS, at(0.2, 0.1, 0.0), at(0.4, -0.1, 0.0))),
        ]
    }

    #[test]
    fn a_timed_sequence_sets_its_supports_to_the_stances_sums() {
        let timing = DynamicGaitConfig {
            timed_single_support_s: Some([0.3, 2.0]),
            timed_double_support_s: Some([0.1, 2.0]),
            ..DynamicGaitConfig::default()
        };
        let plan = FootstepPlan::new(&timed_walk(), standing(), &timing).unwrap();
        assert_eq!(kinds(&plan), ["ds+lift", "ss", "ds+lift", "ss", "ds"]);
        use PhaseTiming::{Configured, Sequence};
        assert_eq!(
            timings(&plan),
            [
                // Standing 1.5 s (above initial_double_support_s, 1.0 s).
                (1.5, Sequence),
                // The left swing through two stances: 0.25 + 0.5 s.
                (0.75, Sequence),
                // Both feet down in two stances: 0.125 + 0.25 s.
                (0.375, Sequence),
                (0.875, Sequence),
                (timing.final_double_support_s, Configured),
            ]
        );
        for pair in plan.phases.windows(2) {
            assert_eq!(pair[0].end_s(), pair[1].start_s);
        }
    }

    #[test]
    fn timed_durations_outside_the_limits_are_clamped() {
        // Default limits: single support [0.55, 1.65] s, double support [0.25, 1.0] s.
        let timing = DynamicGaitConfig::default();
        let stances = [
            lasting(0.5, stance(DS, standing()[0], standing()[1])),
            lasting(0.125, stance(LEFT_UP, at(0.1, 0.1, 0.05), standing()[1])),
            lasting(9.0, stance(DS, at(0.2, 0.1, 0.0), standing()[1])),
            lasting(
                0.75,
                stance(RIGHT_UP, at(0.2, 0.1, 0.0), at(0.2, -0.1, 0.06)),
            ),
            lasting(0.5, stance(DS, at(0.2, 0.1, 0.0), at(0.4, -0.1, 0.0))),
        ];
        let plan = FootstepPlan::new(&stances, standing(), &timing).unwrap();
        use PhaseTiming::{Clamped, Configured, Sequence};
        assert_eq!(
            timings(&plan),
            [
                // The first lift-off: no shorter than initial_double_support_s.
                (timing.initial_double_support_s, Clamped),
                (timing.single_support_s, Clamped),
                (4.0 * timing.double_support_s, Clamped),
                (0.75, Sequence),
                (timing.final_double_support_s, Configured),
            ]
        );
    }

    #[test]
    fn a_timed_stair_climbed_is_no_shorter_than_the_climb_single_support() {
        let timing = DynamicGaitConfig::default();
        let step = |duration_s| {
            let stances = [
                lasting(1.0, stance(DS, standing()[0], standing()[1])),
                lasting(
                    duration_s,
                    stance(LEFT_UP, at(0.15, 0.1, 0.13), standing()[1]),
                ),
                lasting(1.0, stance(DS, at(0.3, 0.1, 0.1), standing()[1])),
            ];
            let plan = FootstepPlan::new(&stances, standing(), &timing).unwrap();
            (plan.phases[1].duration_s, plan.phases[1].timing)
        };
        assert_eq!(
            step(0.6),
            (timing.climb_single_support(), PhaseTiming::Clamped)
        );
        assert_eq!(step(1.5), (1.5, PhaseTiming::Sequence));
    }

    #[test]
    fn an_untimed_sequence_gives_the_configured_plan() {
        let timing = DynamicGaitConfig::default();
        let untimed: Vec<PreparedStance> = timed_walk()
            .into_iter()
            .map(|stance| PreparedStance {
                duration_s: None,
                ..stance
            })
            .collect();
        let plan = FootstepPlan::new(&untimed, standing(), &timing).unwrap();
        let configured = [
            timing.initial_double_support_s,
            timing.single_support_s,
            timing.double_support_s,
            timing.single_support_s,
            timing.final_double_support_s,
        ];
        assert_eq!(
            timings(&plan),
            configured.map(|duration| (duration, PhaseTiming::Configured))
        );
    }

    #[test]
    fn a_partly_timed_span_falls_back_to_the_config() {
        let timing = DynamicGaitConfig::default();
        let mut stances = timed_walk();
        // The second stance of the left swing, and the first of the double support after it.
        stances[2].duration_s = None;
        stances[3].duration_s = None;
        let plan = FootstepPlan::new(&stances, standing(), &timing).unwrap();
        use PhaseTiming::{Clamped, Configured, Sequence};
        assert_eq!(
            timings(&plan),
            [
                (timing.initial_double_support_s, Clamped),
                (timing.single_support_s, Configured),
                (timing.double_support_s, Configured),
                (0.875, Sequence),
                (timing.final_double_support_s, Configured),
            ]
        );
    }

    #[test]
    fn hand_reaches_and_a_change_of_support_foot_keep_their_configured_durations() {
        let timing = DynamicGaitConfig::default();
        let mut with_hand = DS;
        with_hand[LH] = true;
        let stances = [
            lasting(0.75, stance(RIGHT_UP, standing()[0], at(0.1, -0.1, 0.05))),
            lasting(
                0.75,
                stance(LEFT_UP, at(0.0, 0.1, 0.05), at(0.2, -0.1, 0.0)),
            ),
            lasting(0.375, stance(DS, at(0.3, 0.1, 0.0), at(0.2, -0.1, 0.0))),
            // The reach stands for the stance before it; the lift-off after it takes this one.
            lasting(
                0.5,
                stance(with_hand, at(0.3, 0.1, 0.0), at(0.2, -0.1, 0.0)),
            ),
            lasting(
                0.75,
                stance(RIGHT_UP, at(0.3, 0.1, 0.0), at(0.3, -0.1, 0.05)),
            ),
            lasting(
                0.5,
                stance(with_hand, at(0.3, 0.1, 0.0), at(0.4, -0.1, 0.0)),
            ),
        ];
        let plan = FootstepPlan::new(&stances, standing(), &timing).unwrap();
        assert_eq!(
            kinds(&plan),
            [
                "ds+lift", "ss", "ds+lift", "ss", "ds", "ds+lift", "ss", "ds"
            ]
        );
        use PhaseTiming::{Configured, Sequence};
        assert_eq!(
            timings(&plan),
            [
                // Lifting off at once from standing: no stance on both feet.
                (timing.initial_double_support_s, Configured),
                (0.75, Sequence),
                // Right lands and left lifts at once: no stance on both feet between.
                (timing.double_support_s, Configured),
                (0.75, Sequence),
                (timing.hand_transition_s, Configured),
                (0.5, Sequence),
                (0.75, Sequence),
                (timing.final_double_support_s, Configured),
            ]
        );
    }

    #[test]
    fn a_controlled_stop_ends_with_the_configured_double_support() {
        let mut plan =
            FootstepPlan::new(&timed_walk(), standing(), &DynamicGaitConfig::default()).unwrap();
        // During the first swing: it lands, then the stop's double support.
        let last = plan.end_early(1, 0, 1.2, 0.6);
        assert_eq!(
            (last.duration_s, last.timing),
            (0.6, PhaseTiming::Configured)
        );
        assert_eq!(plan.phases.last(), Some(&last));
        // During a timed double support: it becomes the stop's.
        let mut plan =
            FootstepPlan::new(&timed_walk(), standing(), &DynamicGaitConfig::default()).unwrap();
        let last = plan.end_early(0, 0, 0.5, 0.6);
        assert_eq!(last.timing, PhaseTiming::Configured);
        assert!((last.duration_s - 1.1).abs() < 1e-12);
    }

    #[test]
    fn a_sequence_ending_in_the_air_is_refused() {
        let stances = [
            stance(DS, standing()[0], standing()[1]),
            stance(LEFT_UP, at(0.1, 0.1, 0.05), standing()[1]),
        ];
        let refusal =
            FootstepPlan::new(&stances, standing(), &DynamicGaitConfig::default()).unwrap_err();
        assert!(refusal.0.contains("stance 1"), "{refusal}");
    }
}
