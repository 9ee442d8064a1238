//! What the control thread and the service thread share: lock-free slots and atomics only.

use std::sync::atomic::{AtomicBool, AtomicU8, AtomicU64, Ordering};

use shm_types::ControlCommand;

use super::handoff::Slot;
use super::trust::AdapterTrust;
use crate::controller::{PreparedSequence, ResetRefusal, StartRefusal};

/// A prepared sequence on its way to the control thread.
pub struct Submission {
    /// Numbers every hand-over (refused ones too), so an outcome is never mistaken for another's.
    pub ticket: u64,
    /// Id the sequence gets if it starts (ids count started sequences only).
    pub id: u64,
    /// The prepared sequence.
    pub sequence: Box<PreparedSequence>,
}

/// How the control thread answered a submission.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StartOutcome {
    /// Executing it.
    Started,
    /// The controller refused to start it (busy, in fault, no valid measurement, not upright,
    /// not on both feet for a dynamic walk).
    Refused(StartRefusal),
    /// No fresh samples from the adapter: nothing could execute it.
    AdapterStale,
    /// Another process than the adapter walkd follows publishes on `sensors`.
    SecondAdapter,
}

impl StartOutcome {
    /// The outcome's code in the result word: every outcome has its own, so a refusal added to
    /// [`StartRefusal`] does not compile until it has one here and in [`StartOutcome::from_code`].
    fn code(self) -> u8 {
        match self {
            Self::Started => 1,
            Self::AdapterStale => 2,
            Self::SecondAdapter => 3,
            Self::Refused(StartRefusal::Busy) => 10,
            Self::Refused(StartRefusal::Faulted) => 11,
            Self::Refused(StartRefusal::NoMeasurement) => 12,
            Self::Refused(StartRefusal::NotUpright) => 13,
            Self::Refused(StartRefusal::NotOnBothFeet) => 14,
            Self::Refused(StartRefusal::Stopping) => 15,
        }
    }

    /// The outcome of a code written by [`StartOutcome::code`].
    fn from_code(code: u8) -> Option<Self> {
        Some(match code {
            1 => Self::Started,
            2 => Self::AdapterStale,
            3 => Self::SecondAdapter,
            10 => Self::Refused(StartRefusal::Busy),
            11 => Self::Refused(StartRefusal::Faulted),
            12 => Self::Refused(StartRefusal::NoMeasurement),
            13 => Self::Refused(StartRefusal::NotUpright),
            14 => Self::Refused(StartRefusal::NotOnBothFeet),
            15 => Self::Refused(StartRefusal::Stopping),
            _ => return None,
        })
    }
}

/// How the control thread carried out a hold or abort.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ControlOutcome {
    /// Done: holding (a fault was acknowledged).
    Done,
    /// The fault could not be acknowledged yet.
    NotAcknowledged(ResetRefusal),
}

impl ControlOutcome {
    /// The outcome's code in the outcome byte: every outcome has its own.
    fn code(self) -> u8 {
        match self {
            Self::Done => 0,
            Self::NotAcknowledged(ResetRefusal::NotUpright) => 1,
            Self::NotAcknowledged(ResetRefusal::Stopping) => 2,
        }
    }

    /// The outcome of a code written by [`ControlOutcome::code`] (the control thread writes
    /// no other).
    fn from_code(code: u8) -> Self {
        match code {
            1 => Self::NotAcknowledged(ResetRefusal::NotUpright),
            2 => Self::NotAcknowledged(ResetRefusal::Stopping),
            _ => Self::Done,
        }
    }
}

/// The state both threads see.
pub struct Shared {
    /// Service → control thread: the next sequence to start.
    pub inbox: Slot<Submission>,
    /// Control → service thread: sequences to free (replaced or refused ones).
    pub outbox: Slot<PreparedSequence>,
    /// Control → service thread: `ticket << 8 | StartOutcome` of the last submission taken.
    start_result: AtomicU64,
    /// Service → control thread: a pending hold/abort (`ControlCommand as u8 + 1`, 0: none).
    control: AtomicU8,
    /// Control → service thread: count of control commands carried out.
    controls_done: AtomicU64,
    /// Control → service thread: how the last one went ([`ControlOutcome::code`]).
    control_outcome: AtomicU8,
    /// Main → control thread: shut down.
    pub stop: AtomicBool,
    /// Control → service thread: when the control loop last went round (CLOCK_MONOTONIC ns),
    /// so systemd's watchdog is fed only while the control thread is alive.
    heartbeat_ns: AtomicU64,
    /// Both ways: the adapter walkd follows, and who else publishes on `sensors`.
    pub adapter: AdapterTrust,
}

