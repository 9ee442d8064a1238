//! The stance state machine: walks through the transitions of a [`PreparedSequence`], phase by
//! phase, and produces the task set-points and the contact set of every tick.
//!
//! Contacts change only here: a foot leaves the contact set when its unloading starts and joins
//! it when force-torque confirms touchdown (debounced), so the QP's contact constraints always
//! agree with the state machine. Every phase has a planned duration; exceeding it by the
//! configured timeout is a fault.

use kinematics::ground::SupportPolygon;
use kinematics::ground::{planar_frame, sequence_alignment};
use kinematics::robot::{EndEffector, SoleRectangle};
use nalgebra::{Isometry3, Translation3, Vector2, Vector3};

use super::config::ControllerConfig;
use super::debounce::Debounce;
use super::gait::{distribute, force_difference_velocities};
use super::hand_press::reach_goal;
use super::hand_support::{HandLoad, HandSupport, hand_slot};
use super::plan::{Step, TransitionPlan};
use super::sequence::PreparedSequence;
use super::status::{FaultCode, Phase};
use super::trajectory::{PointTrajectory, PoseTrajectory, Profile};

const FEET: [EndEffector; 2] = [EndEffector::LeftFoot, EndEffector::RightFoot];

/// What the state machine needs to know about the robot this tick (estimated, world frame).
pub(crate) struct Feedback<'a> {
    /// Centre of mass.
    pub com: Vector3<f64>,
    /// Pelvis pose.
    pub pelvis: Isometry3<f64>,
    /// End-effector poses by `EndEffector`.
    pub poses: &'a [Isometry3<f64>; 4],
    /// FT normal (world z) force by `EndEffector` (N).
    pub normal_forces: [f64; 4],
    /// The forces are this tick's measurement (false: it was invalid and the state was advanced
    /// by the commands, so no force is to be trusted for control).
    pub measured: bool,
}

/// A pose set-point with its feed-forward velocity (linear xyz, angular xyz, world).
#[derive(Clone, Copy, Debug)]
pub(crate) struct PoseTarget {
    pub pose: Isometry3<f64>,
    pub velocity: [f64; 6],
}

/// The set-points and contact set for one tick's QP.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Targets {
    /// End-effectors in contact (feet: equality constraints; hands: held pose tasks).
    pub contacts: [bool; 4],
    /// World pose of each end-effector in contact (valid where `contacts`).
    pub anchors: [Isometry3<f64>; 4],
    /// CoM x/y set-point and its feed-forward velocity.
    pub com: Vector2<f64>,
    pub com_velocity: Vector2<f64>,
    /// Pose tasks (None: no task; feet in contact are constrained instead).
    pub end_effectors: [Option<PoseTarget>; 4],
    /// The foot being unloaded: out of the contact set but still on the ground.
    pub unloading: Option<EndEffector>,
    /// Hands on their way to a contact (`EndEffector` order; a reach under way), which may come
    /// as close to a railing as they need to.
    pub reaching: [bool; 4],
    /// How the QP keeps the robot balanced.
    pub balance: Balance,
    /// Velocities of the feet in contact on top of holding their anchors (linear xyz, angular
    /// xyz, world; left, right): the dynamic gait's force and CoP compliance.
    pub contact_velocity: [[f64; 6]; 2],
    /// Replaces `posture_weight` on the torso joints (`[robot.joint_groups] torso`): the dynamic
    /// gait's `torso_posture_weight`; `None`: the configured posture weight.
    pub torso_posture_weight: Option<f64>,
    /// The vertical force (N) asked of each held hand (left, right; `hand_support`), which its
    /// admittance tracks; never less than the touch, `hand_force_n`.
    pub hand_forces: [f64; 2],
    /// The weight the held hands carry: `com` and the CoM's support polygon are the feet's
    /// (their centre of pressure), which the QP maps into the CoM's by it.
    pub hand_load: HandLoad,
}

impl Targets {
    /// No contact and no task: the targets before a first stance.
    pub fn none() -> Self {
        Self {
            contacts: [false; 4],
            anchors: [Isometry3::identity(); 4],
            com: Vector2::zeros(),
            com_velocity: Vector2::zeros(),
            end_effectors: [None; 4],
            unloading: None,
            reaching: [false; 4],
            balance: Balance::SupportPolygon { height: None },
            contact_velocity: [[0.0; 6]; 2],
            torso_posture_weight: None,
            hand_forces: [0.0; 2],
            hand_load: HandLoad::NONE,
        }
    }

    /// The vertical force (N) the press of `hand` tracks (`hand_press`): the force asked of it,
    /// never less than the touch `touch_n`, while it is held; 0 for a hand not held.
    pub fn hand_force_pressed(&self, hand: EndEffector, touch_n: f64) -> f64 {
        if self.contacts[hand as usize] {
            self.hand_forces[hand_slot(hand)].max(touch_n)
        } else {
            0.0
        }
    }

    /// Moves every anchor by `motion` (a turn of the world the anchors are held in: the
    /// estimate's heading correction, which moves nothing on the robot).
    pub fn move_anchors(&mut self, motion: &Isometry3<f64>) {
        for anchor in &mut self.anchors {
            *anchor = motion * *anchor;
        }
    }

    /// The support polygon the CoM stays over (the static gait's constraint): the hull of the
    /// soles in contact at their anchors, moved towards the held hands by the weight they carry
    /// (`hand_support`), into `polygon`.
    pub fn com_support(&self, sole: &SoleRectangle, polygon: &mut SupportPolygon) {
        let feet = FEET
            .iter()
            .filter(|&&foot| self.contacts[foot as usize])
            .map(|&foot| &self.anchors[foot as usize]);
        polygon.set_soles(feet, sole, |[x, y]| {
            let com = self.hand_load.com_of(Vector2::new(x, y));
            [com.x, com.y]
        });
    }

    /// World anchors of the feet in contact, for the estimator.
    pub fn foot_anchors(&self) -> [Option<&Isometry3<f64>>; 2] {
        FEET.map(|f| {
            let e = f as usize;
            self.contacts[e].then_some(&self.anchors[e])
        })
    }
}

