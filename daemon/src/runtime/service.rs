//! The service thread: sequence submissions, control requests, status publication, systemd.
//!
//! Everything that may allocate or block happens here: parsing and validating submitted JSON,
//! preparing sequences, freeing the ones the control thread hands back.
//!
//! A submission is bounded before it is parsed: its size against `[runtime]
//! max_submission_bytes`, then whether a walk is executing ("busy" needs no parsing), then its
//! stance count against `max_stances` (counted without building the stances). Memory freed
//! after a walk or a refused submission is handed back to the operating system.
//!
//! The service thread also lists the publishers on `sensors` for the control thread
//! ([`AdapterWatch`]), and puts the standing conditions hold and abort do not clear in front of
//! the status's fault text ([`Notices`]): another process publishing on `sensors`, telemetry or
//! status publication off.

use std::sync::Arc;
use std::time::{Duration, Instant};

use kinematics::robot::Robot;
use shm_types::{
    Code, ControlCommand, ControlReply, DaemonServicePorts, DaemonState, DaemonStatus, DecodeError,
    FixedText, Flag, LinkState, ShmError, SubmitReply,
};

use super::realtime::release_free_memory;
use super::shared::{ControlOutcome, Shared, StartOutcome, Submission};
use super::snapshot::SnapshotReader;
use super::trust::AdapterWatch;
use crate::controller::{Controller, ControllerConfig, GaitConfig};

/// What a submitted sequence is checked and prepared against: the robot and its config.
#[derive(Debug, Clone)]
pub struct Acceptance {
    /// The robot the daemon controls.
    pub robot: Arc<Robot>,
    /// `[controller]`.
    pub config: ControllerConfig,
    /// `[gait]`: the gait of a sequence that does not name one, and whether the dynamic gait
    /// is available.
    pub gaits: GaitConfig,
    /// `[runtime]` size bounds.
    pub limits: SubmissionLimits,
}

/// How large a submission walkd reads (`[runtime]` keys).
#[derive(Debug, Clone, Copy)]
pub struct SubmissionLimits {
    /// `max_submission_bytes`.
    pub max_bytes: usize,
    /// `max_stances`.
    pub max_stances: usize,
}

/// How long the service thread waits for the control thread to take a request.
const HANDOFF_TIMEOUT: Duration = Duration::from_secs(2);
/// Poll interval of the service loop.
const POLL: Duration = Duration::from_millis(1);
/// How often the publishers on `sensors` are listed for the control thread.
const REVIEW_EVERY: Duration = Duration::from_millis(5);

/// The service thread's state.
pub struct ServiceLoop {
    ports: DaemonServicePorts,
    requests: Requests,
    status_interval: Duration,
    last_notified_state: Option<Code<DaemonState>>,
    last_link: Code<LinkState>,
    /// systemd's watchdog interval (`WATCHDOG_USEC`), if it watches us.
    watchdog: Option<Duration>,
}

/// What answering requests needs (separate from the ports that deliver them).
struct Requests {
    shared: Arc<Shared>,
    status_in: SnapshotReader<DaemonStatus>,
    acceptance: Acceptance,
    notices: Notices,
    next_sequence_id: u64,
    next_ticket: u64,
}

/// The standing conditions the status names in front of its fault text: hold and abort do not
/// clear them, only their end does.
struct Notices {
    /// Who publishes on `sensors` (an intruder is named while it is there).
    adapters: AdapterWatch,
    /// walkd found no free `telemetry` publisher slot (or could not open the service).
    telemetry_off: bool,
    /// walkd found no free `status` publisher slot: the status is only had by asking.
    status_off: bool,
}

impl Notices {
    /// Puts the conditions in front of `status`'s fault text (cut at its capacity).
    fn apply(&self, status: &mut DaemonStatus) {
        let mut parts: Vec<String> = self.adapters.notice().into_iter().collect();
        if self.telemetry_off {
            parts.push("telemetry off (see walkd's log)".to_owned());
        }
        if self.status_off {
            parts.push("status publication off (see walkd's log)".to_owned());
        }
        if parts.is_empty() {
            return;
        }
        if !status.fault.is_empty() {
            parts.push(status.fault.as_str().to_owned());
        }
        status.fault = FixedText::new(&parts.join("; "));
    }
}

impl ServiceLoop {
    /// Sets up the service side; `telemetry_off`: the control thread publishes no telemetry.
    pub fn new(
        ports: DaemonServicePorts,
        shared: Arc<Shared>,
        status_in: SnapshotReader<DaemonStatus>,
        acceptance: Acceptance,
        status_rate_hz: f64,
        telemetry_off: bool,
    ) -> Self {
        let status_off = ports.status_off().is_some();
        Self {
            ports,
            requests: Requests {
                shared,
                status_in,
                acceptance,
                notices: Notices {
                    adapters: AdapterWatch::new(),
                    telemetry_off,
                    status_off,
                },
                next_sequence_id: 1,
                next_ticket: 1,
            },
            status_interval: Duration::from_secs_f64(1.0 / status_rate_hz),
            last_notified_state: None,
            last_link: Code::new(LinkState::Waiting),
            watchdog: sd_notify::watchdog_enabled(),
        }
    }

