//! The dynamic gait's state machine: runs a [`DynamicPlan`] on its plan clock and produces the
//! QP's set-points and contact set every tick.
//!
//! Phases advance on time (the ZMP reference leaves a foot before it lifts off and reaches it
//! before it must carry the robot).
//! A double support ends with the lift-off of its foot, once force-torque shows the weight off
//! it (below `release_force_fraction` of the weight): while it still carries load the plan clock
//! waits at the lift-off instant, up to `late_lift_off_max_s`, then the foot lifts anyway (a
//! landing foot that bounced, a robot leaning back on the old stance foot). A single support
//! ends with the touchdown, confirmed by force-torque (debounced):
//! - early, within `early_touchdown_s` of the planned instant: the foot is anchored where it
//!   landed and the plan runs on (the ZMP stays on the stance foot until the double support);
//! - late: at the planned instant the plan clock stops, the foot keeps descending at
//!   `late_descent_speed`, and the stabilizer's pendulum moves on under a ZMP clamped into the
//!   stance foot; once force-torque confirms the contact the clock runs again. A touchdown still
//!   missing `late_touchdown_max_s` after the planned instant is a fault.
//!
//! Before a foot swings up a step, its heel rises about its toe over the end of the double
//! support ([toe-off](super::toe_off)); a stop that cancels the lift-off lowers it again.
//!
//! Hands change with the stance their phases lead to: a released hand leaves the contact set when
//! its transition begins (carried along with the pelvis with `carry_released_hands`); an added
//! hand reaches its contact pose with a minimum-jerk motion timed over the transition and is in
//! contact at its end. After the last phase the walk settles: done once the CoM and the commanded
//! DCM are within `com_tolerance_m` of the final feet's centre.
//!
//! A walk that must end early ends with a controlled stop ([`DynamicWalker::stop_early`],
//! `docs/safety.md`): the plan is cut after the step under way — a swinging foot lands at its
//! planned foothold, no foot lifts off again — and the ZMP crosses to the centre of both feet over
//! `stop_double_support_s`; the DCM comes to rest there and the walk settles as it would at its
//! end. A stop that distrusts the feet's force-torque sensors (they read no load, or never
//! confirmed a touchdown), and every tick that runs on the last valid state instead of a
//! measurement ([`Sensors::measured`]), lands the swing foot by position: at the planned
//! touchdown, once the sole is within [`LANDING_HEIGHT_TOLERANCE_M`] of its foothold's height;
//! the stabilizer then closes no loop on force-torque. A swing foot that cannot land within
//! `late_touchdown_max_s` of the planned touchdown ends the stop with
//! [`FaultCode::StopCouldNotLand`].

use kinematics::ground::SupportPolygon;
use kinematics::ground::sequence_alignment;
use kinematics::robot::{EndEffector, SoleRectangle};
use nalgebra::{DVector, Isometry3, UnitQuaternion, Vector2, Vector3};

use super::DynamicPlan;
use super::compliance::{
    TiltDamping, distribute, foot_damping, force_difference_velocities, internal_force_velocities,
};
use super::elevation::support_elevation;
use super::footsteps::{FEET, Support, SupportPhase, SwingPlan};
use super::sensing::{DcmEstimator, TiltRate, pressure_centre, tilted_com};
use super::stabilizer::{Measured, Stabilizer};
use super::swing::SwingTrajectory;
use super::toe_off::{ToeOff, reachable_pitch};
use crate::controller::config::ControllerConfig;
use crate::controller::debounce::Debounce;
use crate::controller::hand_press::reach_goal;
use crate::controller::machine::{
    Balance, ComHeight, Feedback, PoseTarget, Progress, STEP_HEIGHT_M, Targets, heading_frame,
};
use crate::controller::sequence::PreparedSequence;
use crate::controller::sequencer::on_both_feet;
use crate::controller::status::{BalanceStatus, FaultCode, Phase, PlannedPhase};
use crate::controller::trajectory::{PoseTrajectory, Profile};

/// How far above its foothold's height a swing sole may be and still count as landed when no
/// force-torque confirms it (m): the ground stops a foot commanded below it within this.
const LANDING_HEIGHT_TOLERANCE_M: f64 = 0.015;