/// How the QP keeps the robot balanced.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Balance {
    /// The CoM ground projection stays inside the support polygon (the static gait); the CoM
    /// follows `height` when set (a climb between feet at different elevations, [`ComClimb`]),
    /// else its height is free.
    SupportPolygon { height: Option<ComHeight> },
    /// The CoM set-point moves like a pendulum whose ZMP stays in the support (the dynamic
    /// gait), so no polygon constraint; the CoM follows this height.
    Pendulum(ComHeight),
}

/// A height the QP's CoM task follows.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct ComHeight {
    /// World z (m).
    pub height: f64,
    /// Feed-forward vertical velocity (m/s).
    pub velocity: f64,
}

/// Result of one state-machine update.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Progress {
    Running,
    Done,
    Fault(FaultCode),
    /// A fault the walk answers with a controlled stop (dynamic gait): it keeps running until
    /// the robot rests on both feet, then ends `Done`.
    Stopping(FaultCode),
}

/// The static gait's CoM height change while a shift hands the weight to a foot at another
/// elevation: the posture reference, made on flat ground, would leave the CoM at the lower
/// foot's height and the leg on the step carrying it deeply bent (JVRC-1's knee then sits at
/// its torque limit when the other foot lifts); the height rises (or falls) by the elevation
/// difference with the shift instead, while both feet still carry the weight. After the shift
/// the height is free again: held on through the single support that follows, JVRC-1 rocked
/// on its stance foot and tipped sooner (MuJoCo, `stairs-up-10cm`, seed 0).
#[derive(Clone, Copy, Debug)]
struct ComClimb {
    /// Estimated CoM height at the start of the shift (m).
    from: f64,
    /// Elevation of the foot taking the weight minus that of the foot leaving (m).
    rise: f64,
}

impl ComClimb {
    /// The height target `time` (s) into a shift lasting `duration` (s): linear, then held
    /// while the shift settles.
    fn height(&self, time: f64, duration: f64) -> ComHeight {
        let progress = (time / duration).clamp(0.0, 1.0);
        ComHeight {
            height: self.from + self.rise * progress,
            velocity: if progress < 1.0 {
                self.rise / duration
            } else {
                0.0
            },
        }
    }
}

/// A CoM shift that stalled short of its goal (joint limits) still completes once it has sat
/// this long (s) past its planned duration inside the support it prepares, shrunk by the support
/// margin plus the CoM tolerance.
const COM_SETTLE_S: f64 = 0.5;

/// A foot put down to catch a tipping robot comes down to the standing sole's plane within this
/// time (s), from any swing height. ARMAR-4 tipping mid-swing over its stance sole's edge (MuJoCo,
/// caught from 0.05 rad): coming down straight to that plane in this time it stood; stopping 2 cm
/// above it (its approach height) with the slow lowering taking over, it fell. The joints' speed
/// bounds (`velocity_limit_scale`) cap the motion the QP makes of it.
const CATCH_S: f64 = 0.15;

/// Execution state of the current sequence.
pub(crate) struct StateMachine {
    config: ControllerConfig,
    sole: SoleRectangle,
    /// The support the current CoM shift prepares (the feet staying in contact).
    com_support: SupportPolygon,
    release_force: f64,
    touchdown_force: f64,
    sequence: Option<Box<PreparedSequence>>,
    started: bool,
    to_world: Isometry3<f64>,
    stance: usize,
    plan: TransitionPlan,
    step: usize,
    phase_time: f64,
    deadline: f64,
    debounce: Debounce,
    motion: PoseTrajectory,
    /// Whether the current motion ends at a via pose (a swing apex) rather than an approach.
    motion_is_via: bool,
    com_motion: PointTrajectory,
    com_time: f64,
    /// The CoM height change of the current shift, if it hands the weight to a foot at another
    /// elevation; outside a shift, and with `None`, the height is free (the posture's).
    com_climb: Option<ComClimb>,
    free_targets: [Option<Isometry3<f64>>; 4],
    /// The foot being put down to end the walk and the pose that replaces its stance target: on
    /// the ground below it (`catch_swing_foot`) or where it lifted off (`take_step_back`).
    put_down: Option<(EndEffector, Isometry3<f64>)>,
    /// Estimated CoM height when the foot in the air was released (m): the standing leg must
    /// hold the body up until that foot lands (`standing_crouch_max_m`).
    release_com_height: f64,
    /// Released hands, carried along with the pelvis: their pose relative to its planar frame
    /// (x, y, yaw) at release. Planar, so the pelvis roll of ARMAR-4's hip strategy does not
    /// swing them sideways.
    carried: [Option<Isometry3<f64>>; 4],
    /// Hands whose reach timed out ([`StateMachine::give_up_reach`]): they stay free until the
    /// sequence's contact run they were reaching for ends.
    given_up: [bool; 4],
    /// Reaches given up since the sequence was loaded.
    reaches_given_up: u32,
    /// The forces asked of the held hands.
    hand_support: HandSupport,
    /// The robot's weight (N).
    weight_n: f64,
    targets: Targets,
}

impl StateMachine {
    /// A machine for a robot of weight `weight_n` (N): thresholds are fractions of it.
    pub fn new(config: &ControllerConfig, sole: SoleRectangle, weight_n: f64) -> Self {
        Self {
            config: *config,
            sole,
            com_support: SupportPolygon::empty(),
            release_force: config.release_force_fraction * weight_n,
            touchdown_force: config.touchdown_force_fraction * weight_n,
            sequence: None,
            started: false,
            to_world: Isometry3::identity(),
            stance: 0,
            plan: TransitionPlan::new([false; 4], [false; 4], false),
            step: 0,
            phase_time: 0.0,
            deadline: f64::INFINITY,
            debounce: Debounce::default(),
            motion: PoseTrajectory::hold(Isometry3::identity()),
            motion_is_via: false,
            com_motion: PointTrajectory::new(Vector2::zeros(), Vector2::zeros(), 1.0),
            com_time: 0.0,
            com_climb: None,
            free_targets: [None; 4],
            put_down: None,
            release_com_height: f64::NAN,
            carried: [None; 4],
            given_up: [false; 4],
            reaches_given_up: 0,
            hand_support: HandSupport::default(),
            weight_n,
            targets: Targets::none(),
        }
    }

