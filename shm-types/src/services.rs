//! Service names under a robot's prefix and the one place where every service's QoS is set.
//!
//! All roles open services through these functions so their settings always agree (iceoryx2
//! treats the settings of an opener as minimum requirements of the existing service).

use core::time::Duration;

use iceoryx2::prelude::*;
use iceoryx2::service::builder::event::EventOpenOrCreateError;
use iceoryx2::service::builder::publish_subscribe::{
    PublishSubscribeOpenError, PublishSubscribeOpenOrCreateError,
};
use iceoryx2::service::builder::request_response::{
    RequestResponseOpenError, RequestResponseOpenOrCreateError,
};
use iceoryx2::service::port_factory::{event, publish_subscribe, request_response};

use crate::{
    ControlReply, ControlRequest, DaemonStatus, JointCommand, PROTOCOL_VERSION, SensorSample,
    ShmError, SimTruth, SubmitReply, Telemetry,
};

/// The names of one robot's services: `<prefix>/sensors`, `<prefix>/commands`, ...
#[derive(Debug, Clone)]
pub struct ServiceNames {
    prefix: String,
}

/// Port limits of every service (iceoryx2 fixes them when a service is created). iceoryx2 has no
/// per-process quota, so each limit leaves room beyond the ports the system itself uses: a
/// process that holds a few ports (a leak, a greedy monitor, a second adapter started by
/// mistake) cannot lock out the daemon, its adapter or monitoring. docs/ipc.md ("Capacity")
/// lists them.
pub mod capacity {
    /// Publishers on `sensors` (the adapter; an adapter restarting while the dead one is
    /// cleaned; spare) and on `commands` (walkd; a restarting walkd; spare). walkd takes samples
    /// only from the adapter it pinned, and refuses to walk while `sensors` has another
    /// publisher (see `DaemonServicePorts::review_sensors`).
    pub const STREAM_PUBLISHERS: usize = 4;
    /// Subscribers of `sensors` and `commands`: walkd or the adapter, plus observers.
    pub const STREAM_SUBSCRIBERS: usize = 16;
    /// Subscribers of `status`: every `walkctl watch`, `status`, `demo` and observer.
    pub const STATUS_SUBSCRIBERS: usize = 64;
    /// Clients of `control` (query, hold, abort).
    pub const CONTROL_CLIENTS: usize = 32;
    /// Clients of `stances` (each holds a data segment for its largest submission).
    pub const STANCES_CLIENTS: usize = 16;
    /// Subscribers of `telemetry`: observers (`walkctl record`, `view`, `demo --record`).
    pub const TELEMETRY_SUBSCRIBERS: usize = 8;
    /// Processes' nodes that may open one service.
    pub const NODES: usize = 128;
}

/// Messages of `sensors` and `commands` an observer's subscriber holds before the oldest is
/// dropped: 128 ms at 1 kHz, so an observer that drains every few milliseconds loses none. walkd
/// and the adapters keep only the newest message and subscribe with [`STREAM_PEER_BUFFER`].
pub const STREAM_OBSERVER_BUFFER: usize = 128;

/// Buffer of walkd's and an adapter's stream subscriber: they take the newest message only.
pub const STREAM_PEER_BUFFER: usize = 4;

/// Messages of `telemetry` a subscriber holds before the oldest is dropped: 256 ms at 1 kHz
/// (walkd publishes one per control tick).
pub const TELEMETRY_BUFFER: usize = 256;

/// The service kinds, used to build names.
const SENSORS: &str = "sensors";
const COMMANDS: &str = "commands";
const STATUS: &str = "status";
const STANCES: &str = "stances";
const CONTROL: &str = "control";
const SIM_TRUTH: &str = "sim-truth";
const TELEMETRY: &str = "telemetry";

impl ServiceNames {
    /// Names under `prefix` (e.g. `walk/armar4`); fails if a resulting name is not a valid
    /// iceoryx2 service name.
    pub fn new(prefix: &str) -> Result<Self, ShmError> {
        let names = Self {
            prefix: prefix.trim_end_matches('/').to_owned(),
        };
        if names.prefix.is_empty() {
            return Err(ShmError::InvalidServiceName {
                name: prefix.to_owned(),
                detail: "the service prefix is empty".to_owned(),
            });
        }
        for kind in [
            SENSORS, COMMANDS, STATUS, STANCES, CONTROL, SIM_TRUTH, TELEMETRY,
        ] {
            names.service_name(kind)?;
        }
        Ok(names)
    }

