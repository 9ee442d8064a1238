//! The service thread: sequence submissions, control requests, status publication, systemd.
//!
//! Everything that may allocate or block happens here: parsing and validating submitted JSON,
//! preparing sequences, freeing the ones the control thread hands back.

use std::sync::Arc;
use std::time::{Duration, Instant};

use kinematics::robot::Robot;
use shm_types::{
    ControlCommand, ControlReply, DaemonServicePorts, DaemonState, DaemonStatus, FixedText,
    LinkState, ShmError, SubmitReply,
};

use super::shared::{Shared, StartOutcome, Submission};
use super::snapshot::SnapshotReader;
use crate::controller::{Controller, ControllerConfig};

/// How long the service thread waits for the control thread to take a request.
const HANDOFF_TIMEOUT: Duration = Duration::from_secs(2);
/// Poll interval of the service loop.
const POLL: Duration = Duration::from_millis(1);

/// The service thread's state.
pub struct ServiceLoop {
    ports: DaemonServicePorts,
    requests: Requests,
    status_interval: Duration,
    last_notified_state: Option<DaemonState>,
    last_link: LinkState,
    /// systemd's watchdog interval (`WATCHDOG_USEC`), if it watches us.
    watchdog: Option<Duration>,
}

/// What answering requests needs (separate from the ports that deliver them).
struct Requests {
    shared: Arc<Shared>,
    status_in: SnapshotReader<DaemonStatus>,
    robot: Arc<Robot>,
    config: ControllerConfig,
    next_sequence_id: u64,
}

impl ServiceLoop {
    /// Sets up the service side.
    pub fn new(
        ports: DaemonServicePorts,
        shared: Arc<Shared>,
        status_in: SnapshotReader<DaemonStatus>,
        robot: Arc<Robot>,
        config: ControllerConfig,
        status_rate_hz: f64,
    ) -> Self {
        Self {
            ports,
            requests: Requests {
                shared,
                status_in,
                robot,
                config,
                next_sequence_id: 1,
            },
            status_interval: Duration::from_secs_f64(1.0 / status_rate_hz),
            last_notified_state: None,
            last_link: LinkState::Waiting,
            watchdog: sd_notify::watchdog_enabled(),
        }
    }

    /// Serves until `keep_running()` turns false.
    pub fn run(&mut self, keep_running: impl Fn() -> bool) -> Result<(), ShmError> {
        let mut next_status = Instant::now();
        while keep_running() {
            let requests = &mut self.requests;
            drop(requests.shared.outbox.take());
            let served_submission = self
                .ports
                .serve_submission(|json| requests.handle_submission(json))?;
            let served_control = self
                .ports
                .serve_control(|command| requests.handle_control(command))?;
            if Instant::now() >= next_status {
                self.publish_status()?;
                next_status += self.status_interval;
                if next_status < Instant::now() {
                    next_status = Instant::now() + self.status_interval;
                }
            }
            if !served_submission && !served_control {
                std::thread::sleep(POLL);
            }
        }
        Ok(())
    }

    /// Publishes the newest status and keeps systemd informed.
    pub fn publish_status(&mut self) -> Result<(), ShmError> {
        let status = self.requests.status_in.read();
        self.ports.publish_status(&status)?;
        self.feed_watchdog();
        let link_changed = status.link != self.last_link;
        if link_changed {
            match status.link {
                LinkState::Stale => tracing::warn!(
                    state = status.state.name(),
                    "adapter link stale: no fresh sensor samples, holding"
                ),
                LinkState::Fresh => tracing::info!("adapter link fresh"),
                LinkState::Waiting => {}
            }
            self.last_link = status.link;
        }
        if link_changed || self.last_notified_state != Some(status.state) {
            self.last_notified_state = Some(status.state);
            let text = format!(
                "{} (sequence {}, stance {}/{}, adapter {})",
                status.state.name(),
                status.sequence_id,
                status.stance_index,
                status.stance_count,
                status.link.name()
            );
            let _ = sd_notify::notify(&[sd_notify::NotifyState::Status(&text)]);
        }
        Ok(())
    }