/// What the dynamic gait reads besides the static machine's [`Feedback`] (estimated, world).
pub(crate) struct Sensors<'a> {
    /// Ankle wrenches by `EndEffector` (see `Measurement::wrenches`).
    pub wrenches: &'a [[f64; 6]; 4],
    /// FT frame origins (left, right foot).
    pub ft_origins: [Vector3<f64>; 2],
    /// The leg-odometry base orientation.
    pub base_rotation: UnitQuaternion<f64>,
    /// The IMU's base orientation, if there is an IMU.
    pub imu: Option<UnitQuaternion<f64>>,
    /// The tick runs on a measurement; false: on the last valid state advanced by the commands
    /// (the measurement was invalid), so no force-torque or IMU reading is to be trusted.
    pub measured: bool,
}

/// A controlled stop under way.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Stop {
    /// The feet's force-torque readings may confirm touchdowns and feed the stabilizer.
    trust_force_sensors: bool,
}

/// The swing under way.
#[derive(Clone, Copy, Debug)]
struct Swing {
    foot: EndEffector,
    trajectory: SwingTrajectory,
    /// Plan time of the lift-off (s).
    lift_off_s: f64,
}

/// Execution state of a dynamic walk.
pub(crate) struct DynamicWalker {
    config: ControllerConfig,
    sole: SoleRectangle,
    touchdown_force: f64,
    release_force: f64,
    sequence: Option<Box<PreparedSequence>>,
    running: bool,
    started: bool,
    to_world: Isometry3<f64>,
    /// Plan time (s): stops while a late touchdown is awaited.
    clock: f64,
    phase: usize,
    transition: usize,
    /// Time waited past a planned touchdown (s).
    late_s: Option<f64>,
    settle_s: f64,
    touchdown: Debounce,
    cursor: usize,
    swing: Option<Swing>,
    /// A controlled stop, once one began.
    stop: Option<Stop>,
    /// This tick lands swing feet by position, not by force-torque.
    blind: bool,
    /// Each hand's reach under way: its motion, its start on the plan clock (s) and the contact
    /// it is for (world).
    reaches: [Option<(PoseTrajectory, f64, Isometry3<f64>)>; 2],
    /// Released hands carried with the pelvis: their pose in its planar frame.
    carried: [Option<Isometry3<f64>>; 2],
    stabilizer: Stabilizer,
    estimator: DcmEstimator,
    tilt_rate: TiltRate,
    tilt_damping: TiltDamping,
    /// The heel rising about the toe of the foot about to swing up a step, if one is.
    toe_off: Option<(EndEffector, ToeOff)>,
    /// The foot damping's rotation of each foot since it landed (world x, y; rad).
    foot_turn: [Vector2<f64>; 2],
    support: SupportPolygon,
    targets: Targets,
    balance: BalanceStatus,
}

impl DynamicWalker {
    /// A walker for a robot of weight `weight_n` (N) with soles `sole`.
    pub fn new(
        config: &ControllerConfig,
        sole: SoleRectangle,
        weight_n: f64,
        targets: Targets,
    ) -> Self {
        Self {
            config: *config,
            sole,
            touchdown_force: config.touchdown_force_fraction * weight_n,
            release_force: config.release_force_fraction * weight_n,
            sequence: None,
            running: false,
            started: false,
            to_world: Isometry3::identity(),
            clock: 0.0,
            phase: 0,
            transition: 0,
            late_s: None,
            settle_s: 0.0,
            touchdown: Debounce::default(),
            cursor: 0,
            swing: None,
            stop: None,
            blind: false,
            reaches: [None; 2],
            carried: [None; 2],
            stabilizer: Stabilizer::new(Default::default(), 1.0),
            estimator: DcmEstimator::default(),
            tilt_rate: TiltRate::default(),
            tilt_damping: TiltDamping::default(),
            toe_off: None,
            foot_turn: [Vector2::zeros(); 2],
            support: SupportPolygon::empty(),
            targets,
            balance: BalanceStatus::default(),
        }
    }

    /// Whether a dynamic walk is executing.
    pub fn running(&self) -> bool {
        self.running
    }

    /// Installs a dynamic sequence to execute from the next update; returns the previous one.
    pub fn load(&mut self, sequence: Box<PreparedSequence>) -> Option<Box<PreparedSequence>> {
        debug_assert!(sequence.dynamic.is_some());
        self.running = true;
        self.started = false;
        self.sequence.replace(sequence)
    }

    /// Whether the walk has begun (its contact set is the live one).
    pub fn started(&self) -> bool {
        self.started
    }

