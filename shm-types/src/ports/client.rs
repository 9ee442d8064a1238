//! The client's ports: status, sequence submission and control of a running `walkd`.
//!
//! Each port is created when it is first needed, so a client that only watches the status does
//! not take a `control` or `stances` slot, and one service whose slots another process holds
//! does not lock a client out of the others.

use core::time::Duration;
use std::cell::OnceCell;

use iceoryx2::pending_response::PendingResponse;
use iceoryx2::port::client::Client;
use iceoryx2::prelude::*;
use iceoryx2::service::port_factory::client::ClientCreateError;

use super::trust::TrustedReceiver;
use crate::services::{self, Access, ControlService, IpcNode, SubmitService, Topic, capacity};
use crate::{
    ControlCommand, ControlReply, ControlRequest, DaemonStatus, ServiceNames, ShmError, SubmitReply,
};

/// How often a waiting client looks for an answer.
const POLL: Duration = Duration::from_millis(1);

/// How long a client waits for a published status before it asks walkd for it instead (walkd
/// publishes none when every publisher slot of `status` is taken): five periods of the default
/// `[runtime] status_rate_hz` (20).
const UNPUBLISHED_STATUS_WAIT: Duration = Duration::from_millis(250);

type StancesClient = Client<ipc::Service, [u8], (), SubmitReply, ()>;
type ControlClient = Client<ipc::Service, ControlRequest, (), ControlReply, ()>;

/// Connection to a running daemon. Only opens services: if no daemon ever created them,
/// [`connect`](Self::connect) fails with [`ShmError::NotRunning`].
pub struct ClientPorts {
    names: ServiceNames,
    status: OnceCell<TrustedReceiver<DaemonStatus>>,
    stances: OnceCell<StancesClient>,
    control: OnceCell<ControlClient>,
    stances_service: SubmitService,
    control_service: ControlService,
    node: IpcNode,
}

impl ClientPorts {
    /// Opens the daemon's `status`, `stances` and `control` services under `names`, and
    /// subscribes to the status right away if it can (so the newest one is delivered soon).
    pub fn connect(names: &ServiceNames, node_name: &str) -> Result<Self, ShmError> {
        let (node, _) = services::create_node(node_name)?;
        // Only a daemon creates the status service: without one this fails at once.
        services::publish_subscribe::<DaemonStatus>(&node, names, Access::OpenOnly)?;
        let ports = Self {
            names: names.clone(),
            stances_service: services::stances(&node, names, Access::OpenOnly)?,
            control_service: services::control(&node, names, Access::OpenOnly)?,
            status: OnceCell::new(),
            stances: OnceCell::new(),
            control: OnceCell::new(),
            node,
        };
        // A full status service is reported when the status is asked for, not here.
        let _ = ports.status_subscriber();
        Ok(ports)
    }

    /// Whether a live daemon serves these services (a stances and a control server exist; the
    /// status publisher may be missing: monitoring cannot stop walkd). A `kill -9`ed daemon's
    /// ports are cleaned by `connect`, so they don't count.
    pub fn daemon_present(&self) -> bool {
        self.stances_service.dynamic_config().number_of_servers() > 0
            && self.control_service.dynamic_config().number_of_servers() > 0
    }

    /// The status subscriber: it takes the statuses of the first publisher heard (walkd's) and
    /// refuses any other's.
    fn status_subscriber(&self) -> Result<&TrustedReceiver<DaemonStatus>, ShmError> {
        created(&self.status, || {
            let service = services::publish_subscribe(&self.node, &self.names, Access::OpenOnly)?;
            TrustedReceiver::subscribe(&self.names, service, DaemonStatus::BUFFER, true)
        })
    }

    fn stances_client(&self) -> Result<&StancesClient, ShmError> {
        created(&self.stances, || {
            self.stances_service
                .client_builder()
                .initial_max_slice_len(64 * 1024)
                .allocation_strategy(AllocationStrategy::PowerOfTwo)
                .create()
                .map_err(|e| {
                    client_error(&self.names.full("stances"), capacity::STANCES_CLIENTS, e)
                })
        })
    }

    fn control_client(&self) -> Result<&ControlClient, ShmError> {
        created(&self.control, || {
            self.control_service.client_builder().create().map_err(|e| {
                client_error(&self.names.full("control"), capacity::CONTROL_CLIENTS, e)
            })
        })
    }

    /// The newest status received since the last call, if any.
    pub fn latest_status(&self) -> Result<Option<DaemonStatus>, ShmError> {
        let subscriber = self.status_subscriber()?;
        let mut status = DaemonStatus::INITIAL;
        if !subscriber.take_latest(&mut status)?.any() {
            return Ok(None);
        }
        checked_status(subscriber.name(), status).map(Some)
    }

