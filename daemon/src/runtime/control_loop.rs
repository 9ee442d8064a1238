//! The control thread: waits for samples, ticks the controller, sends commands.
//!
//! Realtime clock: the loop runs on a grid of absolute periods (`clock_nanosleep` on
//! CLOCK_MONOTONIC) aligned so that the adapter's samples, by their timestamps, fall mid-period.
//! Each period it sleeps until the period starts (never ticking early, so it never bursts),
//! waits for a sample stamped in this period until the period ends, ticks and sends the
//! command. With a spin time (`[runtime] spin_us`) it sleeps instead until `spin` before the
//! expected sample and busy-polls shared memory for it until `spin` after, so neither a
//! cross-process wake-up nor a late timer wake-up of up to `spin` lies between the sample and
//! the command; only then (adapter late) it blocks on the sample event. From half a period on
//! it polls from one command to the next sample and never sleeps. Deadline accounting:
//! - a command sent after the end of its sample's period is a deadline miss, and so is every
//!   period the overrun swallowed; the grid then continues with the first period that has not
//!   ended (no catching up);
//! - a period without a sample of its own is stale (an older sample is dropped unanswered, a
//!   sample stamped in a later period is answered in that period); `watchdog_periods` stale
//!   periods in a row trip the watchdog: the controller holds, a hold command goes out and the
//!   status reports the stale link; the grid re-aligns on the next sample, and also whenever the
//!   adapter's phase moves by more than a quarter period. A dynamic walk's hold is a controlled
//!   stop: instead of the hold command it goes on every period without samples, on the last valid
//!   state (an adapter that still receives commands brings the robot to rest), and when samples
//!   come back it goes on from them rather than setting up the world again.
//!
//! Lockstep clock: one tick per received sample, no sleeping; the watchdog trips after
//! `lockstep_timeout` of wall time without a sample.
//!
//! Samples come from the adapter pinned by iceoryx2 identity only (the ports refuse every other
//! publisher's, [`super::trust`]) and pass a [`SampleGate`]: one stamped in the future or older
//! than the last is refused and counted, so the grid only ever follows time that has passed. A
//! new adapter run (a new publisher pinned once the one before is gone) or a link back from
//! stale makes the controller set up its world and hold posture again from the next
//! measurement ([`Controller::relink`]). A sample the controller cannot use (an undecodable
//! flag, a joint outside its limits, NaN) faults it; until it has had one valid measurement
//! there is no safe posture, and no command goes out (the adapter holds on its own). The
//! status's fault text keeps the first cause of a fault and adds what followed ([`FaultLog`]);
//! another process publishing on `sensors` stops any walk (hold) and no walk starts until it is
//! gone.
//!
//! After each tick's command the tick's telemetry (estimate, set-points, support polygon, timing)
//! goes out on `telemetry` for observers ([`super::telemetry`]); nothing is published between
//! the sample and the command.
//!
//! After start-up nothing here allocates, frees, locks or logs per tick.

use std::sync::Arc;
use std::time::Duration;

use shm_types::{
    ClockMode, Code, ControlCommand, DaemonLoopPorts, DaemonState, DaemonStatus, FixedText,
    LinkState, SensorSample, ShmError, monotonic_ns, sleep_until,
};

use super::decode;
use super::fault_log::FaultLog;
use super::sample_gate::{SampleGate, Verdict};
use super::shared::{ControlOutcome, Shared, StartOutcome};
use super::snapshot::SnapshotWriter;
use super::stats::{LoopStats, MissRecord, log_histogram, record, summarize};
use super::telemetry;
use super::trust::AdapterFollower;
use crate::controller::{
    Command, CommandMode, Controller, ControllerState, FaultCode, PreparedSequence,
};

/// Longest single blocking wait, so stop requests and submissions are seen quickly.
const MAX_WAIT: Duration = Duration::from_millis(20);

/// Shortest blocking wait: the event's socket timeout has µs resolution, and a timeout that
/// rounds to 0 would block until the next notification.
const MIN_WAIT: Duration = Duration::from_micros(1);

/// Timing of the control loop.
#[derive(Debug, Clone, Copy)]
pub struct LoopTiming {
    /// Realtime or lockstep.
    pub clock: ClockMode,
    /// Control period (also the controller's `dt` in both modes).
    pub period_ns: u64,
    /// Realtime: stale periods in a row that trip the watchdog.
    pub watchdog_periods: u32,
    /// Lockstep: wall time without a sample that trips the watchdog.
    pub lockstep_timeout_ns: u64,
    /// Interval between status snapshots.
    pub status_interval_ns: u64,
    /// Realtime: busy-poll for the sample from this long before until this long after its
    /// expected time (0: sleep until the period starts and block on the sample event). At
    /// most half a period is used.
    pub spin_ns: u64,
}