    /// Serves until `keep_running()` turns false.
    pub fn run(&mut self, keep_running: impl Fn() -> bool) -> Result<(), ShmError> {
        let mut next_status = Instant::now();
        let mut next_review = Instant::now();
        while keep_running() {
            let requests = &mut self.requests;
            if Instant::now() >= next_review {
                next_review = Instant::now() + REVIEW_EVERY;
                let link_stale = requests.status_in.read().link == LinkState::Stale;
                requests
                    .notices
                    .adapters
                    .review(&self.ports, &requests.shared.adapter, link_stale);
            }
            if let Some(finished) = requests.shared.outbox.take() {
                drop(finished);
                release_free_memory();
            }
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
        let mut status = self.requests.status();
        if status.timestamp_ns == 0 {
            // Before the control loop's first status: stamped now, not at the clock's origin
            // (an observer files messages by their time stamps).
            status.timestamp_ns = shm_types::monotonic_ns();
        }
        self.ports.publish_status(&status)?;
        self.feed_watchdog();
        let link_changed = status.link != self.last_link;
        if link_changed {
            if status.link == LinkState::Stale {
                tracing::warn!(
                    state = status.state.name(),
                    "adapter link stale: no fresh sensor samples, holding"
                );
            } else if status.link == LinkState::Fresh {
                tracing::info!("adapter link fresh");
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
    /// The newest status the control thread wrote, with the standing conditions in front of its
    /// fault text.
    fn status(&mut self) -> DaemonStatus {
        let mut status = self.status_in.read();
        self.notices.apply(&mut status);
        status
    }

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
        let limits = self.acceptance.limits;
        if json.len() > limits.max_bytes {
            return Err(format!(
                "the submission has {} bytes, more than [runtime] max_submission_bytes = {}",
                json.len(),
                limits.max_bytes
            ));
        }
        let status = self.status_in.read();
        if status.state == DaemonState::Executing {
            return Err(format!(
                "busy: sequence {} is executing (stance {}/{}); hold or abort it first",
                status.sequence_id, status.stance_index, status.stance_count
            ));
        }
        if status.state == DaemonState::ControlledStop {
            return Err(format!(
                "sequence {} is coming to a controlled stop: the robot comes to rest on both feet \
                 first",
                status.sequence_id
            ));
        }
        let text = std::str::from_utf8(json)
            .map_err(|e| format!("the submission is not UTF-8 JSON: {e}"))?;
        let stances =
            stance::format::count_stances(text).map_err(|e| format!("invalid sequence: {e}"))?;
        if stances > limits.max_stances {
            return Err(format!(
                "the sequence has {stances} stances, more than [runtime] max_stances = {}",
                limits.max_stances
            ));
        }
        let Acceptance {
            robot,
            config,
            gaits,
            ..
        } = &self.acceptance;
        let prepared = stance::PostProcessedSequence::from_json_str(text, robot)
            .map_err(|e| format!("invalid sequence: {e}"))
            .and_then(|sequence| {
                let gait = sequence.gait().unwrap_or(gaits.default);
                Controller::prepare_gait(robot, config, gaits, &sequence, gait)
                    .map_err(|e| format!("{} gait: {e}", gait.name()))
            });
        // Parsing a large file leaves freed memory behind: hand it back now.
        release_free_memory();
        let prepared = prepared?;
        drop(self.shared.outbox.take());
        let (id, ticket) = (self.next_sequence_id, self.next_ticket);
        self.next_ticket += 1;
        let submission = Box::new(Submission {
            ticket,
            id,
            sequence: Box::new(prepared),
        });
        if self.shared.inbox.put(submission).is_err() {
            return Err("another submission is being started; retry".to_owned());
        }
        let start = Instant::now();
        loop {
            if let Some(outcome) = self.shared.start_outcome(ticket) {
                return match outcome {
                    StartOutcome::Started => {
                        self.next_sequence_id += 1;
                        Ok(id)
                    }
                    StartOutcome::Refused(refusal) => Err(refusal.describe().to_owned()),
                    StartOutcome::AdapterStale => Err(
                        "no fresh sensor samples from the adapter: the sequence cannot start"
                            .to_owned(),
                    ),
                    StartOutcome::SecondAdapter => Err(match self.notices.adapters.notice() {
                        Some(notice) => format!("{notice}: stop it first"),
                        None => "another process published on sensors just now: retry once it \
                                 is gone"
                            .to_owned(),
                    }),
                };
            }
            if start.elapsed() > HANDOFF_TIMEOUT && self.shared.inbox.take().is_some() {
                return Err("the control loop did not take the sequence in time".to_owned());
            }
            std::thread::sleep(POLL);
        }
    }

    /// Carries out hold / abort through the control thread, or answers a query; refuses a
    /// command code the contract does not define, naming it.
    fn handle_control(&mut self, command: Result<ControlCommand, DecodeError>) -> ControlReply {
        let mut reply = ControlReply {
            accepted: Flag::YES,
            message: FixedText::EMPTY,
            status: self.status(),
        };
        let command = match command {
            Ok(command) => command,
            Err(error) => {
                tracing::warn!(%error, "control request refused");
                reply.accepted = Flag::NO;
                reply.message = FixedText::new(&format!("refused: unknown command: {error}"));
                return reply;
            }
        };
        reply.message = FixedText::new(command.name());
        if command == ControlCommand::Query {
            return reply;
        }
        let target = self.shared.request_control(command);
        let start = Instant::now();
        let outcome = loop {
            if let Some(outcome) = self.shared.control_outcome(target) {
                break outcome;
            }
            if start.elapsed() > HANDOFF_TIMEOUT {
                reply.accepted = Flag::NO;
                reply.message = FixedText::new("the control loop did not answer in time");
                return reply;
            }
            std::thread::sleep(POLL);
        };
        match outcome {
            ControlOutcome::Done => {
                tracing::info!(command = command.name(), "control command carried out")
            }
            ControlOutcome::NotAcknowledged(refusal) => {
                tracing::warn!(command = command.name(), "fault not acknowledged");
                reply.accepted = Flag::NO;
                reply.message = FixedText::new(&format!(
                    "{} refused: {}",
                    command.name(),
                    refusal.describe()
                ));
            }
        }
        reply.status = self.status();
        reply
    }
}