    /// The prefix these names live under.
    pub fn prefix(&self) -> &str {
        &self.prefix
    }

    /// The full name of one service, e.g. `walk/armar4/sensors`.
    pub fn full(&self, kind: &str) -> String {
        format!("{}/{kind}", self.prefix)
    }

    fn service_name(&self, kind: &str) -> Result<ServiceName, ShmError> {
        let name = self.full(kind);
        ServiceName::new(&name).map_err(|e| ShmError::InvalidServiceName {
            name,
            detail: format!("{e:?}"),
        })
    }
}

/// The kind of iceoryx2 node every process of this system uses.
pub type IpcNode = Node<ipc::Service>;

/// Creates a node that installs no signal handlers: each process decides what SIGTERM means.
/// Also removes the resources of dead nodes (e.g. a `kill -9`ed daemon) so the services can be
/// reused at once; returns how many dead nodes were found and cleaned.
pub fn create_node(name: &str) -> Result<(IpcNode, u64), ShmError> {
    set_log_level_from_env_or(LogLevel::Error);
    let dead_before = count_dead_nodes();
    let node_name = NodeName::new(name).map_err(|e| ShmError::ipc("name node", name, e))?;
    let node = NodeBuilder::new()
        .name(&node_name)
        .signal_handling_mode(SignalHandlingMode::Disabled)
        .create::<ipc::Service>()
        .map_err(|e| ShmError::ipc("create node", name, e))?;
    node.try_cleanup_dead_nodes();
    Ok((node, dead_before.saturating_sub(count_dead_nodes())))
}

/// Removes the resources of the nodes whose process died without releasing them (iceoryx2's
/// dead-node detection): their ports leave every service.
pub(crate) fn remove_dead_nodes() {
    let mut dead = Vec::new();
    // A failing listing only means there is nothing to remove.
    let _ = IpcNode::list(Config::global_config(), |state| {
        if let NodeState::Dead(node) = state {
            dead.push(node);
        }
        CallbackProgression::Continue
    });
    for node in dead {
        // Another process cleaning it, or no permission: it stays listed, and counts.
        let _ = node.try_remove_stale_resources();
    }
}

/// Number of nodes whose process died without releasing them.
fn count_dead_nodes() -> u64 {
    let mut dead = 0;
    // A failing listing only means there is nothing to report.
    let _ = IpcNode::list(Config::global_config(), |state| {
        if matches!(state, NodeState::Dead(_)) {
            dead += 1;
        }
        CallbackProgression::Continue
    });
    dead
}

pub(crate) type PubSub<T> = publish_subscribe::PortFactory<ipc::Service, T, ()>;
pub(crate) type Event = event::PortFactory<ipc::Service>;
pub(crate) type SubmitService =
    request_response::PortFactory<ipc::Service, [u8], (), SubmitReply, ()>;
pub(crate) type ControlService =
    request_response::PortFactory<ipc::Service, ControlRequest, (), ControlReply, ()>;

/// Whether the caller may create a missing service (daemon, adapter) or only open it (client).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Access {
    OpenOrCreate,
    OpenOnly,
}

fn pubsub_error(service: &str, error: PublishSubscribeOpenOrCreateError) -> ShmError {
    match error {
        PublishSubscribeOpenOrCreateError::PublishSubscribeOpenError(e) => {
            pubsub_open_error(service, e)
        }
        other => ShmError::ipc("open or create", service, other),
    }
}

fn pubsub_open_error(service: &str, error: PublishSubscribeOpenError) -> ShmError {
    match error {
        PublishSubscribeOpenError::IncompatibleTypes => protocol_mismatch(service),
        PublishSubscribeOpenError::DoesNotExist => not_running(service),
        other => ShmError::ipc("open", service, other),
    }
}

fn request_response_error(service: &str, error: RequestResponseOpenOrCreateError) -> ShmError {
    match error {
        RequestResponseOpenOrCreateError::RequestResponseOpenError(e) => {
            request_response_open_error(service, e)
        }
        other => ShmError::ipc("open or create", service, other),
    }
}

