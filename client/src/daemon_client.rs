//! The library API for programs that drive a running `walkd`: connect, submit, control, watch.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use anyhow::{Context, bail};
use kinematics::ConfigFile;
use shm_types::{
    ClientPorts, ControlCommand, DaemonState, DaemonStatus, LatencySummary, LinkState,
    RuntimeConfig, ServiceNames, ShmError,
};

use crate::process::Process;

/// How long a request to the daemon may take before it counts as unanswered.
pub const REQUEST_TIMEOUT: Duration = Duration::from_secs(10);

/// Which daemon to talk to: the service prefix from a robot config, or given directly.
#[derive(Debug, Clone, clap::Args)]
pub struct DaemonTarget {
    /// Robot config whose `[runtime] service_prefix` names the daemon.
    #[arg(long)]
    pub config: Option<PathBuf>,
    /// Service prefix of the daemon (overrides the config's).
    #[arg(long)]
    pub service_prefix: Option<String>,
}

impl DaemonTarget {
    /// The service prefix to use.
    pub fn prefix(&self) -> anyhow::Result<String> {
        if let Some(prefix) = &self.service_prefix {
            return Ok(prefix.clone());
        }
        let Some(config) = &self.config else {
            bail!("say which daemon: pass --config CONFIG or --service-prefix PREFIX");
        };
        let file = ConfigFile::load(config)?;
        Ok(RuntimeConfig::from_section(file.section("runtime"), &file.origin())?.service_prefix)
    }
}

/// A connection to a running `walkd`.
pub struct DaemonClient {
    ports: ClientPorts,
}

/// Why a sequence was not accepted.
#[derive(Debug, thiserror::Error)]
pub enum SubmitError {
    /// The daemon refused it; the reason names what is wrong.
    #[error("walkd refused the sequence: {0}")]
    Refused(String),
    /// The request did not get through.
    #[error(transparent)]
    Ipc(#[from] shm_types::ShmError),
}

impl DaemonClient {
    /// Connects to the daemon serving `prefix`; fails at once with a clear message if none
    /// does (no service, or services left by a daemon that is gone).
    pub fn connect(prefix: &str) -> anyhow::Result<Self> {
        let names = ServiceNames::new(prefix)?;
        let ports = ClientPorts::connect(&names, "walkctl")?;
        if !ports.daemon_present() {
            bail!(
                "no walkd serves `{prefix}`: its services exist, but no daemon process is \
                 attached to them (is walkd running with this service prefix?)"
            );
        }
        Ok(Self { ports })
    }

    /// Whether a live daemon serves the services.
    pub fn is_running(&self) -> bool {
        self.ports.daemon_present()
    }

    /// The daemon's current status: asked for directly, or, when every `control` slot is taken
    /// by other processes, the next one the daemon publishes.
    pub fn status(&self) -> anyhow::Result<DaemonStatus> {
        match self.ports.control(ControlCommand::Query, REQUEST_TIMEOUT) {
            Ok(reply) => Ok(reply.status),
            Err(full @ ShmError::ServiceFull { .. }) => self
                .ports
                .next_status(Duration::from_secs(2))
                .with_context(|| format!("{full}; nor did a published status arrive")),
            Err(other) => Err(other.into()),
        }
    }

    /// The next published status (waits up to `timeout`).
    pub fn next_status(&self, timeout: Duration) -> anyhow::Result<DaemonStatus> {
        Ok(self.ports.next_status(timeout)?)
    }

    /// Submits a post-processed sequence (JSON); returns its id once it started executing.
    pub fn submit_json(&self, json: &str) -> Result<u64, SubmitError> {
        let reply = self.ports.submit(json.as_bytes(), REQUEST_TIMEOUT)?;
        if reply.accepted.is_set() {
            Ok(reply.sequence_id)
        } else {
            Err(SubmitError::Refused(reply.reason.as_str().to_owned()))
        }
    }

    /// Sends hold or abort; returns the status after it was carried out.
    pub fn control(&self, command: ControlCommand) -> anyhow::Result<DaemonStatus> {
        let reply = self.ports.control(command, REQUEST_TIMEOUT)?;
        if !reply.accepted.is_set() {
            bail!(
                "walkd did not carry out {}: {}",
                command.name(),
                reply.message
            );
        }
        Ok(reply.status)
    }

