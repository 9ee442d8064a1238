//! The state machine of the last loaded sequence's gait behind one interface: the static gait's
//! [`StateMachine`] (which also holds the contact set between walks) or the [`DynamicWalker`].
//! A dynamic walk takes over the static machine's contacts when it starts and hands them back
//! when it ends, however it ends.

use kinematics::robot::{EndEffector, SoleRectangle};
use nalgebra::{DVector, Isometry3, Vector2};

use super::config::ControllerConfig;
use super::gait::{DynamicWalker, Sensors};
use super::hand_clearance::RailAxis;
use super::machine::{Feedback, Progress, StateMachine, Targets};
use super::sequence::PreparedSequence;
use super::status::{BalanceStatus, Phase};
use stance::Gait;

/// Both gaits' state machines; see the module docs.
pub(crate) struct Sequencer {
    fallback: StateMachine,
    dynamic: DynamicWalker,
    /// The last loaded sequence is a dynamic one.
    dynamic_selected: bool,
}

impl Sequencer {
    /// Machines for a robot of weight `weight_n` (N) with soles `sole`.
    pub fn new(config: &ControllerConfig, sole: SoleRectangle, weight_n: f64) -> Self {
        let fallback = StateMachine::new(config, sole, weight_n);
        let dynamic = DynamicWalker::new(config, sole, weight_n, *fallback.targets());
        Self {
            fallback,
            dynamic,
            dynamic_selected: false,
        }
    }

    /// Declares the feet standing when the world frame is set up (anchored at `poses`).
    pub fn set_standing(&mut self, standing: [bool; 2], poses: &[Isometry3<f64>; 4]) {
        self.fallback.set_standing(standing, poses);
    }

    /// Whether the current contacts suit `sequence`: a dynamic walk starts on both feet.
    pub fn on_both_feet_for(&self, sequence: &PreparedSequence) -> bool {
        sequence.dynamic.is_none() || on_both_feet(self.fallback.targets())
    }

    /// Installs a sequence to execute from the next update; returns the previous one of its gait.
    pub fn load(&mut self, sequence: Box<PreparedSequence>) -> Option<Box<PreparedSequence>> {
        self.dynamic_selected = sequence.dynamic.is_some();
        if self.dynamic_selected {
            self.dynamic.load(sequence)
        } else {
            self.fallback.load(sequence)
        }
    }

    /// Stops executing; the contact set and anchors stay as they are.
    pub fn stop(&mut self) {
        if self.dynamic.running() {
            self.dynamic.stop();
            self.fallback.adopt(self.dynamic.targets());
        }
        self.fallback.stop();
    }

    /// Ends a dynamic walk under way with a controlled stop (`DynamicWalker::stop_early`). The
    /// static gait stops only by putting a foot down, which it begins itself (a catch, a step
    /// taken back): true while it does; otherwise false (the static gait holds at once).
    pub fn stop_early(&mut self, trust_force_sensors: bool) -> bool {
        if self.dynamic.running() {
            self.dynamic.stop_early(trust_force_sensors)
        } else {
            self.fallback.putting_foot_down()
        }
    }

    /// Puts the static gait's foot in the air down at once, `tipped` (m) from below it, ending
    /// the walk (`StateMachine::catch_swing_foot`); false when there is none (or a dynamic walk
    /// runs).
    pub fn catch_swing_foot(&mut self, poses: &[Isometry3<f64>; 4], tipped: Vector2<f64>) -> bool {
        !self.dynamic.running() && self.fallback.catch_swing_foot(poses, tipped)
    }

    /// Whether the feet's force-torque readings are trusted: false during a controlled stop that
    /// distrusts them.
    pub fn trusts_force_sensors(&self) -> bool {
        !self.dynamic.running() || self.dynamic.trusts_force_sensors()
    }

    /// One tick of the running sequence. `sensors` is called only for a dynamic walk.
    pub fn update<'a>(
        &mut self,
        feedback: &Feedback,
        sensors: impl FnOnce() -> Sensors<'a>,
        dt: f64,
    ) -> Progress {
        if !self.dynamic.running() {
            return self.fallback.update(feedback, dt);
        }
        if !self.dynamic.started() {
            self.dynamic.take_over(self.fallback.targets());
        }
        let progress = self.dynamic.update(feedback, &sensors(), dt);
        if matches!(progress, Progress::Done | Progress::Fault(_)) {
            self.fallback.adopt(self.dynamic.targets());
        }
        progress
    }

    /// The live contact set, anchors and set-points: the dynamic walk's while it runs, else the
    /// static machine's (which takes a dynamic walk's over when it ends).
    pub fn targets(&self) -> &Targets {
        if self.dynamic.started() {
            self.dynamic.targets()
        } else {
            self.fallback.targets()
        }
    }

    /// Moves the live anchors by `motion`, a turn of the world they are held in (the
    /// estimate's heading correction).
    pub fn move_anchors(&mut self, motion: &Isometry3<f64>) {
        let targets = if self.dynamic.started() {
            self.dynamic.targets_mut()
        } else {
            self.fallback.targets_mut()
        };
        targets.move_anchors(motion);
    }

    /// World anchors of the feet in contact, for the estimator.
    pub fn foot_anchors(&self) -> [Option<&Isometry3<f64>>; 2] {
        self.targets().foot_anchors()
    }

    /// Hand reaches the static gait gave up in its walk (`StateMachine::give_up_reach`).
    pub fn reaches_given_up(&self) -> u32 {
        self.fallback.reaches_given_up()
    }

    /// The railings of the running gait's sequence, in the world (`hand_clearance`).
    pub fn railings(&self) -> impl Iterator<Item = RailAxis> + Clone + '_ {
        let running = if self.dynamic_selected {
            self.dynamic.sequence_in_world()
        } else {
            self.fallback.sequence_in_world()
        };
        running
            .into_iter()
            .flat_map(|(sequence, to_world)| sequence.railings_in(to_world))
    }

    /// The posture reference of the stance being moved towards.
    pub fn posture(&self) -> Option<&DVector<f64>> {
        if self.dynamic_selected {
            self.dynamic.posture()
        } else {
            self.fallback.posture()
        }
    }

    /// The gait of the last loaded sequence (static before the first).
    pub fn gait(&self) -> Gait {
        if self.dynamic_selected {
            Gait::Dynamic
        } else {
            Gait::Static
        }
    }

    /// Current phase.
    pub fn phase(&self) -> Phase {
        if self.dynamic_selected {
            self.dynamic.phase()
        } else {
            self.fallback.phase()
        }
    }

    /// Index of the stance being moved towards and the stance count.
    pub fn progress(&self) -> (usize, usize) {
        if self.dynamic_selected {
            self.dynamic.progress()
        } else {
            self.fallback.progress()
        }
    }

    /// The QP tuning of the running gait: `config`, with the dynamic gait's overrides while a
    /// dynamic walk runs.
    pub fn qp_config(&self, config: &ControllerConfig) -> ControllerConfig {
        if self.dynamic.started() {
            self.dynamic.qp_config(config)
        } else {
            *config
        }
    }

    /// The dynamic walk's balance readings (kept after it ended, zero before the first).
    pub fn balance(&self) -> &BalanceStatus {
        self.dynamic.balance()
    }
}

/// Both feet are in the contact set.
pub(crate) fn on_both_feet(targets: &Targets) -> bool {
    targets.contacts[EndEffector::LeftFoot as usize]
        && targets.contacts[EndEffector::RightFoot as usize]
}