    /// Takes over the live contact set and anchors to start the walk from.
    pub fn take_over(&mut self, live: &Targets) {
        self.targets = *live;
        self.targets.unloading = None;
        self.targets.reaching = [false; 4];
        self.targets.end_effectors = [None; 4];
        self.targets.contact_velocity = [[0.0; 6]; 2];
        self.carried = [None; 2];
    }

    /// Stops executing (the contact set and anchors stay as they are).
    pub fn stop(&mut self) {
        self.running = false;
        self.started = false;
        self.stop = None;
    }

    /// Ends the walk early with a controlled stop (see the module docs); with
    /// `trust_force_sensors` false, touchdowns are confirmed by position and the stabilizer
    /// closes no loop on force-torque until the walk ends. A stop already under way goes on,
    /// and a distrust is kept. Returns false when no walk has begun (nothing moves that needs
    /// stopping). Allocation-free.
    pub fn stop_early(&mut self, trust_force_sensors: bool) -> bool {
        if !self.started {
            return false;
        }
        if let Some(stop) = &mut self.stop {
            stop.trust_force_sensors &= trust_force_sensors;
            return true;
        }
        self.stop = Some(Stop {
            trust_force_sensors,
        });
        let Some(phase) = self.current_phase() else {
            // Settling after the last phase: the walk is coming to rest already.
            return true;
        };
        let (current, transition, now) = (self.phase, self.transition, self.clock);
        let duration = self.plan().config.stop_double_support_s;
        let to_world = self.to_world;
        let plan = self
            .sequence
            .as_mut()
            .and_then(|s| s.dynamic.as_deref_mut())
            .expect("the walker runs only dynamic sequences");
        let last = plan.footsteps.end_early(current, transition, now, duration);
        let [Some(left), Some(right)] = last.feet else {
            unreachable!("a double support stands on both feet");
        };
        let rest = ((to_world * left).translation.vector.xy()
            + (to_world * right).translation.vector.xy())
            / 2.0;
        let from = match phase.support {
            Support::Single(_) => phase.end_s(),
            Support::Double { .. } => now,
        };
        plan.pattern.end_early(from, rest, duration);
        // A lift-off that waited for its foot to unload is cancelled: no foot lifts any more.
        if matches!(phase.support, Support::Double { .. }) {
            self.late_s = None;
        }
        true
    }

    /// Whether the feet's force-torque readings are trusted (false during a stop that
    /// distrusts them).
    pub fn trusts_force_sensors(&self) -> bool {
        self.stop.is_none_or(|stop| stop.trust_force_sensors)
    }

    /// The contact set, anchors and set-points of the last update.
    pub fn targets(&self) -> &Targets {
        &self.targets
    }

    /// The live targets, to turn their anchors with the estimate's heading.
    pub fn targets_mut(&mut self) -> &mut Targets {
        &mut self.targets
    }

    /// The balance readings of the last update.
    pub fn balance(&self) -> &BalanceStatus {
        &self.balance
    }

    /// The loaded sequence and the pose of its frame in the world (set when the walk begins).
    pub fn sequence_in_world(&self) -> Option<(&PreparedSequence, &Isometry3<f64>)> {
        Some((self.sequence.as_deref()?, &self.to_world))
    }

    /// The posture reference: the stance the current phases lead to.
    pub fn posture(&self) -> Option<&DVector<f64>> {
        let sequence = self.sequence.as_ref()?;
        Some(&sequence.stances[self.stance_index()].posture)
    }

    /// `config` with the dynamic gait's QP overrides.
    pub fn qp_config(&self, config: &ControllerConfig) -> ControllerConfig {
        let dynamic = &self.plan().config;
        ControllerConfig {
            hand_weight: dynamic.hand_weight.unwrap_or(config.hand_weight),
            com_gain: dynamic.com_gain.unwrap_or(config.com_gain),
            ..*config
        }
    }

    /// The current phase.
    pub fn phase(&self) -> Phase {
        if !self.started {
            return Phase::None;
        }
        match self.current_phase().map(|p| p.support) {
            None => Phase::Settle,
            Some(Support::Double { .. }) if self.late_s.is_some() => Phase::LateLiftOff,
            Some(Support::Double { .. }) => Phase::DoubleSupport,
            Some(Support::Single(_)) if self.late_s.is_some() => Phase::LateTouchdown,
            Some(Support::Single(_)) => Phase::SingleSupport,
        }
    }