    /// Declares the feet standing when the world frame is set up (anchored at `poses`).
    pub fn set_standing(&mut self, standing: [bool; 2], poses: &[Isometry3<f64>; 4]) {
        for (slot, foot) in FEET.iter().enumerate() {
            let e = *foot as usize;
            self.targets.contacts[e] = standing[slot];
            self.targets.anchors[e] = poses[e];
            self.free_targets[e] = (!standing[slot]).then_some(poses[e]);
        }
    }

    /// Takes over the contact set and anchors another gait's walk left: they are the support
    /// for estimation and the start of the next walk. Feet in the air keep their last target.
    pub fn adopt(&mut self, targets: &Targets) {
        self.targets.contacts = targets.contacts;
        self.targets.anchors = targets.anchors;
        self.carried = [None; 4];
        for foot in FEET {
            let e = foot as usize;
            self.free_targets[e] = if targets.contacts[e] {
                None
            } else {
                targets.end_effectors[e].map(|target| target.pose)
            };
        }
    }

    /// The live contact set and anchors (also used for estimation while holding).
    pub fn targets(&self) -> &Targets {
        &self.targets
    }

    /// The live targets, to turn their anchors with the estimate's heading.
    pub fn targets_mut(&mut self) -> &mut Targets {
        &mut self.targets
    }

    /// The loaded sequence and the pose of its frame in the world (set when the walk begins).
    pub fn sequence_in_world(&self) -> Option<(&PreparedSequence, &Isometry3<f64>)> {
        Some((self.sequence.as_deref()?, &self.to_world))
    }

    /// The posture reference of the stance being moved towards.
    pub fn posture(&self) -> Option<&nalgebra::DVector<f64>> {
        self.sequence
            .as_ref()
            .map(|s| &s.stances[self.stance.min(s.stances.len() - 1)].posture)
    }

    /// Current phase (None when no transition runs).
    pub fn phase(&self) -> Phase {
        if self.started {
            self.current_step().phase
        } else {
            Phase::None
        }
    }

    /// Index of the stance being moved towards and the stance count.
    pub fn progress(&self) -> (usize, usize) {
        (self.stance, self.sequence.as_ref().map_or(0, |s| s.len()))
    }

    /// Reaches given up since the sequence was loaded ([`StateMachine::give_up_reach`]).
    pub fn reaches_given_up(&self) -> u32 {
        self.reaches_given_up
    }

    /// Installs a sequence to execute from the next update; returns the previous one.
    pub fn load(&mut self, sequence: Box<PreparedSequence>) -> Option<Box<PreparedSequence>> {
        self.started = false;
        self.put_down = None;
        self.stance = 0;
        self.given_up = [false; 4];
        self.reaches_given_up = 0;
        self.sequence.replace(sequence)
    }

    /// Stops executing (the contact set and anchors stay as they are).
    pub fn stop(&mut self) {
        self.started = false;
        self.put_down = None;
        self.deadline = f64::INFINITY;
    }

    /// Puts the foot in the air down at once, ending the walk: a robot tipping over its stance
    /// foot towards the lifted one catches itself on it. The rest of the sequence is dropped;
    /// the foot, at `poses` (world), comes down within [`CATCH_S`] to the sole plane of the foot
    /// standing, then is lowered as every foot is, until its touchdown is confirmed, and the
    /// walk ends (`Done`). A tipping robot's estimate holds the standing foot flat, so the
    /// ground under the lifted foot lies above that plane on the side it tips to, and the foot
    /// meets it during the fast part. It comes down `tipped` (world, m: how far the tilt has
    /// carried the CoM beyond the estimate) from where it is, so the support it makes lies
    /// where the CoM is going, unless that is nearer the standing foot (the feet would cross):
    /// then straight below. False, and nothing changes, when no foot is lifting, swinging or
    /// lowering over one standing.
    pub fn catch_swing_foot(&mut self, poses: &[Isometry3<f64>; 4], tipped: Vector2<f64>) -> bool {
        let step = self.started.then(|| self.current_step());
        let Some(Step {
            phase: Phase::Lift | Phase::Swing | Phase::Lower,
            end_effector: Some(foot),
        }) = step
        else {
            return false;
        };
        let Some(standing) = FEET
            .into_iter()
            .find(|&f| foot.is_foot() && f != foot && self.targets.contacts[f as usize])
        else {
            return false;
        };
        let start = poses[foot as usize];
        let standing_sole = &self.targets.anchors[standing as usize].translation.vector;
        let mut below = heading_frame(&start);
        below.translation.z = standing_sole.z;
        let apart = |shift: Vector2<f64>| {
            (start.translation.vector.xy() + shift - standing_sole.xy()).norm()
        };
        if apart(tipped) >= apart(Vector2::zeros()) {
            below.translation.x += tipped.x;
            below.translation.y += tipped.y;
        }
        self.motion = PoseTrajectory::new(start, below, CATCH_S, Profile::Linear);
        self.motion_is_via = false;
        self.plan = TransitionPlan::catch(foot);
        self.step = 0;
        self.phase_time = 0.0;
        self.debounce.reset();
        self.deadline = CATCH_S + self.config.phase_timeout_s;
        self.put_down = Some((foot, below));
        true
    }

    /// Whether a foot is being put down to end the walk (a catch, a step taken back).
    pub fn putting_foot_down(&self) -> bool {
        self.put_down.is_some()
    }

    /// The standing leg would have to crouch deeper than `standing_crouch_max_m` to land the foot
    /// in the air ([`landing_beyond_crouch`]). A landing beyond the swing leg's reach makes the QP
    /// lower the body on the standing knee to bring the foot down: JVRC-1 down a 10 cm stair,
    /// 0.29 m ahead, sank with the foot until its knee gave way 8 cm down and it fell (MuJoCo),
    /// where ARMAR-4 lands the same step 11 cm down.
    fn standing_leg_gives_way(&self, feedback: &Feedback) -> bool {
        let step = self.current_step();
        let Some(foot) = step.end_effector.filter(|e| e.is_foot()) else {
            return false;
        };
        if self.put_down.is_some()
            || !matches!(step.phase, Phase::Lift | Phase::Swing | Phase::Lower)
        {
            return false;
        }
        let sink = self.release_com_height - feedback.com.z;
        if sink <= self.config.standing_crouch_max_m / 2.0 {
            return false;
        }
        // Only now look ahead for the foothold (a scan of the stances).
        let to_descend =
            (feedback.poses[foot as usize].translation.z - self.landing_height(foot)).max(0.0);
        landing_beyond_crouch(sink, to_descend, &self.config)
    }

