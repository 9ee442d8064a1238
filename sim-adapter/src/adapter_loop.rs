//! The adapter loop shared by the simulator and hardware adapters.

use std::time::Duration;

use shm_types::{
    AdapterPorts, ClockMode, CommandMode, DecodeError, JointCommand, MAX_JOINTS, SensorSample,
    ShmError, monotonic_ns, sleep_then_spin_until, sleep_until,
};

use crate::RobotIo;

/// Longest single wait, so a stop request is seen quickly.
const MAX_WAIT: Duration = Duration::from_millis(20);

/// How the loop is clocked and when it holds.
#[derive(Debug, Clone, Copy)]
pub struct AdapterOptions {
    /// Realtime: a sample every period on absolute deadlines. Lockstep: the next sample when the
    /// command answering the previous one arrives.
    pub clock: ClockMode,
    /// Sample rate (realtime) and simulated time step `1 / rate_hz` (both modes).
    pub rate_hz: f64,
    /// Realtime: periods without a fresh command before holding position.
    pub watchdog_periods: u32,
    /// Lockstep: wall time without the awaited command before holding position (and
    /// re-publishing the current sample so a restarted daemon can pick up).
    pub lockstep_timeout: Duration,
    /// Realtime: the last part of each period spent busy-waiting instead of sleeping, so a late
    /// timer wake-up cannot delay a sample (zero: sleep through; see `sleep_then_spin_until`).
    pub spin: Duration,
}

/// What happened during a run.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct AdapterReport {
    /// Samples published.
    pub samples: u64,
    /// Fresh commands applied.
    pub commands: u64,
    /// Times the command watchdog tripped and the adapter started holding.
    pub watchdog_trips: u64,
    /// Realtime periods skipped because the loop overran.
    pub overruns: u64,
    /// Commands refused: an unknown mode, or a setpoint the robot rejected (NaN, wrong size).
    pub refused_commands: u64,
    /// Commands of another publisher than the daemon the adapter pinned (never applied).
    pub foreign_commands: u64,
}

/// Why the loop stopped early.
#[derive(Debug, thiserror::Error)]
pub enum AdapterError {
    /// The robot has more joints than the messages can carry.
    #[error("the robot has {0} joints, the protocol carries at most {MAX_JOINTS}")]
    TooManyJoints(usize),
    /// An IPC operation failed.
    #[error(transparent)]
    Ipc(#[from] ShmError),
}

/// The setpoint the robot is driven with: the daemon's latest command or a hold posture.
struct Setpoint {
    holding: bool,
    q: [f64; MAX_JOINTS],
    qd: [f64; MAX_JOINTS],
}

impl Setpoint {
    /// Hold the posture of `sample` (zero velocity).
    fn hold(&mut self, sample: &SensorSample) {
        self.holding = true;
        self.q = sample.q;
        self.qd = [0.0; MAX_JOINTS];
    }

    /// Follow `command` (a hold command keeps its posture with zero velocity); refuses a
    /// command whose mode the contract does not define.
    fn follow(&mut self, command: &JointCommand) -> Result<(), DecodeError> {
        let mode = command.mode.get().map_err(|e| e.in_field("mode"))?;
        self.holding = false;
        self.q = command.q_des;
        self.qd = match mode {
            CommandMode::Track => command.qd_des,
            CommandMode::Hold => [0.0; MAX_JOINTS],
        };
        Ok(())
    }
}

/// Logs a repeated problem once, then at most once per [`Throttle::INTERVAL_NS`] with the
/// count since, so a daemon sending bad commands at 1 kHz cannot flood the log.
struct Throttle {
    suppressed: u64,
    next_ns: u64,
}

impl Throttle {
    const INTERVAL_NS: u64 = 1_000_000_000;

    fn new() -> Self {
        Self {
            suppressed: 0,
            next_ns: 0,
        }
    }