fn request_response_open_error(service: &str, error: RequestResponseOpenError) -> ShmError {
    match error {
        RequestResponseOpenError::IncompatibleRequestOrResponseType => protocol_mismatch(service),
        RequestResponseOpenError::DoesNotExist => not_running(service),
        other => ShmError::ipc("open", service, other),
    }
}

/// The peer that created `service` uses other message types: another protocol version.
fn protocol_mismatch(service: &str) -> ShmError {
    ShmError::ProtocolMismatch {
        service: service.to_owned(),
        ours: PROTOCOL_VERSION,
    }
}

/// Nobody created `service`: no daemon serves this prefix.
fn not_running(service: &str) -> ShmError {
    ShmError::NotRunning {
        service: service.to_owned(),
    }
}

/// A message type with a publish-subscribe service of its own: the type names the service and
/// fixes its settings, so a port cannot open a service with the wrong payload and every role opens
/// it with the same settings. Every such service keeps the newest message for a late subscriber
/// and drops a subscriber's oldest message when its buffer is full.
pub(crate) trait Topic: core::fmt::Debug + ZeroCopySend + Copy + Default + 'static {
    /// The service's kind: the last part of its name.
    const KIND: &'static str;
    /// Messages a subscriber may buffer before the oldest is dropped.
    const BUFFER: usize;
    /// Subscribers the service admits.
    const SUBSCRIBERS: usize;
    /// Publishers the service admits: the one that serves it and one restarting.
    const PUBLISHERS: usize = 2;
    /// Messages a subscriber may hold at once.
    const BORROWED: usize = 2;
}

/// A payload that travels on a high-rate stream of its own (sensors, commands), accompanied by a
/// wake-up event of the same name.
pub(crate) trait StreamPayload:
    core::fmt::Debug + ZeroCopySend + Copy + Default + 'static
{
    /// The stream's kind: the last part of its service name.
    const KIND: &'static str;
}

impl StreamPayload for SensorSample {
    const KIND: &'static str = SENSORS;
}

impl StreamPayload for JointCommand {
    const KIND: &'static str = COMMANDS;
}

/// A stream: its subscribers may buffer up to [`STREAM_OBSERVER_BUFFER`] messages (observers);
/// the peers subscribe with [`STREAM_PEER_BUFFER`].
impl<T: StreamPayload> Topic for T {
    const KIND: &'static str = <T as StreamPayload>::KIND;
    const BUFFER: usize = STREAM_OBSERVER_BUFFER;
    const SUBSCRIBERS: usize = capacity::STREAM_SUBSCRIBERS;
    const PUBLISHERS: usize = capacity::STREAM_PUBLISHERS;
    const BORROWED: usize = 4;
}

/// The daemon's status: a client needs only the newest.
impl Topic for DaemonStatus {
    const KIND: &'static str = STATUS;
    const BUFFER: usize = 2;
    const SUBSCRIBERS: usize = capacity::STATUS_SUBSCRIBERS;
}

/// Messages of `sim-truth` a subscriber can hold before the oldest is dropped: 0.5 s of samples
/// at 2 kHz, or about 70 ms of a lockstep run going 15 000 samples per wall second.
pub const SIM_TRUTH_BUFFER: usize = 1024;

/// The simulator's ground truth: published with every sample, read by evaluation clients that
/// drain it continuously.
impl Topic for SimTruth {
    const KIND: &'static str = SIM_TRUTH;
    const BUFFER: usize = SIM_TRUTH_BUFFER;
    const SUBSCRIBERS: usize = capacity::STREAM_SUBSCRIBERS;
}

/// The control thread's per-tick telemetry: published by walkd, drained by observers.
impl Topic for Telemetry {
    const KIND: &'static str = TELEMETRY;
    const BUFFER: usize = TELEMETRY_BUFFER;
    const SUBSCRIBERS: usize = capacity::TELEMETRY_SUBSCRIBERS;
}