/// When a tick's work was done.
#[derive(Debug, Clone, Copy)]
struct TickTimes {
    /// The controller's command was computed.
    computed_ns: u64,
    /// The command was sent.
    sent_ns: u64,
}

/// The control thread's state.
pub struct ControlLoop {
    controller: Controller,
    ports: DaemonLoopPorts,
    shared: Arc<Shared>,
    status_out: SnapshotWriter<DaemonStatus>,
    timing: LoopTiming,
    dof: usize,
    /// The sample being answered (the last one the gate accepted).
    sample: SensorSample,
    /// Where a received sample waits for the gate's verdict.
    incoming: SensorSample,
    gate: SampleGate,
    /// When the loop took `sample` from the subscriber.
    sample_taken_ns: u64,
    command: Command,
    command_seq: u64,
    /// Telemetries published (the last one's `seq`).
    telemetry_seq: u64,
    stats: LoopStats,
    link: LinkState,
    stale_in_row: u32,
    sequence_id: u64,
    faults: FaultLog,
    /// Follows which adapter is pinned and who else publishes on `sensors`.
    adapters: AdapterFollower,
    /// Another process than the pinned adapter publishes on `sensors` (checked every round).
    intruder: bool,
    last_state: ControllerState,
    /// The fault last recorded in `faults` (`None` outside a fault or controlled stop).
    last_fault: FaultCode,
    /// A sequence to free that did not fit into the outbox yet (never freed here).
    release_later: Option<Box<PreparedSequence>>,
    status: DaemonStatus,
    next_status_ns: u64,
}

impl ControlLoop {
    /// Sets up the loop; all buffers are allocated here.
    pub fn new(
        controller: Controller,
        ports: DaemonLoopPorts,
        shared: Arc<Shared>,
        status_out: SnapshotWriter<DaemonStatus>,
        timing: LoopTiming,
    ) -> Self {
        let dof = controller.robot().model.dof();
        let mut status = DaemonStatus::INITIAL;
        status.pid = std::process::id();
        status.clock = Code::new(timing.clock);
        status.rate_hz = 1e9 / timing.period_ns as f64;
        Self {
            controller,
            ports,
            shared,
            status_out,
            timing,
            dof,
            sample: SensorSample::ZERO,
            incoming: SensorSample::ZERO,
            gate: SampleGate::new(),
            sample_taken_ns: 0,
            command: Command::new(dof),
            command_seq: 0,
            telemetry_seq: 0,
            stats: LoopStats::new(),
            link: LinkState::Waiting,
            stale_in_row: 0,
            sequence_id: 0,
            faults: FaultLog::new(),
            adapters: AdapterFollower::new(),
            intruder: false,
            last_state: ControllerState::Idle,
            last_fault: FaultCode::None,
            release_later: None,
            status,
            next_status_ns: 0,
        }
    }

    /// Runs until [`Shared::stop`] is set; then holds, sends a final hold command and writes a
    /// final `Stopping` status.
    pub fn run(mut self) -> Result<LoopStats, ShmError> {
        let result = match self.timing.clock {
            ClockMode::Realtime => self.run_realtime(),
            ClockMode::Lockstep => self.run_lockstep(),
        };
        self.controller.hold();
        if self.command_seq > 0 {
            // The last command sent is a safe one (inside the limits): hold it.
            self.command.mode = CommandMode::Hold;
            self.command.qd_des.fill(0.0);
            self.send_command()?;
        }
        self.write_status(DaemonState::Stopping);
        result.map(|()| self.stats)
    }

    fn stopping(&self) -> bool {
        self.shared.stop.load(std::sync::atomic::Ordering::Relaxed)
    }

