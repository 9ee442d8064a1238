//! The observer's reading side: a thread that polls a running daemon's streams
//! ([`shm_types::ObserverPorts`]) every [`POLL`] and hands each round's messages on as one
//! [`Batch`], so decoding and writing never hold up the draining. Each stream's messages come
//! from the one publisher the ports pinned (walkd's telemetry, commands and status); what other
//! publishers send is refused and only reported.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{Receiver, Sender};
use std::thread::JoinHandle;
use std::time::Duration;

use anyhow::Context;
use shm_types::{
    DaemonStatus, JointCommand, Observed, ObserverPorts, Refusals, SensorSample, ServiceNames,
    Telemetry,
};

/// Nice value of the observer's threads: an observer yields the CPU to walkd and its adapter.
pub const OBSERVER_NICE: i32 = 10;

/// Lowers the calling thread's scheduling priority to [`OBSERVER_NICE`] (best effort: on Linux
/// the nice value is per thread).
pub fn yield_to_the_controller() {
    // SAFETY: setpriority has no memory-safety preconditions; PRIO_PROCESS with who = 0 is the
    // calling thread on Linux.
    unsafe {
        libc::setpriority(libc::PRIO_PROCESS, 0, OBSERVER_NICE);
    }
}

/// How often the streams are drained: well inside their buffers (128 stream messages and 256
/// telemetries, over 100 ms at 1 kHz).
pub const POLL: Duration = Duration::from_millis(1);

/// The messages of one drain round, each kind oldest first. A telemetry's sample and command are
/// in the same batch (or were lost).
#[derive(Debug, Default)]
pub struct Batch {
    /// Per-tick telemetry.
    pub telemetry: Vec<Telemetry>,
    /// Sensor samples.
    pub samples: Vec<SensorSample>,
    /// Joint commands.
    pub commands: Vec<JointCommand>,
    /// Statuses.
    pub statuses: Vec<DaemonStatus>,
    /// Streams on which another publisher than the pinned one sent messages (refused, never
    /// recorded): the service's full name and what was refused there so far.
    pub refused: Vec<(String, Refusals)>,
}

impl Batch {
    fn is_empty(&self) -> bool {
        self.telemetry.is_empty()
            && self.samples.is_empty()
            && self.commands.is_empty()
            && self.statuses.is_empty()
            && self.refused.is_empty()
    }
}

/// The polling thread; see the module docs.
pub struct Source {
    stop: Arc<AtomicBool>,
    handle: JoinHandle<anyhow::Result<()>>,
}

impl Source {
    /// Subscribes to the daemon serving `prefix` and starts polling; returns once subscribed, with
    /// the receiving end of the batches. Fails at once if no daemon serves `prefix`.
    pub fn start(prefix: &str) -> anyhow::Result<(Self, Receiver<Batch>)> {
        let names = ServiceNames::new(prefix)?;
        let stop = Arc::new(AtomicBool::new(false));
        let stopped = Arc::clone(&stop);
        let (batches, received) = std::sync::mpsc::channel();
        let (ready, subscribed) = std::sync::mpsc::channel();
        let handle = std::thread::Builder::new()
            .name("observer-poll".to_owned())
            .spawn(move || {
                yield_to_the_controller();
                // iceoryx2 ports stay on the thread that created them.
                let ports = match ObserverPorts::open(&names, "walkctl-observer") {
                    Ok(ports) => {
                        let _ = ready.send(Ok(()));
                        ports
                    }
                    Err(error) => {
                        let message = error.to_string();
                        let _ = ready.send(Err(error));
                        anyhow::bail!("{message}");
                    }
                };
                poll(&ports, &stopped, &batches)
            })
            .context("starting the observer's polling thread")?;
        match subscribed.recv() {
            Ok(Ok(())) => Ok((Self { stop, handle }, received)),
            Ok(Err(error)) => Err(anyhow::Error::new(error).context(format!(
                "observing the daemon on `{prefix}` (is walkd running with this service prefix?)"
            ))),
            Err(_) => anyhow::bail!("the observer's polling thread ended before subscribing"),
        }
    }

    /// Stops polling after one last round; the receiver then sees the end of the batches.
    pub fn stop(self) -> anyhow::Result<()> {
        self.stop.store(true, Ordering::Relaxed);
        self.handle
            .join()
            .map_err(|_| anyhow::anyhow!("the observer's polling thread panicked"))?
    }
}

/// Drains the ports every [`POLL`] until `stop` (then once more) and sends non-empty rounds.
fn poll(ports: &ObserverPorts, stop: &AtomicBool, batches: &Sender<Batch>) -> anyhow::Result<()> {
    loop {
        let last_round = stop.load(Ordering::Relaxed);
        let mut batch = Batch::default();
        ports.drain(|message| match message {
            Observed::Telemetry(t) => batch.telemetry.push(*t),
            Observed::Sample(s) => batch.samples.push(*s),
            Observed::Command(c) => batch.commands.push(*c),
            Observed::Status(s) => batch.statuses.push(*s),
            Observed::Refused { service, refusals } => {
                batch.refused.push((service.to_owned(), refusals))
            }
        })?;
        if !batch.is_empty() && batches.send(batch).is_err() {
            // The consumer is gone: nobody wants the messages any more.
            return Ok(());
        }
        if last_round {
            return Ok(());
        }
        std::thread::sleep(POLL);
    }
}