    /// Index of the stance being moved towards and the stance count.
    pub fn progress(&self) -> (usize, usize) {
        (
            self.stance_index(),
            self.sequence.as_ref().map_or(0, |s| s.len()),
        )
    }

    /// One tick: starts the walk on the first call after `load`, advances the plan clock and its
    /// phases, runs the stabilizer and refreshes the targets.
    pub fn update(&mut self, feedback: &Feedback, sensors: &Sensors, dt: f64) -> Progress {
        if !self.started {
            if !on_both_feet(&self.targets) {
                self.running = false;
                return Progress::Fault(FaultCode::NotOnBothFeet);
            }
            self.begin(feedback);
        } else if let Some(late) = &mut self.late_s {
            *late += dt;
        } else {
            self.clock += dt;
        }
        self.blind = !(sensors.measured && self.trusts_force_sensors());
        let mut progress = self.advance(feedback, dt);
        if progress == Progress::Fault(FaultCode::MissedTouchdown) && self.stop.is_none() {
            // The foot may stand on the ground with a sensor that does not say so: stop, and
            // land it by position.
            self.stop_early(false);
            progress = Progress::Stopping(FaultCode::MissedTouchdown);
        }
        if matches!(progress, Progress::Done | Progress::Fault(_)) {
            self.running = false;
            self.started = false;
            self.stop = None;
        }
        self.stabilize(feedback, sensors, dt);
        self.raise_heel();
        self.refresh_targets(&feedback.pelvis);
        progress
    }

    fn plan(&self) -> &DynamicPlan {
        self.sequence
            .as_ref()
            .and_then(|s| s.dynamic.as_deref())
            .expect("the walker runs only dynamic sequences")
    }

    fn current_phase(&self) -> Option<SupportPhase> {
        self.plan().footsteps.phases.get(self.phase).copied()
    }

    fn stance_index(&self) -> usize {
        let Some(sequence) = self.sequence.as_ref() else {
            return 0;
        };
        let transitions = &self.plan().footsteps.transitions;
        transitions
            .get(self.transition)
            .or(transitions.last())
            .map_or(sequence.len() - 1, |t| t.stance)
    }

    /// Aligns the plan with the robot's feet, starts the pendulum at rest on the CoM.
    fn begin(&mut self, feedback: &Feedback) {
        let sequence = self.sequence.as_mut().expect("loaded");
        let first = &sequence.stances[0];
        let feet = |flags: &[bool; 4]| FEET.map(|f| flags[f as usize]);
        let poses = |all: &[Isometry3<f64>; 4]| FEET.map(|f| all[f as usize]);
        self.to_world = sequence_alignment(
            &poses(&first.targets),
            feet(&first.contacts),
            &poses(&self.targets.anchors),
            feet(&self.targets.contacts),
        );
        let plan = sequence.dynamic.as_mut().expect("a dynamic sequence");
        plan.pattern.transform(&self.to_world);
        let com = feedback.com.xy();
        plan.pattern.start_at_rest(com);
        let (stabilizer, omega) = (plan.config.stabilizer, plan.pattern.omega());
        self.stabilizer.reset(stabilizer, omega, com);
        self.estimator.reset();
        self.tilt_rate.reset();
        self.tilt_damping.reset();
        self.foot_turn = [Vector2::zeros(); 2];
        self.toe_off = None;
        self.started = true;
        self.clock = 0.0;
        self.phase = 0;
        self.transition = 0;
        self.late_s = None;
        self.settle_s = 0.0;
        self.touchdown.reset();
        self.cursor = 0;
        self.swing = None;
        self.reaches = [None; 2];
        self.begin_transition(feedback);
    }