    /// Takes the step back (`standing_leg_gives_way`): the foot rises straight up above both the
    /// surface it left and where it is, moves back over where it lifted off, and is lowered there
    /// until its touchdown is confirmed; then the walk ends. The rest of the sequence is dropped.
    fn take_step_back(&mut self, feedback: &Feedback) {
        let Some(foot) = self.current_step().end_effector else {
            return;
        };
        let back = self.targets.anchors[foot as usize];
        let start = feedback.poses[foot as usize];
        let above = (back.translation.z - start.translation.z).max(0.0) + self.config.lift_height_m;
        self.timed_motion(start, raised(&start, above), Profile::MinimumJerk);
        self.motion_is_via = true;
        self.plan = TransitionPlan::step_back(foot);
        self.step = 0;
        self.phase_time = 0.0;
        self.debounce.reset();
        self.deadline = self.motion.duration() + self.config.phase_timeout_s;
        self.put_down = Some((foot, back));
    }

    /// One tick of the sequence: starts it on the first call after `load`, checks the current
    /// phase's completion and timeout (a reach that times out is given up, any other phase
    /// faults), advances, and refreshes the targets.
    pub fn update(&mut self, feedback: &Feedback, dt: f64) -> Progress {
        // The machine moves the feet's centre of pressure: the CoM when no hand carries.
        if feedback.measured {
            self.hand_support.sense(&feedback.normal_forces, dt);
        }
        self.targets.hand_load = self.hand_support.load(&self.targets.anchors, self.weight_n);
        let feet = self.targets.hand_load.feet_of(feedback.com.xy());
        let feedback = &Feedback {
            com: Vector3::new(feet.x, feet.y, feedback.com.z),
            ..*feedback
        };
        if !self.started {
            self.begin(feedback);
        } else {
            self.phase_time += dt;
            self.com_time += dt;
        }
        let mut progress = Progress::Running;
        if self.standing_leg_gives_way(feedback) {
            self.take_step_back(feedback);
            progress = Progress::Stopping(FaultCode::StepOutOfReach);
        }
        loop {
            match self.check_step(feedback, dt) {
                StepStatus::Running => break,
                StepStatus::TimedOut if self.current_step().phase == Phase::Reach => {
                    self.give_up_reach(&feedback.pelvis);
                }
                StepStatus::TimedOut => {
                    return Progress::Fault(FaultCode::Timeout(self.current_step().phase));
                }
                StepStatus::Complete => self.finish_step(feedback),
            }
            if !self.advance(feedback) {
                self.refresh_targets(&feedback.pelvis, feedback.com.z);
                self.support_hands(dt);
                self.targets.contact_velocity = [[0.0; 6]; 2];
                return Progress::Done;
            }
        }
        self.refresh_targets(&feedback.pelvis, feedback.com.z);
        self.support_hands(dt);
        self.comply(feedback);
        progress
    }

    /// Advances the forces asked of the held hands (`hand_support`): towards their share of the
    /// weight, or back to the touch for the hand being unloaded.
    fn support_hands(&mut self, dt: f64) {
        let unloading = self
            .started
            .then(|| self.current_step())
            .filter(|step| step.phase == Phase::Unload)
            .and_then(|step| step.end_effector)
            .filter(|e| !e.is_foot());
        self.hand_support.update(
            &self.targets.contacts,
            unloading,
            &self.config,
            self.weight_n,
            dt,
        );
        self.targets.hand_forces = self.hand_support.desired();
    }

    /// Force-difference control in double support: see [`double_support_compliance`]. Off
    /// with one foot in contact, and for a tick without measurement.
    fn comply(&mut self, feedback: &Feedback) {
        let [left, right] = FEET.map(|f| f as usize);
        let gain = self.config.force_difference_gain;
        let both_feet = self.targets.contacts[left] && self.targets.contacts[right];
        self.targets.contact_velocity = if both_feet && feedback.measured && gain > 0.0 {
            double_support_compliance(
                self.targets.com,
                [&self.targets.anchors[left], &self.targets.anchors[right]],
                &self.sole,
                [feedback.normal_forces[left], feedback.normal_forces[right]],
                (gain, self.config.force_difference_max_speed),
            )
        } else {
            [[0.0; 6]; 2]
        };
    }

    fn sequence(&self) -> &PreparedSequence {
        self.sequence
            .as_ref()
            .expect("state machine runs only with a sequence")
    }

    fn current_step(&self) -> Step {
        self.plan.steps()[self.step]
    }

    /// Aligns the sequence's frame with the robot's feet and starts the first transition.
    fn begin(&mut self, feedback: &Feedback) {
        self.to_world = self.alignment();
        self.started = true;
        self.stance = 0;
        let com = feedback.com.xy();
        self.com_motion = PointTrajectory::new(com, com, self.config.min_motion_s);
        self.com_time = 0.0;
        self.com_climb = None;
        self.begin_transition(feedback);
    }

    /// The planar (x, y, yaw) transform taking the first stance's contact feet onto the feet
    /// standing now ([`sequence_alignment`]).
    fn alignment(&self) -> Isometry3<f64> {
        let first = &self.sequence().stances[0];
        let feet = |flags: &[bool; 4]| FEET.map(|f| flags[f as usize]);
        let poses = |all: &[Isometry3<f64>; 4]| FEET.map(|f| all[f as usize]);
        sequence_alignment(
            &poses(&first.targets),
            feet(&first.contacts),
            &poses(&self.targets.anchors),
            feet(&self.targets.contacts),
        )
    }

    fn world_target(&self, e: EndEffector) -> Isometry3<f64> {
        match self.put_down {
            Some((foot, below)) if foot == e => below,
            _ => self.to_world * self.sequence().stances[self.stance].targets[e as usize],
        }
    }