    fn run_realtime(&mut self) -> Result<(), ShmError> {
        let period = self.timing.period_ns;
        // A spin of half a period or more starts polling as soon as the previous command is
        // out: the thread never sleeps, so no timer wake-up can be late (a core of its own).
        let spin = self.timing.spin_ns.min(period);
        let loop_start = monotonic_ns();
        // `start` is the beginning of the current period; samples are expected at its middle.
        let mut start: Option<u64> = None;
        while !self.stopping() {
            let Some(period_start) = start else {
                // Not aligned (start-up or after a stale streak): tick on the first sample that
                // comes and align the grid on the adapter's sample clock.
                if self.wait_for_sample_until(monotonic_ns() + MAX_WAIT.as_nanos() as u64)? {
                    self.tick(monotonic_ns())?;
                    start = Some(self.aligned_start(monotonic_ns()));
                } else {
                    self.housekeeping();
                }
                continue;
            };
            let mut end = period_start + period;
            let mut expected = period_start + period / 2;
            let wake_at = if spin > 0 {
                expected - spin
            } else {
                period_start
            };
            sleep_until(wake_at);
            let wake_late = monotonic_ns().saturating_sub(wake_at);
            record(&mut self.stats.wakeup, wake_late);
            let fresh = (spin > 0
                && self.spin_for_current_sample(period_start, expected + spin)?)
                || self.wait_for_current_sample(period_start, end)?;
            let now = if fresh {
                let stamped = self.sample.timestamp_ns;
                if stamped >= end {
                    // Stamped in a later period (the adapter was late, or our wait overslept):
                    // the periods before it went without a sample; answer it in its own period.
                    // The gate refused stamps in the future, so this never runs ahead of now.
                    let skipped = (stamped - period_start) / period;
                    self.stats.stale_periods = self.stats.stale_periods.saturating_add(skipped);
                    end += skipped * period;
                    expected += skipped * period;
                }
                let tick_start = monotonic_ns();
                record(&mut self.stats.jitter, tick_start.abs_diff(expected));
                let times = self.tick(tick_start)?;
                if times.sent_ns > end {
                    // Our command is late, and every period we overran stays unanswered.
                    let late = times.sent_ns - end;
                    self.stats.deadline_misses =
                        self.stats.deadline_misses.saturating_add(1 + late / period);
                    let miss = MissRecord {
                        at_ns: tick_start - loop_start,
                        wake_late_ns: wake_late,
                        sample_offset_ns: stamped as i64 - expected as i64,
                        pickup_ns: self.sample_taken_ns.saturating_sub(stamped),
                        tick_ns: times.computed_ns - tick_start,
                        late_ns: late,
                    };
                    self.stats.miss_causes.count(miss.cause());
                    self.stats.misses.push(miss);
                }
                monotonic_ns()
            } else {
                self.stale_period();
                if self.link == LinkState::Stale && self.controller.stopping() {
                    self.tick_without_sample()?;
                }
                let now = monotonic_ns();
                if now > end {
                    self.stats.stale_periods = self
                        .stats
                        .stale_periods
                        .saturating_add((now - end) / period);
                }
                now
            };
            // Never catch up: continue with the first period that has not ended yet.
            let next = if now > end {
                end + ((now - end) / period + 1) * period
            } else {
                end
            };
            start = if self.link == LinkState::Stale && !self.controller.stopping() {
                None
            } else if fresh && self.sample.timestamp_ns.abs_diff(expected) > period / 4 {
                // The adapter's phase moved (another clock, a restart): follow it.
                Some(self.aligned_start(next))
            } else {
                Some(next)
            };
        }
        Ok(())
    }

    /// Busy-polls shared memory until `until` for a sample taken in this period (stamped at or
    /// after `start`); older ones are dropped as in [`Self::wait_for_current_sample`]. No
    /// system call: the subscriber reads shared memory and the clock is read through the vDSO.
    fn spin_for_current_sample(&mut self, start: u64, until: u64) -> Result<bool, ShmError> {
        loop {
            if self.take_sample()? {
                if self.sample.timestamp_ns >= start {
                    return Ok(true);
                }
            } else if monotonic_ns() >= until {
                return Ok(false);
            }
            std::hint::spin_loop();
        }
    }

    /// Waits until `end` for a sample taken in this period (stamped at or after `start`). An
    /// older one — it arrived late, or while the loop slept — is dropped unanswered, so a single
    /// late sample cannot leave the loop answering every sample one period late.
    fn wait_for_current_sample(&mut self, start: u64, end: u64) -> Result<bool, ShmError> {
        while self.wait_for_sample_until(end)? {
            if self.sample.timestamp_ns >= start {
                return Ok(true);
            }
        }
        Ok(false)
    }

    /// The first period start after `not_before` that puts the adapter's samples (in phase
    /// with the last one's timestamp) in the middle of the period.
    fn aligned_start(&self, not_before: u64) -> u64 {
        let period = self.timing.period_ns;
        let phase = (self.sample.timestamp_ns + period / 2) % period;
        let base = not_before - not_before % period + phase;
        if base >= not_before {
            base
        } else {
            base + period
        }
    }

