//! The daemon's ports: one set for the control thread, one for the service thread.

use core::time::Duration;

use core::ops::Deref;

use iceoryx2::active_request::ActiveRequest;
use iceoryx2::port::ReceiveError;
use iceoryx2::port::server::Server;
use iceoryx2::prelude::*;

use super::stream::{StreamReceiver, StreamSender};
use super::topic::TopicSender;
use crate::services::{self, Access, ControlService, IpcNode, SubmitService};
use crate::{
    ControlCommand, ControlReply, ControlRequest, DaemonStatus, DecodeError, JointCommand,
    SensorSample, ServiceNames, ShmError, SubmitReply, Telemetry,
};

/// The control thread's ports: sensor samples in, joint commands and telemetry out. All
/// operations are allocation-free after `open`.
pub struct DaemonLoopPorts {
    sensors: StreamReceiver<SensorSample>,
    commands: StreamSender<JointCommand>,
    telemetry: TopicSender<Telemetry>,
    _node: IpcNode,
}

impl DaemonLoopPorts {
    /// Opens (or creates) `sensors`, `commands` and `telemetry` under `names`.
    pub fn open(names: &ServiceNames, node_name: &str) -> Result<Self, ShmError> {
        let (node, _) = services::create_node(node_name)?;
        Ok(Self {
            sensors: StreamReceiver::open(&node, names)?,
            commands: StreamSender::open(&node, names)?,
            telemetry: TopicSender::open(&node, names, 1)?,
            _node: node,
        })
    }

    /// Writes one tick's telemetry in place and publishes it to the observers (no wake-up, no
    /// system call). Call it after the tick's command was sent.
    pub fn publish_telemetry(&self, fill: impl FnOnce(&mut Telemetry)) -> Result<(), ShmError> {
        self.telemetry.send(fill)
    }

    /// Blocks until the adapter announces a sample or `timeout` passes.
    pub fn wait_for_sample(&self, timeout: Duration) -> Result<bool, ShmError> {
        self.sensors.wait(timeout)
    }

    /// Copies the newest sample into `out`; false when none arrived since the last call.
    pub fn take_latest_sample(&self, out: &mut SensorSample) -> Result<bool, ShmError> {
        self.sensors.take_latest(out)
    }

    /// How many processes publish on `sensors` (more than one: two adapters' samples would
    /// interleave). Reads a counter in shared memory; no allocation.
    pub fn sensor_publishers(&self) -> usize {
        self.sensors.publishers()
    }

    /// Writes a command in place, stamps its send time and wakes the adapter.
    pub fn send_command(&self, fill: impl FnOnce(&mut JointCommand)) -> Result<(), ShmError> {
        self.commands.send(|command| {
            fill(command);
            command.timestamp_ns = crate::monotonic_ns();
        })
    }
}

/// The service thread's ports: status out, sequence submissions and control requests in.
pub struct DaemonServicePorts {
    stances_name: String,
    control_name: String,
    status: TopicSender<DaemonStatus>,
    stances: Server<ipc::Service, [u8], (), SubmitReply, ()>,
    control: Server<ipc::Service, ControlRequest, (), ControlReply, ()>,
    _services: (SubmitService, ControlService),
    _node: IpcNode,
    cleaned_dead_nodes: u64,
}

impl DaemonServicePorts {
    /// Opens (or creates) `status`, `stances` and `control` under `names`.
    pub fn open(names: &ServiceNames, node_name: &str) -> Result<Self, ShmError> {
        let (node, cleaned_dead_nodes) = services::create_node(node_name)?;
        let (stances_name, control_name) = (names.full("stances"), names.full("control"));
        let status = TopicSender::open(&node, names, 2)?;
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
            _services: (stances_service, control_service),
            _node: node,
            cleaned_dead_nodes,
        })
    }

    /// How many dead nodes (of killed processes) `open` cleaned up.
    pub fn cleaned_dead_nodes(&self) -> u64 {
        self.cleaned_dead_nodes
    }

    /// Publishes a status snapshot.
    pub fn publish_status(&self, status: &DaemonStatus) -> Result<(), ShmError> {
        self.status.send_copy(status)
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