/// Opens the service of `T` under `names` (creating it first if `access` allows) with the
/// settings `T` fixes.
pub(crate) fn publish_subscribe<T: Topic>(
    node: &IpcNode,
    names: &ServiceNames,
    access: Access,
) -> Result<PubSub<T>, ShmError> {
    let service = names.full(T::KIND);
    let builder = node
        .service_builder(&names.service_name(T::KIND)?)
        .publish_subscribe::<T>()
        .enable_safe_overflow(true)
        .history_size(1)
        .subscriber_max_buffer_size(T::BUFFER)
        .subscriber_max_borrowed_samples(T::BORROWED)
        .max_publishers(T::PUBLISHERS)
        .max_subscribers(T::SUBSCRIBERS)
        .max_nodes(capacity::NODES);
    match access {
        Access::OpenOrCreate => builder
            .open_or_create()
            .map_err(|e| pubsub_error(&service, e)),
        Access::OpenOnly => builder.open().map_err(|e| pubsub_open_error(&service, e)),
    }
}

/// The wake-up event that accompanies the stream of `T`.
pub(crate) fn stream_event<T: StreamPayload>(
    node: &IpcNode,
    names: &ServiceNames,
) -> Result<Event, ShmError> {
    let service = names.full(T::KIND);
    node.service_builder(&names.service_name(T::KIND)?)
        .event()
        .max_notifiers(capacity::STREAM_PUBLISHERS)
        .max_listeners(capacity::STREAM_SUBSCRIBERS)
        .max_nodes(capacity::NODES)
        .open_or_create()
        .map_err(|e: EventOpenOrCreateError| ShmError::ipc("open or create event", &service, e))
}

/// Opens a client → daemon request-response service: few clients, one answer per request.
/// (A macro because iceoryx2's builder has distinct impls for sized and slice requests.)
macro_rules! request_response_service {
    ($node:expr, $names:expr, $kind:expr, $access:expr, $clients:expr, $req:ty, $resp:ty) => {{
        let service = $names.full($kind);
        let builder = $node
            .service_builder(&$names.service_name($kind)?)
            .request_response::<$req, $resp>()
            .max_clients($clients)
            .max_nodes(capacity::NODES)
            .max_servers(2)
            .max_active_requests_per_client(2)
            .max_response_buffer_size(2);
        match $access {
            Access::OpenOrCreate => builder
                .open_or_create()
                .map_err(|e| request_response_error(&service, e)),
            Access::OpenOnly => builder
                .open()
                .map_err(|e| request_response_open_error(&service, e)),
        }
    }};
}

pub(crate) fn stances(
    node: &IpcNode,
    names: &ServiceNames,
    access: Access,
) -> Result<SubmitService, ShmError> {
    request_response_service!(
        node,
        names,
        STANCES,
        access,
        capacity::STANCES_CLIENTS,
        [u8],
        SubmitReply
    )
}

pub(crate) fn control(
    node: &IpcNode,
    names: &ServiceNames,
    access: Access,
) -> Result<ControlService, ShmError> {
    request_response_service!(
        node,
        names,
        CONTROL,
        access,
        capacity::CONTROL_CLIENTS,
        ControlRequest,
        ControlReply
    )
}

/// Converts an absolute time on [`crate::monotonic_ns`] into the timeout left until then.
pub fn time_until(deadline_ns: u64) -> Duration {
    Duration::from_nanos(deadline_ns.saturating_sub(crate::monotonic_ns()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::AdapterPorts;

    /// A sample type from "another protocol version": same layout idea, other type name.
    #[repr(C)]
    #[derive(Debug, Clone, Copy, Default, ZeroCopySend)]
    #[type_name("walk.v0.SensorSample")]
    struct OldSensorSample {
        seq: u64,
    }

    /// The v0 peer used the same stream and the same QoS, so only the type differs.
    impl StreamPayload for OldSensorSample {
        const KIND: &'static str = SENSORS;
    }

    #[test]
    fn a_peer_of_another_protocol_version_is_refused_at_connect() {
        let prefix = format!("walk-test/shm-types/mismatch/{}", std::process::id());
        let names = ServiceNames::new(&prefix).unwrap();
        let (node, _) = create_node("v0-peer").unwrap();
        let _old =
            publish_subscribe::<OldSensorSample>(&node, &names, Access::OpenOrCreate).unwrap();
        match AdapterPorts::open(&names, "adapter") {
            Err(error @ ShmError::ProtocolMismatch { .. }) => {
                assert!(error.to_string().contains(&format!("{prefix}/sensors")));
            }
            Err(other) => panic!("expected a protocol mismatch, got {other}"),
            Ok(_) => panic!("a v0 service was opened with v1 types"),
        }
    }
}
