//! Typed port wrappers, one per role. Each owns its own iceoryx2 node, so a process can give
//! each of its threads the ports it needs (iceoryx2 `ipc` ports are not shared between threads).

mod adapter;
mod client;
mod daemon;
mod observer;
mod stream;
mod telemetry;
mod truth;

pub use adapter::AdapterPorts;
pub use client::ClientPorts;
pub use daemon::{DaemonLoopPorts, DaemonServicePorts};
pub use observer::{Observed, ObserverPorts};
pub use truth::{TruthPublisher, TruthSubscriber};

use iceoryx2::port::publisher::Publisher;
use iceoryx2::prelude::*;

use crate::ShmError;

/// Loans a message in shared memory, lets `fill` write it in place and sends it: the publishing
/// step of every high-rate sender (no heap allocation, no copy of the payload).
fn send_in_place<T>(
    publisher: &Publisher<ipc::Service, T, ()>,
    service_name: &str,
    fill: impl FnOnce(&mut T),
) -> Result<(), ShmError>
where
    T: core::fmt::Debug + ZeroCopySend + Default + 'static,
{
    let mut sample = publisher
        .loan()
        .map_err(|e| ShmError::ipc("loan a sample on", service_name, e))?;
    fill(sample.payload_mut());
    sample
        .send()
        .map(|_| ())
        .map_err(|e| ShmError::ipc("send on", service_name, e))
}