    /// Height of the contact `foot` swings to: its target in the first stance from the current
    /// one where it is in contact (the current target if none is).
    fn landing_height(&self, foot: EndEffector) -> f64 {
        let stances = &self.sequence().stances[self.stance..];
        stances
            .iter()
            .find(|stance| stance.contacts[foot as usize])
            .map_or(self.world_target(foot).translation.z, |stance| {
                stance.targets[foot as usize].translation.z
            })
    }

    fn begin_transition(&mut self, feedback: &Feedback) {
        let mut next = self.sequence().stances[self.stance].contacts;
        let is_last = self.stance + 1 == self.sequence().len();
        for hand in EndEffector::HANDS {
            let h = hand as usize;
            if !next[h] {
                self.given_up[h] = false;
            } else if self.given_up[h] {
                next[h] = false;
            }
        }
        self.plan = TransitionPlan::new(self.targets.contacts, next, is_last);
        self.step = 0;
        self.enter_step(feedback);
    }

    /// Moves to the next step or transition; false when the sequence is finished (or a caught
    /// foot touched down).
    fn advance(&mut self, feedback: &Feedback) -> bool {
        self.step += 1;
        if self.put_down.is_some() && self.step == self.plan.steps().len() {
            self.stop();
            return false;
        }
        if self.step < self.plan.steps().len() {
            self.enter_step(feedback);
            return true;
        }
        self.stance += 1;
        if self.stance == self.sequence().len() {
            self.stance -= 1;
            self.started = false;
            return false;
        }
        self.begin_transition(feedback);
        true
    }

    fn enter_step(&mut self, feedback: &Feedback) {
        self.phase_time = 0.0;
        self.debounce.reset();
        self.motion_is_via = false;
        let step = self.current_step();
        let c = self.config;
        let timeout = c.phase_timeout_s;
        let duration = match (step.phase, step.end_effector) {
            (Phase::ShiftCom | Phase::Settle, excluded) => {
                let goal = self.support_centre(excluded);
                self.set_com_support(excluded);
                let start = feedback.com.xy();
                let duration = c.min_motion_s.max((goal - start).norm() / c.com_speed);
                self.com_motion = PointTrajectory::new(start, goal, duration);
                self.com_time = 0.0;
                self.com_climb = self.climb_of_shift(excluded).map(|rise| ComClimb {
                    from: feedback.com.z,
                    rise,
                });
                duration
            }
            (Phase::Unload, Some(hand)) if !hand.is_foot() => {
                // Nothing moves: the force asked of the hand falls back to the touch, and the CoM
                // with it to over the feet.
                self.hand_support
                    .unload_s(hand, &c, self.weight_n)
                    .max(c.min_motion_s)
            }
            (Phase::Unload, Some(foot)) => {
                // Straight up from where the foot is estimated to be (not its anchor): pulling it
                // back to the anchor would drag it along the ground while it still touches.
                let start = feedback.poses[foot as usize];
                self.targets.contacts[foot as usize] = false;
                self.release_com_height = feedback.com.z;
                let goal = raised(&start, c.unload_lift_m);
                self.motion =
                    PoseTrajectory::new(start, goal, c.min_motion_s, Profile::MinimumJerk);
                c.min_motion_s
            }
            (Phase::Lift, Some(foot)) => {
                // Up a step, straight up above the landing's surface first, so the toe clears
                // the riser ahead before the foot moves forward.
                let start = *self.motion.goal();
                let climb =
                    self.landing_height(foot) - self.targets.anchors[foot as usize].translation.z;
                let goal = raised(&start, c.lift_height_m + climb_above_step(climb));
                self.timed_motion(start, goal, Profile::MinimumJerk);
                self.motion.duration()
            }
            (Phase::Swing, Some(foot)) => {
                let start =
                    self.free_targets[foot as usize].unwrap_or(feedback.poses[foot as usize]);
                let target = self.world_target(foot);
                // A foot swung to the stance it is in the air in swings to its via pose; one
                // that lands (or is put down) ends its swing above its foothold.
                self.motion_is_via = self.put_down.is_none()
                    && !self.sequence().stances[self.stance].contacts[foot as usize];
                let goal = if self.motion_is_via {
                    target
                } else {
                    // Down a step, the approach stays above the surface the foot left, so the
                    // heel clears the nosing behind the landing: the lowering goes straight down.
                    let descent =
                        self.targets.anchors[foot as usize].translation.z - target.translation.z;
                    raised(&target, c.approach_height_m + climb_above_step(descent))
                };
                self.timed_motion(start, goal, Profile::MinimumJerk);
                self.motion.duration()
            }
            (Phase::Lower, Some(foot)) => {
                // Straight down from where the approach ended (within tolerance of the planned
                // contact), so no horizontal correction is still under way at touchdown.
                let start = feedback.poses[foot as usize];
                let target = self.world_target(foot);
                let goal = Isometry3::from_parts(
                    Translation3::new(
                        start.translation.x,
                        start.translation.y,
                        target.translation.z - c.lower_overshoot_m,
                    ),
                    target.rotation,
                );
                let distance = (goal.translation.vector - start.translation.vector).norm();
                let duration = (distance / c.lower_speed).max(1e-3);
                self.motion = PoseTrajectory::new(start, goal, duration, Profile::Linear);
                duration
            }
            (Phase::Reach, Some(hand)) => {
                let start = feedback.poses[hand as usize];
                let goal = reach_goal(&self.world_target(hand), &c);
                self.timed_motion(start, goal, Profile::MinimumJerk);
                self.motion = self.motion.lifted(c.hand_approach_height_m);
                self.motion.duration()
            }
            (phase, None) => unreachable!("phase {phase:?} needs an end-effector"),
            (Phase::None, _) => unreachable!("plans hold no empty phase"),
            (
                Phase::DoubleSupport
                | Phase::SingleSupport
                | Phase::LateTouchdown
                | Phase::LateLiftOff,
                _,
            ) => {
                unreachable!("static plans hold no dynamic-gait phase")
            }
        };
        // However far a target, a phase that does not complete ends in bounded time: it faults,
        // or a reach is given up.
        self.deadline = duration.min(c.max_phase_s) + timeout;
    }

