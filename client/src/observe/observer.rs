//! [`Observer`]: reads a running daemon's streams ([`super::source`]) and logs them on the
//! Foxglove channels ([`super::channels`]) of a context, whose sinks decide where they go (an MCAP
//! file, a WebSocket server, both). Messages another publisher sent on a stream are not recorded:
//! the observer names that publisher on `/faults` and in its report.

use std::collections::{BTreeMap, VecDeque};
use std::sync::Arc;
use std::sync::mpsc::{Receiver, RecvTimeoutError};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use anyhow::Context as _;
use foxglove::Context;
use foxglove::messages::log::Level;
use kinematics::robot::Robot;
use shm_types::{DaemonState, DaemonStatus, Refusals, SensorSample};

use super::channels::{Channels, Clock};
use super::description::description_urdf;
use super::links::LinkPoser;
use super::report::ObserverReport;
use super::source::{Batch, Source, yield_to_the_controller};

/// How often the robot description is logged again, so a viewer that connects (or seeks) later
/// still gets it.
pub const DESCRIPTION_PERIOD: Duration = Duration::from_secs(1);

/// Sensor samples kept to pair with the telemetry that answers them (over 0.5 s at 1 kHz).
const RECENT_SAMPLES: usize = 512;

/// An observation of one daemon, running on two threads of its own until [`Observer::finish`].
pub struct Observer {
    source: Source,
    worker: JoinHandle<anyhow::Result<ObserverReport>>,
}

impl Observer {
    /// Subscribes to the daemon serving `prefix` (which controls `robot`) and logs everything it
    /// publishes from now on to `context`'s sinks. Fails at once if no daemon serves `prefix`.
    pub fn start(prefix: &str, robot: Arc<Robot>, context: &Arc<Context>) -> anyhow::Result<Self> {
        let description = description_urdf(&robot)?;
        let channels = Channels::new(context, Arc::clone(&robot), Clock::now())?;
        let (source, batches) = Source::start(prefix)?;
        let poser = LinkPoser::new(robot);
        let worker = std::thread::Builder::new()
            .name("observer-log".to_owned())
            .spawn(move || {
                yield_to_the_controller();
                Logger::new(channels, poser, description).run(&batches)
            })
            .context("starting the observer's logging thread")?;
        Ok(Self { source, worker })
    }

    /// Stops observing once everything received so far is logged; returns what was seen.
    pub fn finish(self) -> anyhow::Result<ObserverReport> {
        let polled = self.source.stop();
        let logged = self
            .worker
            .join()
            .map_err(|_| anyhow::anyhow!("the observer's logging thread panicked"))?;
        polled?;
        logged
    }
}

/// The logging thread's state.
struct Logger {
    channels: Channels,
    poser: LinkPoser,
    description: String,
    recent: VecDeque<SensorSample>,
    report: ObserverReport,
    last_status: Option<(DaemonState, String)>,
    /// Messages refused per stream, as reported last.
    refused_seen: BTreeMap<String, u64>,
}

impl Logger {
    fn new(channels: Channels, poser: LinkPoser, description: String) -> Self {
        Self {
            channels,
            poser,
            description,
            recent: VecDeque::with_capacity(RECENT_SAMPLES),
            report: ObserverReport::default(),
            last_status: None,
            refused_seen: BTreeMap::new(),
        }
    }

    /// Logs batches until the source ends; the description first and then every
    /// [`DESCRIPTION_PERIOD`].
    fn run(mut self, batches: &Receiver<Batch>) -> anyhow::Result<ObserverReport> {
        let mut described = Instant::now();
        self.log_description();
        loop {
            match batches.recv_timeout(DESCRIPTION_PERIOD / 4) {
                Ok(batch) => self.log_batch(&batch)?,
                Err(RecvTimeoutError::Timeout) => {}
                Err(RecvTimeoutError::Disconnected) => return Ok(self.report),
            }
            if described.elapsed() >= DESCRIPTION_PERIOD {
                described += DESCRIPTION_PERIOD;
                self.log_description();
            }
        }
    }

    fn log_description(&self) {
        let now = self.channels.clock().unix_ns(shm_types::monotonic_ns());
        self.channels.log_description(&self.description, now);
    }

    fn log_batch(&mut self, batch: &Batch) -> anyhow::Result<()> {
        for sample in &batch.samples {
            self.report.samples.see(sample.seq);
            self.channels.log_sample(sample);
            if self.recent.len() == RECENT_SAMPLES {
                self.recent.pop_front();
            }
            self.recent.push_back(*sample);
        }
        for command in &batch.commands {
            self.report.commands.see(command.seq);
            self.channels.log_command(command);
        }
        for telemetry in &batch.telemetry {
            self.report.telemetry.see(telemetry.seq);
            let sample = self.recent.iter().rev().find(|s| {
                s.seq == telemetry.sample_seq && s.timestamp_ns == telemetry.sample_timestamp_ns
            });
            if sample.is_none() {
                self.report.ticks_without_sample += 1;
            }
            self.channels.log_tick(telemetry, sample, &mut self.poser)?;
        }
        for status in &batch.statuses {
            self.report.statuses += 1;
            self.channels.log_status(status);
            self.log_changes(status);
        }
        for (service, refusals) in &batch.refused {
            self.note_intruder(service, refusals);
        }
        Ok(())
    }

    /// Reports messages another publisher than the pinned one sent on `service` (refused, not
    /// recorded): counted in the report, and logged on `/faults` when the publisher is new.
    fn note_intruder(&mut self, service: &str, refusals: &Refusals) {
        let Some(from) = refusals.last else {
            return;
        };
        let kind = service.rsplit('/').next().unwrap_or(service);
        let intruder = format!("{kind}: {from}");
        let t = self.channels.clock().unix_ns(shm_types::monotonic_ns());
        let seen = self.refused_seen.entry(service.to_owned()).or_default();
        let new = refusals.count.saturating_sub(*seen);
        *seen = refusals.count;
        let known = self.report.intruders.contains_key(&intruder);
        // What was refused since the last report is counted for its last sender.
        *self.report.intruders.entry(intruder.clone()).or_default() += new;
        if !known {
            self.channels.log_fault(
                Level::Error,
                format!("{intruder} also publishes on {service}: its messages are not recorded"),
                t,
            );
        }
    }

    /// Logs a state change (info) and a new fault (error) on `/faults`.
    fn log_changes(&mut self, status: &DaemonStatus) {
        let Ok(state) = status.state.get() else {
            return;
        };
        let fault = status.fault.as_str().to_owned();
        let t = self.channels.clock().unix_ns(status.timestamp_ns);
        let (previous_state, previous_fault) = self
            .last_status
            .take()
            .map_or((None, String::new()), |(s, f)| (Some(s), f));
        if previous_state != Some(state) {
            let from = previous_state.map_or("start", DaemonState::name);
            self.channels.log_fault(
                Level::Info,
                format!(
                    "state {from} → {} (sequence {}, stance {}/{})",
                    state.name(),
                    status.sequence_id,
                    status.stance_index,
                    status.stance_count
                ),
                t,
            );
        }
        if !fault.is_empty() && fault != previous_fault {
            self.channels
                .log_fault(Level::Error, format!("fault: {fault}"), t);
        }
        self.last_status = Some((state, fault));
    }
}