    /// Sends `WATCHDOG=1` if systemd watches us and the control thread went round within half
    /// the watchdog interval: a stuck control thread stops the feeding and systemd restarts us.
    fn feed_watchdog(&self) {
        let Some(interval) = self.watchdog else {
            return;
        };
        let since_beat =
            shm_types::monotonic_ns().saturating_sub(self.requests.shared.last_beat_ns());
        if u128::from(since_beat) <= interval.as_nanos() / 2 {
            let _ = sd_notify::notify(&[sd_notify::NotifyState::Watchdog]);
        }
    }
}

impl Requests {
    /// Validates, prepares and hands over a submitted sequence; the reply says why not.
    fn handle_submission(&mut self, json: &[u8]) -> SubmitReply {
        match self.try_submit(json) {
            Ok(id) => {
                tracing::info!(id, "sequence accepted");
                SubmitReply::accepted(id)
            }
            Err(reason) => {
                tracing::warn!(%reason, "sequence refused");
                SubmitReply::refused(&reason)
            }
        }
    }

    fn try_submit(&mut self, json: &[u8]) -> Result<u64, String> {
        let text = std::str::from_utf8(json)
            .map_err(|e| format!("the submission is not UTF-8 JSON: {e}"))?;
        let sequence = stance::PostProcessedSequence::from_json_str(text, &self.robot)
            .map_err(|e| format!("invalid sequence: {e}"))?;
        let prepared =
            Controller::prepare(&self.robot, &self.config, &sequence).map_err(|e| e.to_string())?;
        let status = self.status_in.read();
        if status.state == DaemonState::Executing {
            return Err(format!(
                "busy: sequence {} is executing (stance {}/{}); hold or abort it first",
                status.sequence_id, status.stance_index, status.stance_count
            ));
        }
        drop(self.shared.outbox.take());
        let id = self.next_sequence_id;
        self.next_sequence_id += 1;
        let submission = Box::new(Submission {
            id,
            sequence: Box::new(prepared),
        });
        if self.shared.inbox.put(submission).is_err() {
            return Err("another submission is being started; retry".to_owned());
        }
        let start = Instant::now();
        loop {
            if let Some(outcome) = self.shared.start_outcome(id) {
                return match outcome {
                    StartOutcome::Started => Ok(id),
                    StartOutcome::Busy => {
                        Err("busy: a sequence is executing; hold or abort it first".to_owned())
                    }
                    StartOutcome::Faulted => Err(
                        "the controller is in fault; send hold or abort to acknowledge it"
                            .to_owned(),
                    ),
                    StartOutcome::AdapterStale => Err(
                        "no fresh sensor samples from the adapter: the sequence cannot start"
                            .to_owned(),
                    ),
                };
            }
            if start.elapsed() > HANDOFF_TIMEOUT && self.shared.inbox.take().is_some() {
                return Err("the control loop did not take the sequence in time".to_owned());
            }
            std::thread::sleep(POLL);
        }
    }

    /// Carries out hold / abort through the control thread, or answers a query.
    fn handle_control(&mut self, command: ControlCommand) -> ControlReply {
        let mut reply = ControlReply {
            accepted: true,
            message: FixedText::new(command.name()),
            status: self.status_in.read(),
        };
        if command == ControlCommand::Query {
            return reply;
        }
        let target = self.shared.request_control(command);
        let start = Instant::now();
        while self.shared.controls_done() < target {
            if start.elapsed() > HANDOFF_TIMEOUT {
                reply.accepted = false;
                reply.message = FixedText::new("the control loop did not answer in time");
                return reply;
            }
            std::thread::sleep(POLL);
        }
        tracing::info!(command = command.name(), "control command carried out");
        reply.status = self.status_in.read();
        reply
    }
}