    /// Waits up to `timeout` for a status newer than the last one received. When none is
    /// published for 250 ms (walkd found no free publisher slot on `status`), asks walkd for it
    /// instead.
    pub fn next_status(&self, timeout: Duration) -> Result<DaemonStatus, ShmError> {
        let service = self.names.full("status");
        let mut ask_at = std::time::Instant::now() + UNPUBLISHED_STATUS_WAIT;
        poll_until(&service, timeout, || {
            if std::time::Instant::now() < ask_at {
                return self.latest_status();
            }
            ask_at = std::time::Instant::now() + UNPUBLISHED_STATUS_WAIT;
            match self.control(ControlCommand::Query, timeout) {
                Ok(reply) => Ok(Some(reply.status)),
                // Every control slot taken: the published status is all there is.
                Err(ShmError::ServiceFull { .. }) => self.latest_status(),
                Err(other) => Err(other),
            }
        })
    }

    /// Submits a post-processed sequence (its JSON) and waits up to `timeout` for the verdict.
    /// The daemon bounds the size (`[runtime] max_submission_bytes`) and says so if it is
    /// exceeded.
    pub fn submit(&self, json: &[u8], timeout: Duration) -> Result<SubmitReply, ShmError> {
        let service = self.names.full("stances");
        let request = self
            .stances_client()?
            .loan_slice_uninit(json.len())
            .map_err(|e| ShmError::ipc("loan a request on", &service, e))?;
        let pending = request
            .write_from_slice(json)
            .send()
            .map_err(|e| ShmError::ipc("send to", &service, e))?;
        wait_for_reply(&service, timeout, &pending)
    }

    /// Sends a control command and waits up to `timeout` for the answer.
    pub fn control(
        &self,
        command: ControlCommand,
        timeout: Duration,
    ) -> Result<ControlReply, ShmError> {
        let service = self.names.full("control");
        let pending = self
            .control_client()?
            .send_copy(ControlRequest::new(command))
            .map_err(|e| ShmError::ipc("send to", &service, e))?;
        let reply = wait_for_reply(&service, timeout, &pending)?;
        checked_status(&service, reply.status)?;
        Ok(reply)
    }
}

/// The port in `cell`, created by `create` on first use.
fn created<T>(
    cell: &OnceCell<T>,
    create: impl FnOnce() -> Result<T, ShmError>,
) -> Result<&T, ShmError> {
    if let Some(port) = cell.get() {
        return Ok(port);
    }
    let port = create()?;
    Ok(cell.get_or_init(|| port))
}

fn client_error(service: &str, limit: usize, error: ClientCreateError) -> ShmError {
    match error {
        ClientCreateError::ExceedsMaxSupportedClients => ShmError::ServiceFull {
            service: service.to_owned(),
            port: "client",
            limit,
        },
        other => ShmError::ipc("create client on", service, other),
    }
}

/// A status whose codes and flags the client can read, or an error naming the bad field.
fn checked_status(service: &str, status: DaemonStatus) -> Result<DaemonStatus, ShmError> {
    status
        .validate()
        .map(|()| status)
        .map_err(|e| ShmError::ipc("read a status from", service, e.to_string()))
}

/// Waits up to `timeout` for the server's answer to a sent request.
fn wait_for_reply<Request, Reply>(
    service: &str,
    timeout: Duration,
    pending: &PendingResponse<ipc::Service, Request, (), Reply, ()>,
) -> Result<Reply, ShmError>
where
    Request: core::fmt::Debug + IceoryxSend + ?Sized,
    Reply: core::fmt::Debug + ZeroCopySend + Copy,
{
    poll_until(service, timeout, || {
        pending
            .receive()
            .map(|reply| reply.map(|r| *r.payload()))
            .map_err(|e| ShmError::ipc("receive reply from", service, e))
    })
}

/// Calls `poll` every millisecond until it yields a value or `timeout` passes.
fn poll_until<T>(
    service: &str,
    timeout: Duration,
    mut poll: impl FnMut() -> Result<Option<T>, ShmError>,
) -> Result<T, ShmError> {
    let start = std::time::Instant::now();
    loop {
        if let Some(value) = poll()? {
            return Ok(value);
        }
        if start.elapsed() >= timeout {
            return Err(ShmError::Timeout {
                service: service.to_owned(),
                timeout_ms: timeout.as_millis() as u64,
            });
        }
        std::thread::sleep(POLL);
    }
}
