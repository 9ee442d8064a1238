//! The daemon's ports: one set for the control thread, one for the service thread.

use core::time::Duration;

use core::ops::Deref;

use iceoryx2::active_request::ActiveRequest;
use iceoryx2::port::ReceiveError;
use iceoryx2::port::server::Server;
use iceoryx2::prelude::*;

use super::stream::{StreamReceiver, StreamSender};
use super::topic::TopicSender;
use super::trust::{self, Pin, PublisherId, Roster};
use crate::services::{self, Access, ControlService, IpcNode, PubSub, SubmitService};
use crate::{
    ControlCommand, ControlReply, ControlRequest, DaemonStatus, DecodeError, JointCommand,
    SensorSample, ServiceNames, ShmError, SubmitReply, Telemetry,
};

/// The control thread's ports: sensor samples in, joint commands and telemetry out. Taking
/// samples allocates nothing after `open`; each message sent is loaned from iceoryx2, whose
/// 0.10 loan allocates one small block (`tests/control_thread_allocation.rs` counts both).
///
/// Samples are taken only from the adapter's publisher pinned on the first sample; the others
/// are refused and counted ([`Pin`]). Telemetry is for observers only: when its service cannot
/// be opened or has no free publisher slot, the ports open without it and say why
/// ([`telemetry_off`](Self::telemetry_off)).
pub struct DaemonLoopPorts {
    sensors: StreamReceiver<SensorSample>,
    commands: StreamSender<JointCommand>,
    telemetry: Result<TopicSender<Telemetry>, ShmError>,
    _node: IpcNode,
}

impl DaemonLoopPorts {
    /// Opens (or creates) `sensors` and `commands` under `names`, and `telemetry` if it can.
    pub fn open(names: &ServiceNames, node_name: &str) -> Result<Self, ShmError> {
        let (node, _) = services::create_node(node_name)?;
        Ok(Self {
            sensors: StreamReceiver::open(&node, names, false)?,
            commands: StreamSender::open(&node, names)?,
            telemetry: TopicSender::open(&node, names, 1),
            _node: node,
        })
    }

    /// Why there is no telemetry (its service could not be opened, or every publisher slot of it
    /// is taken); `None` while it is published.
    pub fn telemetry_off(&self) -> Option<&ShmError> {
        self.telemetry.as_ref().err()
    }

    /// Writes one tick's telemetry in place and publishes it to the observers (no wake-up, no
    /// system call); nothing without telemetry. Call it after the tick's command was sent.
    pub fn publish_telemetry(&self, fill: impl FnOnce(&mut Telemetry)) -> Result<(), ShmError> {
        match &self.telemetry {
            Ok(telemetry) => telemetry.send(fill),
            Err(_) => Ok(()),
        }
    }

    /// Blocks until the adapter announces a sample or `timeout` passes.
    pub fn wait_for_sample(&self, timeout: Duration) -> Result<bool, ShmError> {
        self.sensors.wait(timeout)
    }

    /// Copies the newest sample of the pinned adapter into `out` (pinning the publisher of the
    /// first sample); false when none arrived since the last call. Samples of other publishers
    /// are refused and counted in [`sensor_pin`](Self::sensor_pin).
    pub fn take_latest_sample(&self, out: &mut SensorSample) -> Result<bool, ShmError> {
        Ok(self.sensors.take_latest(out)?.any())
    }

    /// Which publisher on `sensors` is trusted, and what the others sent.
    pub fn sensor_pin(&self) -> Pin {
        self.sensors.trusted().pin()
    }

    /// The pinned adapter `publisher` is gone (another thread reviewed `sensors`,
    /// [`DaemonServicePorts::review_sensors`]): the next publisher heard is pinned.
    pub fn release_sensor_pin(&self, publisher: PublisherId) {
        self.sensors.trusted().release(publisher);
    }

    /// Writes a command in place, stamps its send time and wakes the adapter.
    pub fn send_command(&self, fill: impl FnOnce(&mut JointCommand)) -> Result<(), ShmError> {
        self.commands.send(|command| {
            fill(command);
            command.timestamp_ns = crate::monotonic_ns();
        })
    }
}