    fn run_lockstep(&mut self) -> Result<(), ShmError> {
        let mut last_sample = monotonic_ns();
        while !self.stopping() {
            if self.wait_for_sample_until(monotonic_ns() + MAX_WAIT.as_nanos() as u64)? {
                last_sample = monotonic_ns();
                self.tick(last_sample)?;
            } else {
                self.housekeeping();
                if monotonic_ns() - last_sample > self.timing.lockstep_timeout_ns {
                    self.trip_watchdog();
                }
            }
        }
        Ok(())
    }

    /// Waits for a fresh sample until `deadline_ns`, in short slices so a stop request, a
    /// submission or a control command is handled meanwhile. Leaves it in `self.sample`.
    fn wait_for_sample_until(&mut self, deadline_ns: u64) -> Result<bool, ShmError> {
        loop {
            if self.take_sample()? {
                return Ok(true);
            }
            let now = monotonic_ns();
            if now >= deadline_ns || self.stopping() {
                return Ok(false);
            }
            // At least 1 µs: the socket timeout has µs resolution and 0 would mean "forever".
            let wait = Duration::from_nanos(deadline_ns - now).clamp(MIN_WAIT, MAX_WAIT);
            if !self.ports.wait_for_sample(wait)? {
                self.housekeeping();
            }
        }
    }

    /// Takes the pinned adapter's newest sample into `self.sample` if one arrived and the gate
    /// accepts it; a new adapter run makes the controller set up again from it.
    fn take_sample(&mut self) -> Result<bool, ShmError> {
        let fresh = self.ports.take_latest_sample(&mut self.incoming)?;
        let pin = self.ports.sensor_pin();
        self.gate.count_foreign(&pin);
        if !fresh {
            return Ok(false);
        }
        let taken = monotonic_ns();
        match self.gate.judge(&self.incoming, pin.pinned(), taken) {
            Verdict::Reject => return Ok(false),
            Verdict::Restarted => self.controller.relink(),
            Verdict::Accept => {}
        }
        std::mem::swap(&mut self.sample, &mut self.incoming);
        self.sample_taken_ns = taken;
        Ok(true)
    }

    /// One control step on `self.sample`. Between taking the sample and sending the command
    /// only the controller runs; submissions, control requests and the status come after.
    fn tick(&mut self, tick_start: u64) -> Result<TickTimes, ShmError> {
        if self.link == LinkState::Stale && !self.controller.stopping() {
            // Whatever happened while the link was down, start from what is measured now. A
            // controlled stop that ran on without samples goes on from the measurement instead.
            self.controller.relink();
        }
        self.link = LinkState::Fresh;
        self.stale_in_row = 0;
        let commanded = self.control_step();
        let computed_ns = monotonic_ns();
        if commanded {
            self.send_command()?;
        }
        let sent_ns = monotonic_ns();
        record(&mut self.stats.tick, computed_ns - tick_start);
        if commanded {
            record(
                &mut self.stats.latency,
                sent_ns.saturating_sub(self.sample.timestamp_ns),
            );
        }
        self.stats.ticks += 1;
        self.publish_telemetry(commanded, computed_ns - tick_start, sent_ns);
        let changed = self.note_state_change();
        self.housekeeping();
        if changed || sent_ns >= self.next_status_ns {
            self.write_status(self.daemon_state());
        }
        Ok(TickTimes {
            computed_ns,
            sent_ns,
        })
    }

    /// Decodes `self.sample` and ticks the controller on it; returns whether a command is ready.
    fn control_step(&mut self) -> bool {
        let dt = self.timing.period_ns as f64 * 1e-9;
        match decode::measurement(&self.sample, self.dof) {
            Ok(measurement) => self.controller.tick(&measurement, dt, &mut self.command),
            Err(fault) => self
                .controller
                .refuse_measurement(fault, dt, &mut self.command),
        }
    }

    fn send_command(&mut self) -> Result<(), ShmError> {
        self.command_seq += 1;
        let (seq, answers, n) = (self.command_seq, self.sample.seq, self.dof);
        let command = &self.command;
        self.ports.send_command(|out| {
            out.seq = seq;
            out.answers_seq = answers;
            out.joint_count = n as u32;
            out.mode = Code::new(match command.mode {
                CommandMode::Hold => shm_types::CommandMode::Hold,
                CommandMode::Track => shm_types::CommandMode::Track,
            });
            out.q_des[..n].copy_from_slice(command.q_des.as_slice());
            out.qd_des[..n].copy_from_slice(command.qd_des.as_slice());
        })
    }