    /// Waits until sequence `id` stops executing (done, fault, hold or abort), calling
    /// `on_status` with every status on the way; returns the final status.
    pub fn wait_for_sequence(
        &self,
        id: u64,
        timeout: Duration,
        mut on_status: impl FnMut(&DaemonStatus),
    ) -> anyhow::Result<DaemonStatus> {
        let start = Instant::now();
        loop {
            let status = self
                .next_status(Duration::from_secs(2))
                .context("walkd stopped publishing its status")?;
            on_status(&status);
            let finished = status.sequence_id == id && !status.walking();
            if finished || status.sequence_id > id || status.state == DaemonState::Stopping {
                return Ok(status);
            }
            if start.elapsed() > timeout {
                bail!(
                    "sequence {id} still executing after {} s",
                    timeout.as_secs()
                );
            }
        }
    }
}

/// Waits until the daemon on `prefix` serves with a fresh adapter link, failing with a child's
/// log as soon as one of `watched` (the processes started for it, if any) exits.
pub fn connect_when_fresh(
    prefix: &str,
    watched: &[Process],
    timeout: Duration,
) -> anyhow::Result<DaemonClient> {
    let start = Instant::now();
    loop {
        for process in watched {
            process.check_running()?;
        }
        if let Ok(client) = DaemonClient::connect(prefix)
            && let Ok(status) = client.status()
            && status.link == LinkState::Fresh
        {
            return Ok(client);
        }
        if start.elapsed() > timeout {
            bail!(
                "walkd on `{prefix}` did not get fresh samples within {} s",
                timeout.as_secs()
            );
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// Midpoint of the two feet (x, y): the walking progress measure of `walkctl demo`.
pub fn feet_midpoint(status: &DaemonStatus) -> [f64; 2] {
    [
        0.5 * (status.left_foot[0] + status.right_foot[0]),
        0.5 * (status.left_foot[1] + status.right_foot[1]),
    ]
}

fn latency_json(summary: &LatencySummary) -> serde_json::Value {
    serde_json::json!({ "p50": summary.p50, "p99": summary.p99, "max": summary.max })
}

/// The status as a JSON object (for `walkctl status --json` and programs).
pub fn status_json(status: &DaemonStatus) -> serde_json::Value {
    serde_json::json!({
        "protocol_version": status.protocol_version,
        "pid": status.pid,
        "state": status.state.name(),
        "clock": status.clock.name(),
        "rate_hz": status.rate_hz,
        "sequence_id": status.sequence_id,
        "stance_index": status.stance_index,
        "stance_count": status.stance_count,
        "phase": status.phase.as_str(),
        "com": status.com,
        "left_foot": status.left_foot,
        "right_foot": status.right_foot,
        "fault": status.fault.as_str(),
        "stop_s": status.stop_s,
        "adapter_link": status.link.name(),
        "adapter_holding": status.adapter_holding.is_set(),
        "ticks": status.ticks,
        "deadline_misses": status.deadline_misses,
        "stale_periods": status.stale_periods,
        "watchdog_trips": status.watchdog_trips,
        "rejected_samples": status.rejected_samples,
        "last_rejection": status.last_rejection.as_str(),
        "tick_us": latency_json(&status.tick_us),
        "latency_us": latency_json(&status.latency_us),
        "jitter_us": latency_json(&status.jitter_us),
    })
}

/// The status as a few human-readable lines.
pub fn status_text(status: &DaemonStatus) -> String {
    let mut text = format!(
        "state {} (sequence {}, stance {}/{}, phase {})\n\
         adapter link {}{}, clock {} at {} Hz\n\
         CoM [{:.3}, {:.3}, {:.3}] m\n\
         ticks {}, deadline misses {}, stale periods {}, watchdog trips {}\n\
         tick {:.1}/{:.1}/{:.1} us, sensor->command {:.1}/{:.1}/{:.1} us (p50/p99/max)",
        status.state.name(),
        status.sequence_id,
        status.stance_index,
        status.stance_count,
        status.phase,
        status.link.name(),
        if status.adapter_holding.is_set() {
            " (adapter holding)"
        } else {
            ""
        },
        status.clock.name(),
        status.rate_hz,
        status.com[0],
        status.com[1],
        status.com[2],
        status.ticks,
        status.deadline_misses,
        status.stale_periods,
        status.watchdog_trips,
        status.tick_us.p50,
        status.tick_us.p99,
        status.tick_us.max,
        status.latency_us.p50,
        status.latency_us.p99,
        status.latency_us.max,
    );
    if !status.fault.is_empty() {
        text.push_str(&format!("\nlast fault: {}", status.fault));
    }
    if status.stop_s > 0.0 {
        text.push_str(&format!(
            "\nlast controlled stop: {:.2} s to rest on both feet",
            status.stop_s
        ));
    }
    text
}

/// Reads a file to a string, naming it in the error.
pub(crate) fn read_text(path: &Path) -> anyhow::Result<String> {
    std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))
}