/// The service thread's ports: status out, sequence submissions and control requests in, and
/// the roster of `sensors`.
///
/// The status is for monitoring: when its service has no free publisher slot, the ports open
/// without it and say why ([`status_off`](Self::status_off)); clients then get the status with
/// their control queries.
pub struct DaemonServicePorts {
    stances_name: String,
    control_name: String,
    status: Result<TopicSender<DaemonStatus>, ShmError>,
    stances: Server<ipc::Service, [u8], (), SubmitReply, ()>,
    control: Server<ipc::Service, ControlRequest, (), ControlReply, ()>,
    sensors: PubSub<SensorSample>,
    _services: (SubmitService, ControlService),
    _node: IpcNode,
    cleaned_dead_nodes: u64,
}

impl DaemonServicePorts {
    /// Opens (or creates) `stances`, `control` and `sensors` under `names`, and publishes on
    /// `status` if it can.
    pub fn open(names: &ServiceNames, node_name: &str) -> Result<Self, ShmError> {
        let (node, cleaned_dead_nodes) = services::create_node(node_name)?;
        let (stances_name, control_name) = (names.full("stances"), names.full("control"));
        let status = TopicSender::open(&node, names, 2);
        let sensors = services::publish_subscribe(&node, names, Access::OpenOrCreate)?;
        let stances_service = services::stances(&node, names, Access::OpenOrCreate)?;
        let control_service = services::control(&node, names, Access::OpenOrCreate)?;
        let stances = stances_service
            .server_builder()
            .create()
            .map_err(|e| ShmError::ipc("create server on", &stances_name, e))?;
        let control = control_service
            .server_builder()
            .create()
            .map_err(|e| ShmError::ipc("create server on", &control_name, e))?;
        Ok(Self {
            stances_name,
            control_name,
            status,
            stances,
            control,
            sensors,
            _services: (stances_service, control_service),
            _node: node,
            cleaned_dead_nodes,
        })
    }

    /// How many dead nodes (of killed processes) `open` cleaned up.
    pub fn cleaned_dead_nodes(&self) -> u64 {
        self.cleaned_dead_nodes
    }

    /// Why the status is not published (no free publisher slot, or its service could not be
    /// opened); `None` while it is.
    pub fn status_off(&self) -> Option<&ShmError> {
        self.status.as_ref().err()
    }

    /// Publishes a status snapshot (nothing while the status is off).
    pub fn publish_status(&self, status: &DaemonStatus) -> Result<(), ShmError> {
        match &self.status {
            Ok(sender) => sender.send_copy(status),
            Err(_) => Ok(()),
        }
    }

    /// The publishers on `sensors` now, and whether `pinned` (the control thread's adapter) is
    /// gone; with `clean_dead`, dead processes' nodes are removed first. Allocates.
    pub fn review_sensors(&self, pinned: Option<PublisherId>, clean_dead: bool) -> Roster {
        trust::review(&self.sensors, pinned, clean_dead)
    }

    /// Answers at most one pending submission with `handle(json_bytes)`; returns whether there
    /// was one.
    pub fn serve_submission(
        &self,
        handle: impl FnOnce(&[u8]) -> SubmitReply,
    ) -> Result<bool, ShmError> {
        answer(&self.stances_name, self.stances.receive(), handle)
    }

    /// Answers at most one pending control request with `handle(command)`, where `command` is
    /// the decoded command or why its code means none (refuse it with that reason); returns
    /// whether there was a request.
    pub fn serve_control(
        &self,
        handle: impl FnOnce(Result<ControlCommand, DecodeError>) -> ControlReply,
    ) -> Result<bool, ShmError> {
        answer(&self.control_name, self.control.receive(), |request| {
            handle(request.command.get())
        })
    }
}

/// A request a server received and has not answered yet.
type Received<Request, Reply> = ActiveRequest<ipc::Service, Request, (), Reply, ()>;

/// Answers the request a server `received` (if any) with `handle(payload)`; returns whether
/// there was one.
fn answer<Request, Reply>(
    service: &str,
    received: Result<Option<Received<Request, Reply>>, ReceiveError>,
    handle: impl FnOnce(&Request) -> Reply,
) -> Result<bool, ShmError>
where
    Request: core::fmt::Debug + IceoryxSend + ?Sized,
    Reply: core::fmt::Debug + ZeroCopySend,
    Received<Request, Reply>: Deref<Target = Request>,
{
    let Some(request) = received.map_err(|e| ShmError::ipc("receive from", service, e))? else {
        return Ok(false);
    };
    let reply = handle(&request);
    request
        .send_copy(reply)
        .map_err(|e| ShmError::ipc("reply on", service, e))?;
    Ok(true)
}