    /// A hand that did not reach its contact within the reach's deadline: the walk goes on
    /// without it. It never carried any of the weight (a hand counts as a support only once it
    /// reached), so nothing the balance relies on is lost. It is let go as a released hand is: back
    /// to where the reach started and carried with the pelvis (`carry_released_hands`), or left
    /// to the posture task; it stays free until the contact run it reached for ends. A grasp the
    /// arm cannot reach (the feet too far from the railing, a joint limit, the CoM constraint)
    /// would otherwise stop the whole walk there.
    fn give_up_reach(&mut self, pelvis: &Isometry3<f64>) {
        let Some(hand) = self.current_step().end_effector else {
            return;
        };
        let h = hand as usize;
        let (start, _) = self.motion.sample(0.0);
        self.carried[h] = self
            .config
            .carry_released_hands
            .then(|| heading_frame(pelvis).inverse() * start);
        self.given_up[h] = true;
        self.reaches_given_up = self.reaches_given_up.saturating_add(1);
    }

    /// A motion from `start` to `goal` at the configured swing speeds.
    fn timed_motion(&mut self, start: Isometry3<f64>, goal: Isometry3<f64>, profile: Profile) {
        let c = &self.config;
        let distance = (goal.translation.vector - start.translation.vector).norm();
        let angle = goal.rotation.angle_to(&start.rotation);
        let duration = c
            .min_motion_s
            .max(distance / c.swing_speed)
            .max(angle / c.swing_angular_speed);
        self.motion = PoseTrajectory::new(start, goal, duration, profile);
    }

    /// Centre of the feet in contact, leaving out `excluded` (the foot about to be released).
    fn support_centre(&self, excluded: Option<EndEffector>) -> Vector2<f64> {
        let (sum, count) = FEET
            .iter()
            .filter(|f| Some(**f) != excluded && self.targets.contacts[**f as usize])
            .fold((Vector2::zeros(), 0.0), |(sum, n), f| {
                (
                    sum + self.targets.anchors[*f as usize].translation.vector.xy(),
                    n + 1.0,
                )
            });
        sum / count
    }

    /// The elevation (m) the weight climbs when a shift hands it from foot `lifting` to the
    /// other foot standing higher (negative: lower), `None` between feet on one level (within
    /// [`STEP_HEIGHT_M`]) or when no foot is lifting.
    fn climb_of_shift(&self, lifting: Option<EndEffector>) -> Option<f64> {
        let lifting = lifting.filter(|e| e.is_foot())?;
        let staying = FEET
            .into_iter()
            .find(|&f| f != lifting && self.targets.contacts[f as usize])?;
        let rise = self.targets.anchors[staying as usize].translation.z
            - self.targets.anchors[lifting as usize].translation.z;
        (rise.abs() > STEP_HEIGHT_M).then_some(rise)
    }

    /// The polygon of the feet in contact except `excluded`.
    fn set_com_support(&mut self, excluded: Option<EndEffector>) {
        let staying = FEET
            .iter()
            .filter(|&&foot| Some(foot) != excluded && self.targets.contacts[foot as usize])
            .map(|&foot| &self.targets.anchors[foot as usize]);
        self.com_support.set_soles(staying, &self.sole, |p| p);
    }

    fn check_step(&mut self, feedback: &Feedback, dt: f64) -> StepStatus {
        let step = self.current_step();
        let caught_on_ground = match (self.put_down, step.phase) {
            (Some((foot, _)), Phase::Swing) => self.debounced(
                feedback.normal_forces[foot as usize] > self.touchdown_force,
                dt,
            ),
            _ => false,
        };
        let c = &self.config;
        let complete = match (step.phase, step.end_effector) {
            (Phase::ShiftCom | Phase::Settle, _) => {
                let com = feedback.com.xy();
                let reached = (com - self.com_motion.goal()).norm() <= c.com_tolerance_m;
                let stalled_inside = self.com_time >= self.com_motion.duration() + COM_SETTLE_S
                    && self.com_support.signed_distance([com.x, com.y])
                        >= c.support_margin_m + c.com_tolerance_m;
                self.com_time >= self.com_motion.duration() && (reached || stalled_inside)
            }
            (Phase::Unload, Some(e)) => {
                let asked_no_more = e.is_foot() || self.hand_support.unloaded(e, &self.config);
                let released = feedback.normal_forces[e as usize] < self.release_force;
                asked_no_more && self.debounced(released, dt)
            }
            (Phase::Lower, Some(foot)) => self.debounced(
                feedback.normal_forces[foot as usize] > self.touchdown_force,
                dt,
            ),
            // A caught foot's fast descent ends where it meets the ground, if that comes first.
            (Phase::Swing, Some(_)) if caught_on_ground => true,
            (Phase::Lift | Phase::Swing | Phase::Reach, Some(e)) => {
                let goal = self.motion.goal();
                let pose = &feedback.poses[e as usize];
                let (position_tolerance, orientation_tolerance) = if self.motion_is_via {
                    (c.via_position_tolerance_m, c.via_orientation_tolerance_rad)
                } else if step.phase == Phase::Reach {
                    (
                        c.hand_position_tolerance_m,
                        c.hand_orientation_tolerance_rad,
                    )
                } else {
                    (c.position_tolerance_m, c.orientation_tolerance_rad)
                };
                self.phase_time >= self.motion.duration()
                    && (pose.translation.vector - goal.translation.vector).norm()
                        <= position_tolerance
                    && pose.rotation.angle_to(&goal.rotation) <= orientation_tolerance
            }
            _ => true,
        };
        if complete {
            StepStatus::Complete
        } else if self.phase_time > self.deadline {
            StepStatus::TimedOut
        } else {
            StepStatus::Running
        }
    }

    /// Whether `condition` has held, through this tick of `dt` (s), for `touchdown_debounce_s`.
    fn debounced(&mut self, condition: bool, dt: f64) -> bool {
        let hold_s = self.config.touchdown_debounce_s;
        self.debounce.update(condition, dt, hold_s)
    }

