//! What the control thread and the service thread share: lock-free slots and atomics only.

use std::sync::atomic::{AtomicBool, AtomicU8, AtomicU64, Ordering};

use shm_types::ControlCommand;

use super::handoff::Slot;
use crate::controller::PreparedSequence;

/// A prepared sequence on its way to the control thread.
pub struct Submission {
    /// Id the daemon gave the sequence.
    pub id: u64,
    /// The prepared sequence.
    pub sequence: Box<PreparedSequence>,
}

/// How the control thread answered a submission.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u8)]
pub enum StartOutcome {
    /// Executing it.
    Started = 1,
    /// Another sequence is executing.
    Busy = 2,
    /// The controller is in fault (hold or abort acknowledges it).
    Faulted = 3,
    /// No fresh samples from the adapter: nothing could execute it.
    AdapterStale = 4,
}

impl StartOutcome {
    fn from_code(code: u8) -> Option<Self> {
        [Self::Started, Self::Busy, Self::Faulted, Self::AdapterStale]
            .into_iter()
            .find(|outcome| *outcome as u8 == code)
    }
}

/// The state both threads see.
pub struct Shared {
    /// Service → control thread: the next sequence to start.
    pub inbox: Slot<Submission>,
    /// Control → service thread: sequences to free (replaced or refused ones).
    pub outbox: Slot<PreparedSequence>,
    /// Control → service thread: `id << 8 | StartOutcome` of the last submission taken.
    start_result: AtomicU64,
    /// Service → control thread: a pending hold/abort (`ControlCommand as u8 + 1`, 0: none).
    control: AtomicU8,
    /// Control → service thread: count of control commands carried out.
    controls_done: AtomicU64,
    /// Main → control thread: shut down.
    pub stop: AtomicBool,
    /// Control → service thread: when the control loop last went round (CLOCK_MONOTONIC ns),
    /// so systemd's watchdog is fed only while the control thread is alive.
    heartbeat_ns: AtomicU64,
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
            stop: AtomicBool::new(false),
            heartbeat_ns: AtomicU64::new(shm_types::monotonic_ns()),
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

    /// Control thread: reports how submission `id` went.
    pub fn report_start(&self, id: u64, outcome: StartOutcome) {
        self.start_result
            .store(id << 8 | outcome as u64, Ordering::Release);
    }

    /// Service thread: the outcome for submission `id`, once reported.
    pub fn start_outcome(&self, id: u64) -> Option<StartOutcome> {
        let value = self.start_result.load(Ordering::Acquire);
        (value >> 8 == id)
            .then(|| StartOutcome::from_code((value & 0xff) as u8))
            .flatten()
    }

    /// Service thread: asks for a hold or abort; returns the completion count to wait for.
    pub fn request_control(&self, command: ControlCommand) -> u64 {
        let target = self.controls_done.load(Ordering::Acquire) + 1;
        self.control.store(command as u8 + 1, Ordering::Release);
        target
    }

    /// Service thread: how many control commands the control thread carried out.
    pub fn controls_done(&self) -> u64 {
        self.controls_done.load(Ordering::Acquire)
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

    /// Control thread: marks a control command as carried out.
    pub fn control_done(&self) {
        self.controls_done.fetch_add(1, Ordering::AcqRel);
    }
}

impl Default for Shared {
    fn default() -> Self {
        Self::new()
    }
}