    /// Publishes the tick's telemetry for observers: after the command, so it never delays one. A
    /// failed publication costs the observers one message (a gap in its `seq`) and is counted;
    /// it does not stop the robot.
    fn publish_telemetry(&mut self, commanded: bool, compute_ns: u64, sent_ns: u64) {
        self.telemetry_seq += 1;
        let state = self.daemon_state();
        let controller = self.controller.telemetry();
        let published = self.ports.publish_telemetry(|out| {
            out.seq = self.telemetry_seq;
            out.tick = self.stats.ticks;
            out.sample_seq = self.sample.seq;
            out.sample_timestamp_ns = self.sample.timestamp_ns;
            out.command_seq = if commanded { self.command_seq } else { 0 };
            out.sent_ns = sent_ns;
            out.compute_ns = compute_ns;
            out.deadline_misses = self.stats.deadline_misses;
            telemetry::fill(out, state, &controller);
        });
        if published.is_err() {
            self.stats.telemetry_failures += 1;
        }
    }

    /// Realtime, the link stale: a controlled stop goes on without samples, so an adapter that
    /// still receives commands brings the robot to rest (`Controller::tick_without_measurement`).
    fn tick_without_sample(&mut self) -> Result<(), ShmError> {
        let dt = self.timing.period_ns as f64 * 1e-9;
        if self
            .controller
            .tick_without_measurement(dt, &mut self.command)
        {
            self.send_command()?;
        }
        if self.note_state_change() {
            self.write_status(self.daemon_state());
        }
        Ok(())
    }

    /// Realtime: a period ended without a fresh sample.
    fn stale_period(&mut self) {
        self.stats.stale_periods = self.stats.stale_periods.saturating_add(1);
        self.stale_in_row += 1;
        if self.stale_in_row >= self.timing.watchdog_periods {
            self.trip_watchdog();
        }
    }

    /// No fresh sample for too long: hold and report (once per stale streak).
    fn trip_watchdog(&mut self) {
        if self.link == LinkState::Stale || self.link == LinkState::Waiting {
            return;
        }
        self.link = LinkState::Stale;
        self.stats.watchdog_trips += 1;
        self.faults
            .record("adapter link stale: no fresh sensor sample within the watchdog time");
        if self.controller.status().state == ControllerState::Executing {
            self.controller.hold();
        }
        if self.timing.clock == ClockMode::Realtime && self.controller.stopping() {
            // A dynamic walk's controlled stop goes on without samples, period by period.
            self.write_status(self.daemon_state());
            return;
        }
        // Tell the adapter to hold too, in case only its samples are lost.
        self.command.mode = CommandMode::Hold;
        if self.command_seq > 0 {
            // A send failure here cannot be acted upon beyond what the status already says.
            let _ = self.send_command();
        }
        self.write_status(self.daemon_state());
    }

    /// Handles control commands and submissions, hands freed sequences out and shows the
    /// service thread that this thread is alive.
    fn housekeeping(&mut self) {
        self.shared.beat(monotonic_ns());
        if self.check_adapters() {
            self.write_status(self.daemon_state());
        }
        if let Some(sequence) = self.release_later.take() {
            self.release(sequence);
        }
        if let Some(command) = self.shared.take_control() {
            let outcome = self.carry_out(command);
            self.shared.control_done(outcome);
            self.note_state_change();
            self.write_status(self.daemon_state());
        }
        if let Some(submission) = self.shared.inbox.take() {
            let outcome = if self.link != LinkState::Fresh {
                self.release(submission.sequence);
                StartOutcome::AdapterStale
            } else if self.intruder {
                self.release(submission.sequence);
                StartOutcome::SecondAdapter
            } else {
                match self.controller.start(submission.sequence) {
                    Ok(previous) => {
                        if let Some(previous) = previous {
                            self.release(previous);
                        }
                        self.sequence_id = submission.id;
                        self.faults.clear();
                        StartOutcome::Started
                    }
                    Err((refused, why)) => {
                        self.release(refused);
                        StartOutcome::Refused(why)
                    }
                }
            };
            self.shared.report_start(submission.ticket, outcome);
            self.note_state_change();
            self.write_status(self.daemon_state());
        }
    }