    /// Whether to log now; `Some(n)`: log, saying `n` similar events were not logged.
    fn due(&mut self) -> Option<u64> {
        let now = monotonic_ns();
        if now < self.next_ns {
            self.suppressed += 1;
            return None;
        }
        self.next_ns = now + Self::INTERVAL_NS;
        Some(std::mem::take(&mut self.suppressed))
    }
}

/// The loop's state between periods.
struct Adapter<'a, R: RobotIo> {
    ports: &'a AdapterPorts,
    robot: &'a mut R,
    options: AdapterOptions,
    joints: usize,
    dt: f64,
    sample: SensorSample,
    command: JointCommand,
    setpoint: Setpoint,
    report: AdapterReport,
    refusals: Throttle,
    foreign: Throttle,
}

impl<R: RobotIo> Adapter<'_, R> {
    /// Reads the robot and publishes the next sample.
    fn publish(&mut self) -> Result<(), ShmError> {
        self.robot.read(&mut self.sample);
        self.sample.seq += 1;
        self.sample.joint_count = self.joints as u32;
        self.sample.adapter_holding = self.setpoint.holding.into();
        let sample = &self.sample;
        self.ports.publish_sample(|out| *out = *sample)?;
        self.report.samples += 1;
        Ok(())
    }

    /// Applies the current setpoint for one period. A setpoint the robot rejects (e.g. NaN)
    /// makes the adapter hold instead.
    fn apply(&mut self) {
        let n = self.joints;
        if let Err(error) = self
            .robot
            .write(&self.setpoint.q[..n], &self.setpoint.qd[..n], self.dt)
        {
            self.report.refused_commands += 1;
            if let Some(suppressed) = self.refusals.due() {
                tracing::error!(
                    %error,
                    since_last_report = suppressed,
                    "setpoint rejected by the robot: holding position"
                );
            }
            self.setpoint.hold(&self.sample);
            // The hold posture is the last reading, which the robot accepted before.
            let _ = self
                .robot
                .write(&self.setpoint.q[..n], &self.setpoint.qd[..n], self.dt);
        }
    }

    /// Starts holding because commands went stale.
    fn trip_watchdog(&mut self, why: &str) {
        if !self.setpoint.holding {
            tracing::warn!("{why}: holding position");
            self.report.watchdog_trips += 1;
        }
        self.setpoint.hold(&self.sample);
    }

    /// Takes a fresh command of the pinned daemon if one arrived (in lockstep only the one
    /// answering our last sample).
    fn take_command(&mut self, must_answer_last: bool) -> Result<bool, ShmError> {
        let fresh = self.ports.take_latest_command(&mut self.command)?;
        self.note_foreign_commands();
        if !fresh {
            return Ok(false);
        }
        if must_answer_last && self.command.answers_seq != self.sample.seq {
            return Ok(false);
        }
        let was_holding = self.setpoint.holding;
        if let Err(error) = self.setpoint.follow(&self.command) {
            self.report.refused_commands += 1;
            if let Some(suppressed) = self.refusals.due() {
                tracing::error!(
                    %error,
                    command = self.command.seq,
                    since_last_report = suppressed,
                    "command refused: holding position"
                );
            }
            self.setpoint.hold(&self.sample);
            return Ok(false);
        }
        if was_holding && self.report.commands > 0 {
            tracing::info!("commands are fresh again: following the daemon");
        }
        self.report.commands += 1;
        Ok(true)
    }

    /// Counts the commands the ports refused as another publisher's and logs who sent them
    /// (throttled like [`Throttle`]).
    fn note_foreign_commands(&mut self) {
        let refusals = self.ports.command_refusals();
        if refusals.count <= self.report.foreign_commands {
            return;
        }
        self.report.foreign_commands = refusals.count;
        if let Some(suppressed) = self.foreign.due() {
            let from = refusals
                .last
                .map(|peer| peer.to_string())
                .unwrap_or_default();
            tracing::error!(
                %from,
                node = %format_args!("{:x}", refusals.last.map_or(0, |peer| peer.node())),
                total = refusals.count,
                since_last_report = suppressed,
                "commands of another publisher refused: following only the daemon linked to"
            );
        }
    }

    fn run_realtime(&mut self, should_stop: &dyn Fn() -> bool) -> Result<(), ShmError> {
        let period = ((1e9 / self.options.rate_hz) as u64).max(1);
        let spin = (self.options.spin.as_nanos() as u64).min(period);
        let mut stale_periods = 0;
        self.publish()?;
        let mut deadline = monotonic_ns() + period;
        while wait_for_deadline(deadline, spin, should_stop) {
            if self.take_command(false)? {
                stale_periods = 0;
            } else {
                stale_periods += 1;
                if stale_periods >= self.options.watchdog_periods {
                    self.trip_watchdog("no fresh command within the watchdog periods");
                }
            }
            self.apply();
            self.publish()?;
            deadline += period;
            let now = monotonic_ns();
            if now > deadline {
                let skipped = (now - deadline) / period + 1;
                self.report.overruns += skipped;
                deadline += skipped * period;
            }
        }
        Ok(())
    }

    fn run_lockstep(&mut self, should_stop: &dyn Fn() -> bool) -> Result<(), ShmError> {
        let timeout = self.options.lockstep_timeout.as_nanos() as u64;
        self.publish()?;
        let mut last_progress = monotonic_ns();
        while !should_stop() {
            self.ports.wait_for_command(MAX_WAIT)?;
            if self.take_command(true)? {
                self.apply();
                self.publish()?;
                last_progress = monotonic_ns();
            } else if monotonic_ns() - last_progress > timeout {
                self.trip_watchdog("no command answered the last sample in time");
                // Time stands still in lockstep: re-publish the reading so a (re)started daemon
                // gets a sample to answer.
                self.publish()?;
                last_progress = monotonic_ns();
            }
        }
        Ok(())
    }
}