impl Shared {
    /// Nothing pending.
    pub fn new() -> Self {
        Self {
            inbox: Slot::new(),
            outbox: Slot::new(),
            start_result: AtomicU64::new(0),
            control: AtomicU8::new(0),
            controls_done: AtomicU64::new(0),
            control_outcome: AtomicU8::new(0),
            stop: AtomicBool::new(false),
            heartbeat_ns: AtomicU64::new(shm_types::monotonic_ns()),
            adapter: AdapterTrust::new(),
        }
    }

    /// Control thread: the loop goes round (one atomic store).
    pub fn beat(&self, now_ns: u64) {
        self.heartbeat_ns.store(now_ns, Ordering::Relaxed);
    }

    /// Service thread: when the control loop last went round.
    pub fn last_beat_ns(&self) -> u64 {
        self.heartbeat_ns.load(Ordering::Relaxed)
    }

    /// Control thread: reports how the submission with `ticket` went.
    pub fn report_start(&self, ticket: u64, outcome: StartOutcome) {
        self.start_result
            .store(ticket << 8 | u64::from(outcome.code()), Ordering::Release);
    }

    /// Service thread: the outcome for the submission with `ticket`, once reported.
    pub fn start_outcome(&self, ticket: u64) -> Option<StartOutcome> {
        let value = self.start_result.load(Ordering::Acquire);
        (value >> 8 == ticket)
            .then(|| StartOutcome::from_code((value & 0xff) as u8))
            .flatten()
    }

    /// Service thread: asks for a hold or abort; returns the completion count to wait for.
    pub fn request_control(&self, command: ControlCommand) -> u64 {
        let target = self.controls_done.load(Ordering::Acquire) + 1;
        self.control.store(command as u8 + 1, Ordering::Release);
        target
    }

    /// Service thread: the outcome of the last control command once `target` (from
    /// [`Shared::request_control`]) of them were carried out.
    pub fn control_outcome(&self, target: u64) -> Option<ControlOutcome> {
        (self.controls_done.load(Ordering::Acquire) >= target)
            .then(|| ControlOutcome::from_code(self.control_outcome.load(Ordering::Acquire)))
    }

    /// Control thread: takes the pending control command, if any.
    pub fn take_control(&self) -> Option<ControlCommand> {
        match self.control.swap(0, Ordering::AcqRel) {
            0 => None,
            code => [
                ControlCommand::Query,
                ControlCommand::Hold,
                ControlCommand::Abort,
            ]
            .into_iter()
            .find(|command| *command as u8 + 1 == code),
        }
    }

    /// Control thread: marks a control command as carried out, with its outcome.
    pub fn control_done(&self, outcome: ControlOutcome) {
        self.control_outcome
            .store(outcome.code(), Ordering::Release);
        self.controls_done.fetch_add(1, Ordering::AcqRel);
    }
}

impl Default for Shared {
    fn default() -> Self {
        Self::new()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_start_outcome_round_trips_through_its_code() {
        let refusals = [
            StartRefusal::Busy,
            StartRefusal::Faulted,
            StartRefusal::NoMeasurement,
            StartRefusal::NotUpright,
            StartRefusal::NotOnBothFeet,
            StartRefusal::Stopping,
        ];
        let outcomes = [
            StartOutcome::Started,
            StartOutcome::AdapterStale,
            StartOutcome::SecondAdapter,
        ]
        .into_iter()
        .chain(refusals.map(StartOutcome::Refused));
        let shared = Shared::new();
        for (ticket, outcome) in (1..).zip(outcomes) {
            shared.report_start(ticket, outcome);
            assert_eq!(shared.start_outcome(ticket), Some(outcome));
        }
        for code in 0..=u8::MAX {
            if let Some(outcome) = StartOutcome::from_code(code) {
                assert_eq!(outcome.code(), code);
            }
        }
    }

    #[test]
    fn every_control_outcome_round_trips_through_its_code() {
        let shared = Shared::new();
        for outcome in [
            ControlOutcome::Done,
            ControlOutcome::NotAcknowledged(ResetRefusal::NotUpright),
            ControlOutcome::NotAcknowledged(ResetRefusal::Stopping),
        ] {
            let target = shared.request_control(ControlCommand::Hold);
            assert_eq!(shared.take_control(), Some(ControlCommand::Hold));
            shared.control_done(outcome);
            assert_eq!(shared.control_outcome(target), Some(outcome));
        }
    }
}