    /// Hold or abort: acknowledges a fault (if it can be) and holds.
    fn carry_out(&mut self, command: ControlCommand) -> ControlOutcome {
        if command == ControlCommand::Query {
            return ControlOutcome::Done;
        }
        if let Err(refusal) = self.controller.reset() {
            return ControlOutcome::NotAcknowledged(refusal);
        }
        match command {
            ControlCommand::Abort => self.controller.abort(),
            _ => self.controller.hold(),
        }
        self.faults.clear();
        ControlOutcome::Done
    }

    /// Hands a sequence to the service thread to free (or keeps it until the outbox is free).
    fn release(&mut self, sequence: Box<PreparedSequence>) {
        if let Err(sequence) = self.shared.outbox.put(sequence) {
            self.release_later = Some(sequence);
        }
    }

    /// Follows the controller's state: records the cause of a new fault (a controlled stop
    /// reports its cause when it begins, and a fault that ends the stop after it), forgets old
    /// faults when a walk ends `done`. Returns whether the state or the fault changed.
    fn note_state_change(&mut self) -> bool {
        let status = self.controller.status();
        let faulted = matches!(
            status.state,
            ControllerState::Fault | ControllerState::ControlledStop
        );
        let new_fault =
            faulted && status.fault != FaultCode::None && status.fault != self.last_fault;
        if status.state == self.last_state && !new_fault {
            return false;
        }
        if new_fault {
            self.faults
                .record(status.fault.describe_for(self.controller.robot()));
        }
        if status.state == ControllerState::Done {
            self.faults.clear();
        }
        self.last_fault = if faulted {
            status.fault
        } else {
            FaultCode::None
        };
        self.last_state = status.state;
        true
    }

    /// Follows the pinned adapter (let go once it is gone) and whether another process
    /// publishes on `sensors`: while one does, a walk is stopped with hold and none starts
    /// (its samples never reach the controller). Returns whether that changed.
    fn check_adapters(&mut self) -> bool {
        let intruder = self
            .adapters
            .check(&self.ports, &self.shared.adapter, monotonic_ns());
        let onset = intruder && !self.intruder;
        if onset && self.controller.status().state == ControllerState::Executing {
            self.controller.hold();
            match self.ports.sensor_pin().last_refused() {
                Some(from) => self.faults.record(format_args!(
                    "walk stopped: publisher {from} also publishes on sensors"
                )),
                None => self
                    .faults
                    .record("walk stopped: another process publishes on sensors"),
            }
        }
        let changed = intruder != self.intruder;
        self.intruder = intruder;
        changed
    }

    fn daemon_state(&self) -> DaemonState {
        match self.controller.status().state {
            ControllerState::Idle => DaemonState::Idle,
            ControllerState::Holding => DaemonState::Holding,
            ControllerState::Executing => DaemonState::Executing,
            ControllerState::ControlledStop => DaemonState::ControlledStop,
            ControllerState::Done => DaemonState::Done,
            ControllerState::Fault => DaemonState::Fault,
        }
    }

    /// Writes a status snapshot for the service thread. No allocation.
    fn write_status(&mut self, state: DaemonState) {
        let controller = self.controller.status();
        let status = &mut self.status;
        status.timestamp_ns = monotonic_ns();
        status.state = Code::new(state);
        status.sequence_id = self.sequence_id;
        status.stance_index = controller.stance_index;
        status.stance_count = controller.stance_count;
        status.phase = FixedText::new(controller.phase.name());
        status.com = controller.com;
        status.left_foot = controller.left_foot;
        status.right_foot = controller.right_foot;
        status.fault = *self.faults.text();
        status.stop_s = controller.stop_s;
        status.link = Code::new(self.link);
        status.adapter_holding = self.sample.adapter_holding;
        status.rejected_samples = self.gate.rejected();
        status.last_rejection = *self.gate.last_rejection();
        status.ticks = self.stats.ticks;
        status.deadline_misses = self.stats.deadline_misses;
        status.stale_periods = self.stats.stale_periods;
        status.watchdog_trips = self.stats.watchdog_trips;
        status.tick_us = summarize(&self.stats.tick);
        status.latency_us = summarize(&self.stats.latency);
        status.jitter_us = summarize(&self.stats.jitter);
        status.tick_histogram = log_histogram(&self.stats.tick);
        status.latency_histogram = log_histogram(&self.stats.latency);
        status.jitter_histogram = log_histogram(&self.stats.jitter);
        self.status_out.write(&self.status);
        self.next_status_ns = self.status.timestamp_ns + self.timing.status_interval_ns;
    }
}
