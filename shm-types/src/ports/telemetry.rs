//! The sending end of `telemetry`, held by walkd's control thread ([`super::DaemonLoopPorts`]).

use iceoryx2::port::publisher::Publisher;
use iceoryx2::prelude::*;

use crate::services::{self, IpcNode, PubSub, TELEMETRY};
use crate::{ServiceNames, ShmError, Telemetry};

/// Publishes one [`Telemetry`] per control tick; no event wakes the subscribers (observers poll),
/// so publishing is a shared-memory write without a system call. Allocation-free after `open`.
pub(crate) struct TelemetrySender {
    service_name: String,
    publisher: Publisher<ipc::Service, Telemetry, ()>,
    _service: PubSub<Telemetry>,
}

impl TelemetrySender {
    /// Opens (or creates) `telemetry` under `names`, as its publisher.
    pub(crate) fn open(node: &IpcNode, names: &ServiceNames) -> Result<Self, ShmError> {
        let service_name = names.full(TELEMETRY);
        let service = services::telemetry(node, names)?;
        let publisher = service
            .publisher_builder()
            .max_loaned_samples(1)
            .create()
            .map_err(|e| ShmError::ipc("create publisher on", &service_name, e))?;
        Ok(Self {
            service_name,
            publisher,
            _service: service,
        })
    }

    /// Fills a message in shared memory in place and sends it. No heap allocation.
    pub(crate) fn send(&self, fill: impl FnOnce(&mut Telemetry)) -> Result<(), ShmError> {
        super::send_in_place(&self.publisher, &self.service_name, fill)
    }
}