    /// Moves through the phases the plan clock has passed.
    fn advance(&mut self, feedback: &Feedback, dt: f64) -> Progress {
        loop {
            let Some(phase) = self.current_phase() else {
                return self.settle(feedback);
            };
            match phase.support {
                Support::Single(swing) => {
                    let i = swing.foot as usize;
                    if !self.targets.contacts[i] && self.touched_down(feedback, &phase, &swing, dt)
                    {
                        self.land(swing.foot, feedback);
                    }
                    if self.clock < phase.end_s() {
                        return Progress::Running;
                    }
                    if !self.targets.contacts[i] {
                        self.clock = phase.end_s();
                        let late = self.late_s.get_or_insert(0.0);
                        if *late <= self.plan().config.late_touchdown_max_s {
                            return Progress::Running;
                        }
                        if self.stop.is_none() {
                            return Progress::Fault(FaultCode::MissedTouchdown);
                        }
                        if !self.at_foothold(feedback, &swing) {
                            return Progress::Fault(FaultCode::StopCouldNotLand);
                        }
                        // A stop lands a foot the ground holds up, whatever its sensor says.
                        self.land(swing.foot, feedback);
                    }
                }
                Support::Double { lift_off } => {
                    if self.clock < phase.end_s() {
                        return Progress::Running;
                    }
                    if let Some(foot) = lift_off {
                        let loaded = !self.blind
                            && feedback.normal_forces[foot as usize] > self.release_force;
                        if loaded {
                            self.clock = phase.end_s();
                            let late = self.late_s.get_or_insert(0.0);
                            if *late <= self.plan().config.late_lift_off_max_s {
                                return Progress::Running;
                            }
                        }
                        self.lift_off(foot, feedback);
                    }
                }
            }
            self.next_phase(feedback);
        }
    }

    /// The swing foot has touched down: confirmed by force-torque, or by position on a tick
    /// that is blind to force-torque.
    fn touched_down(
        &mut self,
        feedback: &Feedback,
        phase: &SupportPhase,
        swing: &SwingPlan,
        dt: f64,
    ) -> bool {
        if self.blind {
            self.clock >= phase.end_s() && self.at_foothold(feedback, swing)
        } else {
            self.touchdown_confirmed(feedback, phase, swing.foot as usize, dt)
        }
    }

    /// The swing sole is no higher than [`LANDING_HEIGHT_TOLERANCE_M`] above its foothold.
    fn at_foothold(&self, feedback: &Feedback, swing: &SwingPlan) -> bool {
        let foothold = (self.to_world * swing.landing).translation.z;
        feedback.poses[swing.foot as usize].translation.z - foothold <= LANDING_HEIGHT_TOLERANCE_M
    }

    /// Force-torque confirms the swing foot's contact (debounced), and the planned touchdown is
    /// near enough for it to count.
    fn touchdown_confirmed(
        &mut self,
        feedback: &Feedback,
        phase: &SupportPhase,
        foot: usize,
        dt: f64,
    ) -> bool {
        let pressed = feedback.normal_forces[foot] > self.touchdown_force;
        let held = self
            .touchdown
            .update(pressed, dt, self.config.touchdown_debounce_s);
        let due = self.clock >= phase.end_s() - self.plan().config.early_touchdown_s;
        due && held
    }

    /// Anchors a foot where it landed: at its contact surface's height when force-torque
    /// confirmed the contact, exactly where it is when position did (the ground holds it there,
    /// and leg odometry, then weighting both feet alike, must not see it move).
    fn land(&mut self, foot: EndEffector, feedback: &Feedback) {
        let e = foot as usize;
        let planned = match self.swing {
            Some(swing) if !self.blind => {
                swing.trajectory.landing().translation.z + self.plan().config.landing_depth_m
            }
            _ => feedback.poses[e].translation.z,
        };
        let mut anchor = feedback.poses[e];
        anchor.translation.z = planned;
        self.targets.contacts[e] = true;
        self.targets.anchors[e] = anchor;
        self.swing = None;
    }

    /// Releases `foot` and starts its swing (the next phase's).
    fn lift_off(&mut self, foot: EndEffector, feedback: &Feedback) {
        let next = self.plan().footsteps.phases[self.phase + 1];
        let Support::Single(plan) = next.support else {
            unreachable!("a lift-off is followed by its swing");
        };
        debug_assert_eq!(plan.foot, foot);
        let depth = self.plan().config.landing_depth_m;
        let mut landing = self.to_world * plan.landing;
        landing.translation.z -= depth;
        let trajectory = SwingTrajectory::new(
            feedback.poses[foot as usize],
            self.to_world * plan.apex,
            landing,
            next.duration_s,
        );
        self.targets.contacts[foot as usize] = false;
        self.toe_off = None;
        self.swing = Some(Swing {
            foot,
            trajectory,
            lift_off_s: next.start_s,
        });
    }