    fn finish_step(&mut self, feedback: &Feedback) {
        let step = self.current_step();
        if matches!(step.phase, Phase::ShiftCom | Phase::Settle) {
            // Hold the CoM where the shift ended (it may have stalled short of its goal).
            let com = feedback.com.xy();
            self.com_motion = PointTrajectory::new(com, com, self.config.min_motion_s);
            self.com_time = self.config.min_motion_s;
            return;
        }
        let Some(e) = step.end_effector else {
            return;
        };
        let i = e as usize;
        match step.phase {
            Phase::Lower => {
                // Anchor where the foot landed, at the surface's height: the estimate there
                // includes the ground compression that confirmed the touchdown, and keeping it
                // would let the height estimate sink a little with every step.
                // A caught foot meets the ground wherever it is (it is anchored as estimated).
                let mut anchor = feedback.poses[i];
                if self.put_down.is_none() {
                    anchor.translation.z = self.world_target(e).translation.z;
                }
                self.targets.contacts[i] = true;
                self.targets.anchors[i] = anchor;
                self.free_targets[i] = None;
            }
            Phase::Reach => {
                self.targets.contacts[i] = true;
                self.carried[i] = None;
                self.targets.anchors[i] = self.world_target(e);
            }
            Phase::Unload if !e.is_foot() => {
                // The hand carries no more than a touch: let it go.
                self.targets.contacts[i] = false;
                if self.config.carry_released_hands {
                    self.carried[i] =
                        Some(heading_frame(&feedback.pelvis).inverse() * self.targets.anchors[i]);
                }
            }
            Phase::Lift | Phase::Swing => self.free_targets[i] = Some(*self.motion.goal()),
            _ => {}
        }
    }

    /// The CoM height while a foot is lowered (`com_height`: the estimated one, m): free
    /// (`None`) until the lowering has brought the foot's target to its goal just below the
    /// surface. A foot still without touchdown then is held up by its leg's reach, and the body
    /// comes down after it at `lower_speed`, at most `standing_crouch_max_m` below its height at
    /// the release; a landing that needs more is taken back (`standing_leg_gives_way`). Free,
    /// the legs' flat-ground posture held ARMAR-4's body up: down the 0.10 m stairs its foot,
    /// 0.33 m ahead, stopped on the tread with no load (seed 1 of 10) until the lowering timed
    /// out (MuJoCo).
    fn body_after_foot(&self, com_height: f64) -> Option<ComHeight> {
        if self.phase_time < self.motion.duration() || !self.release_com_height.is_finite() {
            return None;
        }
        let lowest = self.release_com_height - self.config.standing_crouch_max_m;
        let descending = com_height > lowest;
        Some(ComHeight {
            height: com_height.max(lowest),
            velocity: if descending {
                -self.config.lower_speed
            } else {
                0.0
            },
        })
    }

    fn refresh_targets(&mut self, pelvis: &Isometry3<f64>, com_height: f64) {
        let (com, com_velocity) = self.com_motion.sample(self.com_time);
        self.targets.com = com;
        self.targets.com_velocity = com_velocity;
        let step = self.started.then(|| self.current_step());
        let shifting = step.is_some_and(|step| step.phase == Phase::ShiftCom);
        // While a hand carries weight the CoM does not move up or down (outside a climb's
        // shift): the palm is held on a rigid rail, and the stance knee straightening towards
        // the legs' posture when JVRC-1 lifted its other foot raised the body 3 cm/s, pressed
        // the palm into the rail with 1100 N and bounced it off.
        let leaning = (self.targets.hand_load.share() > 0.0).then_some(ComHeight {
            height: com_height,
            velocity: 0.0,
        });
        let reaching_down = step
            .filter(|step| step.phase == Phase::Lower)
            .and_then(|_| self.body_after_foot(com_height));
        self.targets.balance = Balance::SupportPolygon {
            height: self
                .com_climb
                .filter(|_| shifting)
                .map(|climb| climb.height(self.com_time, self.com_motion.duration()))
                .or(leaning)
                .or(reaching_down),
        };
        // A hand being unloaded stays held where it is; a foot being unloaded rises.
        let unloading_foot = step
            .filter(|step| step.phase == Phase::Unload)
            .and_then(|step| step.end_effector)
            .filter(|e| e.is_foot());
        let moving = step.and_then(|step| match step.phase {
            Phase::Lift | Phase::Swing | Phase::Lower | Phase::Reach => step.end_effector,
            _ => None,
        });
        let moving = moving.or(unloading_foot);
        self.targets.unloading = unloading_foot;
        self.targets.reaching = EndEffector::ALL.map(|e| {
            step.is_some_and(|step| step.phase == Phase::Reach && step.end_effector == Some(e))
        });
        for e in EndEffector::ALL {
            let i = e as usize;
            self.targets.end_effectors[i] = if Some(e) == moving {
                let (pose, velocity) = self.motion.sample(self.phase_time);
                Some(PoseTarget { pose, velocity })
            } else if self.targets.contacts[i] {
                (!e.is_foot()).then_some(PoseTarget {
                    pose: self.targets.anchors[i],
                    velocity: [0.0; 6],
                })
            } else {
                let carried = self.carried[i].map(|relative| heading_frame(pelvis) * relative);
                carried.or(self.free_targets[i]).map(|pose| PoseTarget {
                    pose,
                    velocity: [0.0; 6],
                })
            };
        }
    }
}

/// Whether landing a foot takes the standing leg deeper than `standing_crouch_max_m`: the CoM
/// sank `sink` (m) more than half that below its height at the release, and that sink plus what
/// the foot still has to descend to its foothold's level, `to_descend` (a foot at full reach
/// comes down only as far as the body does), exceeds it, with the foot still more than
/// `approach_height_m + position_tolerance_m` above that level. A foot that low is landing, not
/// out of reach: JVRC-1 leaning on a railing sank 8.8 cm on its stance hip (at its torque
/// limit) with the swing foot 2 mm above the ground; taking that foot back up and back made
/// it tip and fall where landing it walked on (MuJoCo, `railing.toml`, right hand, seed 0).
fn landing_beyond_crouch(sink: f64, to_descend: f64, config: &ControllerConfig) -> bool {
    let budget = config.standing_crouch_max_m;
    let landing = config.approach_height_m + config.position_tolerance_m;
    sink > budget / 2.0 && to_descend > landing && sink + to_descend > budget
}

