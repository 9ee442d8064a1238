//! The adapter's ports: what a simulator or a hardware driver uses to talk to `walkd`.

use core::time::Duration;

use super::stream::{StreamReceiver, StreamSender};
use crate::services::{self, IpcNode};
use crate::{JointCommand, SensorSample, ServiceNames, ShmError};

/// Sensor samples out, joint commands in. All operations are allocation-free after `open`.
///
/// A typical adapter loop: fill and [`publish_sample`](Self::publish_sample) every period;
/// [`take_latest_command`](Self::take_latest_command) before applying the next command; hold
/// position when no fresh command came for a few periods.
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
            commands: StreamReceiver::open(&node, names)?,
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

    /// Copies the newest command into `out`; false when none arrived since the last call.
    pub fn take_latest_command(&self, out: &mut JointCommand) -> Result<bool, ShmError> {
        self.commands.take_latest(out)
    }
}