    fn next_phase(&mut self, feedback: &Feedback) {
        self.phase += 1;
        self.touchdown.reset();
        self.late_s = None;
        let ends_transition = self
            .plan()
            .footsteps
            .transitions
            .get(self.transition)
            .is_some_and(|t| t.phases.end == self.phase);
        if ends_transition {
            self.finish_transition();
            self.transition += 1;
            self.begin_transition(feedback);
        }
    }

    /// Releases the hands the next stance lets go of and starts the reaches of those it adds.
    fn begin_transition(&mut self, feedback: &Feedback) {
        let plan = self.plan();
        let Some(transition) = plan.footsteps.transitions.get(self.transition) else {
            return;
        };
        let phases = &plan.footsteps.phases;
        let start = phases[transition.phases.start].start_s;
        let duration = phases[transition.phases.end - 1].end_s() - start;
        let stance = &self.sequence.as_ref().expect("loaded").stances[transition.stance];
        let (contacts, targets) = (stance.contacts, stance.targets);
        for (k, hand) in EndEffector::HANDS.iter().enumerate() {
            let h = *hand as usize;
            if self.targets.contacts[h] && !contacts[h] {
                self.targets.contacts[h] = false;
                if self.config.carry_released_hands {
                    self.carried[k] =
                        Some(heading_frame(&feedback.pelvis).inverse() * self.targets.anchors[h]);
                }
            } else if !self.targets.contacts[h] && contacts[h] {
                let contact = self.to_world * targets[h];
                let goal = reach_goal(&contact, &self.config);
                let reach =
                    PoseTrajectory::new(feedback.poses[h], goal, duration, Profile::MinimumJerk)
                        .lifted(self.config.hand_approach_height_m);
                self.reaches[k] = Some((reach, start, contact));
            }
        }
    }

    /// The hands that reached are in contact.
    fn finish_transition(&mut self) {
        for (k, hand) in EndEffector::HANDS.iter().enumerate() {
            if let Some((_, _, contact)) = self.reaches[k].take() {
                let h = *hand as usize;
                self.targets.contacts[h] = true;
                self.targets.anchors[h] = contact;
                self.carried[k] = None;
            }
        }
    }

    /// After the plan: done once the CoM and the commanded DCM rest over the final feet.
    fn settle(&mut self, feedback: &Feedback) -> Progress {
        let rest = self.plan().pattern.rest();
        let tolerance = self.config.com_tolerance_m;
        let at_rest = (feedback.com.xy() - rest).norm() <= tolerance
            && (self.stabilizer.pendulum().dcm - rest).norm() <= tolerance;
        if at_rest {
            Progress::Done
        } else if self.settle_s > self.config.phase_timeout_s {
            Progress::Fault(FaultCode::Timeout(Phase::Settle))
        } else {
            Progress::Running
        }
    }

    /// Measures ZMP and DCM, runs the stabilizer and the foot compliance.
    fn stabilize(&mut self, feedback: &Feedback, sensors: &Sensors, dt: f64) {
        if self.current_phase().is_none() {
            self.settle_s += dt;
        }
        let plan = self.plan();
        let (config, omega) = (plan.config.stabilizer, plan.pattern.omega());
        let mut cursor = self.cursor;
        let reference = plan.pattern.sample(self.clock, &mut cursor);
        self.cursor = cursor;
        let ground = self.ground_height();
        let foot_wrenches = || {
            FEET.iter()
                .zip(&sensors.ft_origins)
                .map(|(f, o)| (&sensors.wrenches[*f as usize], o))
        };
        let zmp = if self.blind {
            None
        } else {
            pressure_centre(foot_wrenches(), ground, self.touchdown_force)
        };
        let imu = sensors.imu.filter(|_| sensors.measured);
        let mut com = feedback.com;
        if let (true, Some(imu)) = (config.imu_tilt, imu) {
            let pivot = zmp.unwrap_or(reference.zmp);
            let pivot = Vector3::new(pivot.x, pivot.y, ground);
            com = tilted_com(&com, &pivot, &imu, &sensors.base_rotation);
        }
        let dcm = self
            .estimator
            .update(com.xy(), dt, omega, config.velocity_filter_s);
        self.set_support();
        let measured = Measured { dcm, zmp };
        let command = self
            .stabilizer
            .update(&reference, &measured, &self.support, dt);
        self.targets.com = command.com;
        self.targets.com_velocity = command.com_velocity;
        let (elevation, rate) =
            support_elevation(&self.plan().footsteps.phases, self.phase, self.clock);
        self.targets.balance = Balance::Pendulum(ComHeight {
            height: elevation + self.plan().com_height,
            velocity: rate,
        });
        self.targets.torso_posture_weight = self.plan().config.torso_posture_weight;
        if self.blind {
            // No force-torque to comply with: the feet hold their anchors, and the compliance
            // starts afresh when readings come back (a tilt rate differenced across a gap, or
            // the rotation applied before it, would otherwise kick the stance foot).
            self.targets.contact_velocity = [[0.0; 6]; 2];
            self.foot_turn = [Vector2::zeros(); 2];
            self.tilt_rate.reset();
            self.tilt_damping.reset();
        } else {
            self.comply(command.zmp, sensors, ground, dt);
        }
        let offset = self.stabilizer.zmp_offset();
        let xy = |v: Vector2<f64>| [v.x, v.y];
        self.balance = BalanceStatus {
            zmp_reference: xy(reference.zmp),
            zmp_desired: xy(command.zmp),
            zmp_measured: zmp.map_or([f64::NAN; 2], xy),
            dcm_reference: xy(reference.dcm),
            dcm_measured: xy(dcm + offset),
            com_offset: xy(offset),
            planned_phase: self.current_phase().map(|phase| PlannedPhase {
                duration_s: phase.duration_s,
                timing: phase.timing,
            }),
        };
    }

