//! The adapter's ports: what a simulator or a hardware driver uses to talk to `walkd`.

use core::time::Duration;

use super::stream::{StreamReceiver, StreamSender};
use super::trust::Refusals;
use crate::services::{self, IpcNode};
use crate::{JointCommand, SensorSample, ServiceNames, ShmError};

/// Sensor samples out, joint commands in. Taking commands allocates nothing after `open` while
/// only the pinned daemon sends them (see below); each sample published is loaned from
/// iceoryx2, whose 0.10 loan allocates one small block.
///
/// A typical adapter loop: fill and [`publish_sample`](Self::publish_sample) every period;
/// [`take_latest_command`](Self::take_latest_command) before applying the next command; hold
/// position when no fresh command came for a few periods.
///
/// Commands are taken only from the daemon's publisher pinned on the first command; the others
/// are refused and counted ([`command_refusals`](Self::command_refusals)). While refused
/// commands come, the ports list the publishers of `commands` at most every 50 ms, and follow
/// the next daemon once the pinned one is gone (it left, or its process died).
pub struct AdapterPorts {
    sensors: StreamSender<SensorSample>,
    commands: StreamReceiver<JointCommand>,
    _node: IpcNode,
}

impl AdapterPorts {
    /// Opens (or creates) `sensors` and `commands` under `names`, so the adapter may start
    /// before or after the daemon.
    pub fn open(names: &ServiceNames, node_name: &str) -> Result<Self, ShmError> {
        let (node, _) = services::create_node(node_name)?;
        Ok(Self {
            sensors: StreamSender::open(&node, names)?,
            commands: StreamReceiver::open(&node, names, true)?,
            _node: node,
        })
    }

    /// Writes a sample in place, stamps its time ([`crate::monotonic_ns`]) and wakes the daemon.
    /// The caller sets `seq`, the joint values and wrenches.
    pub fn publish_sample(&self, fill: impl FnOnce(&mut SensorSample)) -> Result<(), ShmError> {
        self.sensors.send(|sample| {
            fill(sample);
            sample.timestamp_ns = crate::monotonic_ns();
        })
    }

    /// Blocks until the daemon announces a command or `timeout` passes.
    pub fn wait_for_command(&self, timeout: Duration) -> Result<bool, ShmError> {
        self.commands.wait(timeout)
    }

    /// Copies the newest command of the pinned daemon into `out`; false when none arrived since
    /// the last call.
    pub fn take_latest_command(&self, out: &mut JointCommand) -> Result<bool, ShmError> {
        Ok(self.commands.take_latest(out)?.any())
    }

    /// Commands refused because another publisher than the pinned daemon sent them.
    pub fn command_refusals(&self) -> Refusals {
        self.commands.trusted().refusals()
    }
}
