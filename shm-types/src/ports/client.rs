//! The client's ports: status, sequence submission and control of a running `walkd`.

use core::time::Duration;

use iceoryx2::pending_response::PendingResponse;
use iceoryx2::port::client::Client;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::prelude::*;

use crate::services::{self, Access, ControlService, IpcNode, PubSub, SubmitService};
use crate::{
    ControlCommand, ControlReply, ControlRequest, DaemonStatus, MAX_SEQUENCE_BYTES, ServiceNames,
    ShmError, SubmitReply,
};

/// How often a waiting client looks for an answer.
const POLL: Duration = Duration::from_millis(1);

/// Connection to a running daemon. Only opens services: if no daemon ever created them,
/// [`connect`](Self::connect) fails with [`ShmError::NotRunning`].
pub struct ClientPorts {
    names: ServiceNames,
    status: Subscriber<ipc::Service, DaemonStatus, ()>,
    stances: Client<ipc::Service, [u8], (), SubmitReply, ()>,
    control: Client<ipc::Service, ControlRequest, (), ControlReply, ()>,
    status_service: PubSub<DaemonStatus>,
    stances_service: SubmitService,
    _control_service: ControlService,
    _node: IpcNode,
}

impl ClientPorts {
    /// Opens the daemon's `status`, `stances` and `control` services under `names`.
    pub fn connect(names: &ServiceNames, node_name: &str) -> Result<Self, ShmError> {
        let (node, _) = services::create_node(node_name)?;
        let status_service = services::status(&node, names, Access::OpenOnly)?;
        let stances_service = services::stances(&node, names, Access::OpenOnly)?;
        let control_service = services::control(&node, names, Access::OpenOnly)?;
        let status = status_service
            .subscriber_builder()
            .create()
            .map_err(|e| ShmError::ipc("create subscriber on", &names.full("status"), e))?;
        let stances = stances_service
            .client_builder()
            .initial_max_slice_len(64 * 1024)
            .allocation_strategy(AllocationStrategy::PowerOfTwo)
            .create()
            .map_err(|e| ShmError::ipc("create client on", &names.full("stances"), e))?;
        let control = control_service
            .client_builder()
            .create()
            .map_err(|e| ShmError::ipc("create client on", &names.full("control"), e))?;
        Ok(Self {
            names: names.clone(),
            status,
            stances,
            control,
            status_service,
            stances_service,
            _control_service: control_service,
            _node: node,
        })
    }

    /// Whether a live daemon serves these services (a status publisher and a stances server
    /// exist). A `kill -9`ed daemon's ports are cleaned by `connect`, so they don't count.
    pub fn daemon_present(&self) -> bool {
        self.status_service.dynamic_config().number_of_publishers() > 0
            && self.stances_service.dynamic_config().number_of_servers() > 0
    }

    /// The newest status received since the last call, if any.
    pub fn latest_status(&self) -> Result<Option<DaemonStatus>, ShmError> {
        let mut latest = None;
        while let Some(sample) = self
            .status
            .receive()
            .map_err(|e| ShmError::ipc("receive from", &self.names.full("status"), e))?
        {
            latest = Some(*sample.payload());
        }
        Ok(latest)
    }

    /// Waits up to `timeout` for a status newer than the last one received.
    pub fn next_status(&self, timeout: Duration) -> Result<DaemonStatus, ShmError> {
        let service = self.names.full("status");
        poll_until(&service, timeout, || self.latest_status())
    }

    /// Submits a post-processed sequence (its JSON) and waits up to `timeout` for the verdict.
    pub fn submit(&self, json: &[u8], timeout: Duration) -> Result<SubmitReply, ShmError> {
        let service = self.names.full("stances");
        if json.len() > MAX_SEQUENCE_BYTES {
            return Err(ShmError::ipc(
                "submit to",
                &service,
                format!(
                    "sequence of {} bytes exceeds {MAX_SEQUENCE_BYTES}",
                    json.len()
                ),
            ));
        }
        let request = self
            .stances
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
            .control
            .send_copy(ControlRequest { command })
            .map_err(|e| ShmError::ipc("send to", &service, e))?;
        wait_for_reply(&service, timeout, &pending)
    }
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