    /// Foot damping, force difference, internal force and tilt damping as contact velocities for
    /// the desired ZMP `zmp`.
    fn comply(&mut self, zmp: Vector2<f64>, sensors: &Sensors, ground: f64, dt: f64) {
        let config = self.plan().config.stabilizer;
        self.targets.contact_velocity = [[0.0; 6]; 2];
        let feet = FEET.map(|f| {
            let e = f as usize;
            self.targets.contacts[e].then_some(&self.targets.anchors[e])
        });
        let inward = self.plan().config.zmp_inward_offset_m;
        let loads = distribute(zmp, feet, &self.sole, config.zmp_margin_m, inward);
        let forces = FEET.map(|f| sensors.wrenches[f as usize][2]);
        let toe_off = self.toe_off.map(|(foot, _)| foot as usize);
        for f in 0..2 {
            let (Some(load), true, false) = (loads[f], config.foot_damping, toe_off == Some(f))
            else {
                self.foot_turn[f] = Vector2::zeros();
                continue;
            };
            let wrench = [(&sensors.wrenches[FEET[f] as usize], &sensors.ft_origins[f])];
            if let Some(cop) = pressure_centre(wrench, ground, 0.5 * self.touchdown_force) {
                let turn = foot_damping(load.cop, cop, forces[f], self.foot_turn[f], &config);
                self.foot_turn[f] += turn * dt;
                self.targets.contact_velocity[f][3] = turn.x;
                self.targets.contact_velocity[f][4] = turn.y;
            }
        }
        if let (true, [Some(left), Some(right)]) = (config.force_difference, loads) {
            let [vl, vr] = force_difference_velocities(
                [left.share, right.share],
                forces,
                config.force_difference_gain,
                config.force_difference_max_speed,
            );
            self.targets.contact_velocity[0][2] = vl;
            self.targets.contact_velocity[1][2] = vr;
        }
        if let (true, [Some(_), Some(_)]) = (config.internal_force, feet) {
            let horizontal = FEET.map(|f| {
                let w = &sensors.wrenches[f as usize];
                Vector2::new(w[0], w[1])
            });
            let velocities = internal_force_velocities(
                horizontal,
                forces,
                config.internal_force_gain,
                config.internal_force_max_speed,
            );
            for (velocity, v) in self.targets.contact_velocity.iter_mut().zip(velocities) {
                velocity[0] = v.x;
                velocity[1] = v.y;
            }
        }
        if let (true, Some(imu)) = (config.tilt_damping, &sensors.imu) {
            let rate = self.tilt_rate.update(imu, dt, config.tilt_rate_filter_s);
            let (gain, max) = (config.tilt_damping_s, config.tilt_damping_max_rad);
            let turn = self.tilt_damping.velocity(rate, gain, max, dt);
            for (f, velocity) in self.targets.contact_velocity.iter_mut().enumerate() {
                if feet[f].is_some() {
                    velocity[3] += turn.x;
                    velocity[4] += turn.y;
                }
            }
        }
    }