/// The static gait's force-difference control in double support (Kajita et al. 2010; the
/// dynamic gait's, `gait::force_difference_velocities`), as velocities of the feet (left,
/// right): they move vertically against each other until their normal forces `forces` (N)
/// split as the CoM set-point `com` asks, by the lever rule between the soles at `feet`. `gain`: m/s per N and
/// the bound (m/s). A robot held stiffly by its joints rocks from one foot onto the other as a
/// rigid block (an arm's reach, a shift of the CoM excite it); pressing the foot that lost its
/// load back down damps that.
fn double_support_compliance(
    com: Vector2<f64>,
    feet: [&Isometry3<f64>; 2],
    sole: &SoleRectangle,
    forces: [f64; 2],
    (gain, max): (f64, f64),
) -> [[f64; 6]; 2] {
    let mut velocities = [[0.0; 6]; 2];
    if let [Some(left), Some(right)] = distribute(com, feet.map(Some), sole, 0.0, 0.0) {
        let [vl, vr] = force_difference_velocities([left.share, right.share], forces, gain, max);
        velocities[0][2] = vl;
        velocities[1][2] = vr;
    }
    velocities
}

enum StepStatus {
    Running,
    Complete,
    TimedOut,
}

/// The planar frame (x, y, yaw) of `pose`.
pub(crate) fn heading_frame(pose: &Isometry3<f64>) -> Isometry3<f64> {
    planar_frame(std::iter::once(pose))
}

/// A height difference between where a foot lifts off and where it lands counts as a step up
/// or down (a stair or a ramp) above this (m); below it the swing is the flat-ground one. Both
/// gaits shape their swings by it.
pub(crate) const STEP_HEIGHT_M: f64 = 0.01;

/// The extra height of a swing that climbs (or descends) `height` (m): all of it for a step,
/// none on flat ground.
fn climb_above_step(height: f64) -> f64 {
    if height > STEP_HEIGHT_M { height } else { 0.0 }
}

/// `pose` moved up by `height` along world z.
fn raised(pose: &Isometry3<f64>, height: f64) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::from(pose.translation.vector + Vector3::z() * height),
        pose.rotation,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_climb_raises_the_com_with_the_shift_then_holds_it() {
        let climb = ComClimb {
            from: 0.85,
            rise: 0.1,
        };
        let at = |t| climb.height(t, 2.0);
        assert_eq!(at(0.0).height, 0.85);
        assert!((at(1.0).height - 0.9).abs() < 1e-12);
        assert!((at(1.0).velocity - 0.05).abs() < 1e-12);
        assert!((at(3.0).height - 0.95).abs() < 1e-12);
        assert_eq!(at(3.0).velocity, 0.0);
        // Down a stair, the same the other way.
        let down = ComClimb {
            from: 0.85,
            rise: -0.1,
        };
        assert!((down.height(2.0, 2.0).height - 0.75).abs() < 1e-12);
    }

    #[test]
    fn a_held_hand_presses_with_its_share_never_less_than_the_touch() {
        let mut targets = Targets::none();
        targets.hand_forces = [0.0, 95.0];
        let pressed = |targets: &Targets| {
            EndEffector::HANDS.map(|hand| targets.hand_force_pressed(hand, 10.0))
        };
        assert_eq!(pressed(&targets), [0.0, 0.0], "no hand held");
        targets.contacts[EndEffector::LeftHand as usize] = true;
        targets.contacts[EndEffector::RightHand as usize] = true;
        assert_eq!(pressed(&targets), [10.0, 95.0]);
    }

    #[test]
    fn a_landing_is_taken_back_only_when_the_foot_is_still_above_its_approach() {
        // JVRC-1's: bound 0.09 m, lowered from 0.02 m above the foothold, 5 mm tolerance.
        let config = ControllerConfig::default();
        let (budget, approach) = (config.standing_crouch_max_m, config.approach_height_m);
        assert_eq!((budget, approach), (0.09, 0.02));
        let beyond = |sink, to_descend| landing_beyond_crouch(sink, to_descend, &config);
        // Down a 10 cm stair out of reach: taken back once half the bound has sunk.
        assert!(beyond(0.046, 0.086));
        assert!(!beyond(0.044, 0.086), "less than half the bound sunk");
        assert!(!beyond(0.05, 0.035), "the sum within the bound");
        // A sagging stance leg with the foot at or just above its approach: landed, not taken
        // back, however deep the sink.
        assert!(!beyond(0.088, 0.002));
        assert!(!beyond(0.105, 0.020));
        assert!(!beyond(0.105, 0.025));
        assert!(beyond(0.105, 0.026));
    }

    #[test]
    fn the_force_difference_presses_down_the_foot_that_lost_its_load() {
        let sole = SoleRectangle {
            length: 0.2,
            width: 0.08,
        };
        let left = Isometry3::translation(0.0, 0.1, 0.0);
        let right = Isometry3::translation(0.0, -0.1, 0.0);
        let (gain, max) = (1e-5, 0.02);
        let at_centre = |forces| {
            double_support_compliance(
                Vector2::zeros(),
                [&left, &right],
                &sole,
                forces,
                (gain, max),
            )
        };
        // Rocked onto the left foot: the left rises, the right presses down, by 1e-5 × 400 N.
        let v = at_centre([500.0, 100.0]);
        assert!((v[0][2] - 2e-3).abs() < 1e-12 && (v[1][2] + 2e-3).abs() < 1e-12);
        assert!(
            v.iter()
                .flat_map(|foot| [foot[0], foot[1], foot[3], foot[4], foot[5]])
                .all(|c| c == 0.0)
        );
        // Split as asked: nothing moves; a large error moves at the bound, shared by both feet.
        assert_eq!(at_centre([300.0, 300.0]), [[0.0; 6]; 2]);
        assert!((at_centre([1e6, 0.0])[0][2] - max / 2.0).abs() < 1e-12);
        // The CoM set-point over the right sole: the right foot should carry everything.
        let over_right = double_support_compliance(
            Vector2::new(0.0, -0.1),
            [&left, &right],
            &sole,
            [300.0, 300.0],
            (gain, max),
        );
        assert!(over_right[1][2] < 0.0, "the right foot presses down");
    }
}