/// Sleeps until `deadline_ns` (busy-waiting its last `spin_ns`) in waits of at most
/// [`MAX_WAIT`], so a stop request is seen however long the period; false if one came.
fn wait_for_deadline(deadline_ns: u64, spin_ns: u64, should_stop: &dyn Fn() -> bool) -> bool {
    let slice = MAX_WAIT.as_nanos() as u64;
    loop {
        if should_stop() {
            return false;
        }
        let now = monotonic_ns();
        if deadline_ns.saturating_sub(now) <= slice + spin_ns {
            sleep_then_spin_until(deadline_ns, spin_ns);
            return true;
        }
        sleep_until(now + slice);
    }
}

/// Runs the adapter until `should_stop()` says so: publishes samples of `robot`, applies the
/// commands of the daemon it pinned (the first publisher heard on `commands`; another
/// publisher's commands are refused, counted and logged, and the next daemon is followed once
/// the pinned one is gone), and holds position whenever commands go stale (also before the
/// first command).
pub fn run_adapter<R: RobotIo>(
    ports: &AdapterPorts,
    robot: &mut R,
    options: &AdapterOptions,
    should_stop: &dyn Fn() -> bool,
) -> Result<AdapterReport, AdapterError> {
    let joints = robot.joint_count();
    if joints > MAX_JOINTS {
        return Err(AdapterError::TooManyJoints(joints));
    }
    let mut adapter = Adapter {
        ports,
        robot,
        options: *options,
        joints,
        dt: 1.0 / options.rate_hz,
        sample: SensorSample::ZERO,
        command: JointCommand::ZERO,
        setpoint: Setpoint {
            holding: true,
            q: [0.0; MAX_JOINTS],
            qd: [0.0; MAX_JOINTS],
        },
        report: AdapterReport::default(),
        refusals: Throttle::new(),
        foreign: Throttle::new(),
    };
    adapter.robot.read(&mut adapter.sample);
    adapter.setpoint.hold(&adapter.sample);
    match options.clock {
        ClockMode::Realtime => adapter.run_realtime(should_stop)?,
        ClockMode::Lockstep => adapter.run_lockstep(should_stop)?,
    }
    Ok(adapter.report)
}