    /// Toe-off (module [`super::toe_off`]): in the double support before a foot swings up a
    /// step, its heel rises about its toe over the support's last `toe_off_s`; a stop that
    /// cancels the lift-off lowers it again over as long.
    fn raise_heel(&mut self) {
        let config = self.plan().config;
        let phase = self.current_phase();
        let lifting = match phase.map(|p| p.support) {
            Some(Support::Double {
                lift_off: Some(foot),
            }) if self.stop.is_none() => Some(foot),
            _ => None,
        };
        if self.toe_off.is_none() {
            let (Some(foot), Some(phase)) = (lifting, phase) else {
                return;
            };
            let duration = config.toe_off_s.min(phase.duration_s);
            let start = phase.end_s() - duration;
            if config.toe_off_rad <= 0.0 || self.clock < start || !self.climbs(foot) {
                return;
            }
            let pitch = reachable_pitch(config.toe_off_rad, self.plan().toe_off_speed, duration);
            self.toe_off = Some((foot, ToeOff::rise(start, pitch, duration)));
        }
        let Some((foot, toe_off)) = &mut self.toe_off else {
            return;
        };
        let e = *foot as usize;
        if lifting != Some(*foot) {
            toe_off.lower(self.clock);
        }
        let velocity = toe_off.update(&mut self.targets.anchors[e], &self.sole, self.clock);
        for (k, v) in velocity.iter().enumerate() {
            self.targets.contact_velocity[e][k] += v;
        }
        if toe_off.lowered() {
            self.toe_off = None;
        }
    }

    /// The swing after this phase takes `foot` more than [`STEP_HEIGHT_M`] up.
    fn climbs(&self, foot: EndEffector) -> bool {
        let next = self.plan().footsteps.phases.get(self.phase + 1);
        let Some(Support::Single(swing)) = next.map(|p| p.support) else {
            return false;
        };
        let rise = (self.to_world * swing.landing).translation.z
            - self.targets.anchors[foot as usize].translation.z;
        swing.foot == foot && rise > STEP_HEIGHT_M
    }

    /// Mean height of the feet in contact (the surface the pendulum stands on).
    fn ground_height(&self) -> f64 {
        let (sum, count) = FEET
            .iter()
            .filter(|f| self.targets.contacts[**f as usize])
            .fold((0.0, 0.0), |(sum, n), f| {
                (
                    sum + self.targets.anchors[*f as usize].translation.z,
                    n + 1.0,
                )
            });
        if count > 0.0 { sum / count } else { 0.0 }
    }

    /// The polygon of the feet in contact.
    fn set_support(&mut self) {
        let standing = FEET
            .iter()
            .filter(|&&foot| self.targets.contacts[foot as usize])
            .map(|&foot| &self.targets.anchors[foot as usize]);
        self.support.set_soles(standing, &self.sole, |p| p);
    }

    fn refresh_targets(&mut self, pelvis: &Isometry3<f64>) {
        for foot in FEET {
            self.targets.end_effectors[foot as usize] = None;
        }
        if let Some(swing) = &self.swing {
            let (mut pose, mut velocity) = swing.trajectory.sample(self.clock - swing.lift_off_s);
            if let Some(late) = self.late_s {
                let speed = self.plan().config.late_descent_speed;
                pose.translation.z -= speed * late;
                velocity = [0.0, 0.0, -speed, 0.0, 0.0, 0.0];
            }
            self.targets.end_effectors[swing.foot as usize] = Some(PoseTarget { pose, velocity });
        }
        for (k, hand) in EndEffector::HANDS.iter().enumerate() {
            let h = *hand as usize;
            self.targets.reaching[h] = !self.targets.contacts[h] && self.reaches[k].is_some();
            self.targets.end_effectors[h] = if self.targets.contacts[h] {
                Some(PoseTarget {
                    pose: self.targets.anchors[h],
                    velocity: [0.0; 6],
                })
            } else if let Some((reach, start, _)) = &self.reaches[k] {
                let (pose, velocity) = reach.sample(self.clock - start);
                Some(PoseTarget { pose, velocity })
            } else {
                self.carried[k].map(|relative| PoseTarget {
                    pose: heading_frame(pelvis) * relative,
                    velocity: [0.0; 6],
                })
            };
        }
    }
}
