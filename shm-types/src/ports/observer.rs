//! An observer's ports: an extra subscriber on a running daemon's `telemetry`, `sensors`,
//! `commands` and `status`, for recorders and live viewers.
//!
//! Observing must not disturb the control loop, so the observer only reads: it creates
//! subscribers but no event listeners (a listener would make walkd and the adapter signal one more
//! process with every message), and it polls. Its subscribers buffer
//! [`services::STREAM_OBSERVER_BUFFER`] stream messages and [`services::TELEMETRY_BUFFER`]
//! telemetries, so an observer that drains every few milliseconds loses nothing at 1 kHz; one
//! that falls further behind loses the oldest, visible as gaps in the messages' `seq`.

use super::topic::TopicReceiver;
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
}

/// A running daemon's streams, seen by an observer. Only opens what a daemon created: if no
/// daemon serves `names`, [`open`](Self::open) fails with [`ShmError::NotRunning`].
pub struct ObserverPorts {
    telemetry: TopicReceiver<Telemetry>,
    sensors: TopicReceiver<SensorSample>,
    commands: TopicReceiver<JointCommand>,
    status: TopicReceiver<DaemonStatus>,
    _node: IpcNode,
}

impl ObserverPorts {
    /// Subscribes to `telemetry`, `sensors`, `commands` and `status` under `names`. Messages
    /// published from now on are received (and the newest stream message before, as history).
    pub fn open(names: &ServiceNames, node_name: &str) -> Result<Self, ShmError> {
        let (node, _) = services::create_node(node_name)?;
        // The status service is opened first and only opened: without a daemon this fails.
        let status = services::publish_subscribe(&node, names, Access::OpenOnly)?;
        let status = TopicReceiver::subscribe(names, &status, DaemonStatus::BUFFER)?;
        let telemetry = TopicReceiver::open(&node, names, Telemetry::BUFFER)?;
        let sensors = TopicReceiver::open(&node, names, SensorSample::BUFFER)?;
        let commands = TopicReceiver::open(&node, names, JointCommand::BUFFER)?;
        Ok(Self {
            telemetry,
            sensors,
            commands,
            status,
            _node: node,
        })
    }

    /// Passes every message received since the last call to `each`: telemetry first, then
    /// sensor samples, commands and statuses, each oldest first. A tick's telemetry is published
    /// after its sample and its command, so the sample and the command a drained telemetry
    /// names are delivered in the same call (unless they were lost). Returns how many.
    pub fn drain(&self, mut each: impl FnMut(Observed<'_>)) -> Result<usize, ShmError> {
        Ok(self.telemetry.drain(|t| each(Observed::Telemetry(t)))?
            + self.sensors.drain(|s| each(Observed::Sample(s)))?
            + self.commands.drain(|c| each(Observed::Command(c)))?
            + self.status.drain(|s| each(Observed::Status(s)))?)
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
