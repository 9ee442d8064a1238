//! An observer's ports: an extra subscriber on a running daemon's `telemetry`, `sensors`,
//! `commands` and `status`, for recorders and live viewers.
//!
//! Observing must not disturb the control loop, so the observer only reads: it creates
//! subscribers but no event listeners (a listener would make walkd and the adapter signal one more
//! process with every message), and it polls. Its subscribers buffer
//! [`services::STREAM_OBSERVER_BUFFER`] stream messages and [`services::TELEMETRY_BUFFER`]
//! telemetries, so an observer that drains every few milliseconds loses nothing at 1 kHz; one
//! that falls further behind loses the oldest, visible as gaps in the messages' `seq`.
//!
//! Each stream is taken from one publisher only: the first one heard (walkd's telemetry,
//! commands and status, the adapter's samples). Messages of any other publisher are refused and
//! reported as [`Observed::Refused`], so an observer never records forged data.

use core::cell::Cell;

use super::trust::{Refusals, TrustedReceiver};
use crate::services::{self, Access, IpcNode, Topic};
use crate::{DaemonStatus, JointCommand, SensorSample, ServiceNames, ShmError, Telemetry};

/// One message an observer received.
#[derive(Debug, Clone, Copy)]
pub enum Observed<'a> {
    /// A tick's telemetry.
    Telemetry(&'a Telemetry),
    /// An adapter's sensor sample.
    Sample(&'a SensorSample),
    /// A joint command of walkd.
    Command(&'a JointCommand),
    /// A status walkd published.
    Status(&'a DaemonStatus),
    /// Messages on `service` came from another publisher than the one pinned there, and were
    /// refused (`refusals` counts all so far).
    Refused {
        /// The service's full name.
        service: &'a str,
        /// What was refused on it.
        refusals: Refusals,
    },
}

/// One stream of an observer: its trusted subscriber, and the refusals reported so far.
struct Stream<T: Topic> {
    receiver: TrustedReceiver<T>,
    reported: Cell<u64>,
}

impl<T: Topic> Stream<T> {
    fn new(receiver: TrustedReceiver<T>) -> Self {
        Self {
            receiver,
            reported: Cell::new(0),
        }
    }

    /// Passes the pinned publisher's messages as `wrap` makes them, then what was refused since
    /// the last call; returns how many messages were passed.
    fn drain(
        &self,
        each: &mut impl FnMut(Observed<'_>),
        wrap: for<'m> fn(&'m T) -> Observed<'m>,
    ) -> Result<usize, ShmError> {
        let mut count = 0;
        self.receiver.drain(|message| {
            count += 1;
            each(wrap(message));
        })?;
        let refusals = self.receiver.refusals();
        if refusals.count > self.reported.get() {
            self.reported.set(refusals.count);
            each(Observed::Refused {
                service: self.receiver.name(),
                refusals,
            });
        }
        Ok(count)
    }
}

/// A running daemon's streams, seen by an observer. Only opens what a daemon created: if no
/// daemon serves `names`, [`open`](Self::open) fails with [`ShmError::NotRunning`].
pub struct ObserverPorts {
    telemetry: Stream<Telemetry>,
    sensors: Stream<SensorSample>,
    commands: Stream<JointCommand>,
    status: Stream<DaemonStatus>,
    _node: IpcNode,
}

impl ObserverPorts {
    /// Subscribes to `telemetry`, `sensors`, `commands` and `status` under `names`. Messages
    /// published from now on are received (and the newest stream message before, as history).
    pub fn open(names: &ServiceNames, node_name: &str) -> Result<Self, ShmError> {
        let (node, _) = services::create_node(node_name)?;
        // The status service is opened first and only opened: without a daemon this fails.
        let status = services::publish_subscribe(&node, names, Access::OpenOnly)?;
        let status = TrustedReceiver::subscribe(names, status, DaemonStatus::BUFFER, true)?;
        let telemetry = TrustedReceiver::open(&node, names, Telemetry::BUFFER, true)?;
        let sensors = TrustedReceiver::open(&node, names, SensorSample::BUFFER, true)?;
        let commands = TrustedReceiver::open(&node, names, JointCommand::BUFFER, true)?;
        Ok(Self {
            telemetry: Stream::new(telemetry),
            sensors: Stream::new(sensors),
            commands: Stream::new(commands),
            status: Stream::new(status),
            _node: node,
        })
    }

    /// Passes every message received since the last call to `each`: telemetry first, then
    /// sensor samples, commands and statuses, each oldest first, each stream followed by what it
    /// refused since the last call. A tick's telemetry is published after its sample and its
    /// command, so the sample and the command a drained telemetry names are delivered in the same
    /// call (unless they were lost). Returns how many messages were passed.
    pub fn drain(&self, mut each: impl FnMut(Observed<'_>)) -> Result<usize, ShmError> {
        Ok(self
            .telemetry
            .drain(&mut each, |t| Observed::Telemetry(t))?
            + self.sensors.drain(&mut each, |s| Observed::Sample(s))?
            + self.commands.drain(&mut each, |c| Observed::Command(c))?
            + self.status.drain(&mut each, |s| Observed::Status(s))?)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_observer_needs_a_running_daemon() {
        let prefix = format!("walk-test/shm-types/observer/{}", std::process::id());
        let names = ServiceNames::new(&prefix).unwrap();
        match ObserverPorts::open(&names, "observer") {
            Err(ShmError::NotRunning { service }) => assert!(service.ends_with("/status")),
            Err(other) => panic!("expected not running, got {other}"),
            Ok(_) => panic!("an observer opened services no daemon created"),
        }
    }
}
