//! The two ends of a high-rate stream (`sensors`, `commands`): a publisher that wakes its
//! listeners after every message, and a subscriber that waits for that wake-up and keeps only
//! the newest message. Shared by the daemon and the adapter, which use it in opposite directions.

use core::time::Duration;

use iceoryx2::port::listener::Listener;
use iceoryx2::port::listener::ListenerWaitError;
use iceoryx2::port::notifier::Notifier;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::prelude::*;

use crate::services::{self, Event, IpcNode, PubSub, StreamPayload};
use crate::{ServiceNames, ShmError};

/// Sending end: publish + notify.
pub(crate) struct StreamSender<T: StreamPayload> {
    service_name: String,
    publisher: Publisher<ipc::Service, T, ()>,
    notifier: Notifier<ipc::Service>,
    _service: PubSub<T>,
    _event: Event,
}

impl<T: StreamPayload> StreamSender<T> {
    /// Opens (or creates) the stream of `T` under `names` and its event, as their sender.
    pub(crate) fn open(node: &IpcNode, names: &ServiceNames) -> Result<Self, ShmError> {
        let service_name = names.full(T::KIND);
        let service = services::stream::<T>(node, names)?;
        let event = services::stream_event::<T>(node, names)?;
        let publisher = service
            .publisher_builder()
            .max_loaned_samples(2)
            .create()
            .map_err(|e| ShmError::ipc("create publisher on", &service_name, e))?;
        let notifier = event
            .notifier_builder()
            .create()
            .map_err(|e| ShmError::ipc("create notifier on", &service_name, e))?;
        Ok(Self {
            service_name,
            publisher,
            notifier,
            _service: service,
            _event: event,
        })
    }

    /// Fills a message in shared memory in place, sends it and wakes the listeners.
    /// No heap allocation.
    pub(crate) fn send(&self, fill: impl FnOnce(&mut T)) -> Result<(), ShmError> {
        super::send_in_place(&self.publisher, &self.service_name, fill)?;
        self.notifier
            .notify()
            .map_err(|e| ShmError::ipc("notify on", &self.service_name, e))?;
        Ok(())
    }
}

/// Receiving end: wait for the wake-up, take the newest message.
pub(crate) struct StreamReceiver<T: StreamPayload> {
    service_name: String,
    subscriber: Subscriber<ipc::Service, T, ()>,
    listener: Listener<ipc::Service>,
    service: PubSub<T>,
    _event: Event,
}

impl<T: StreamPayload> StreamReceiver<T> {
    /// Opens (or creates) the stream of `T` under `names` and its event, as their receiver.
    pub(crate) fn open(node: &IpcNode, names: &ServiceNames) -> Result<Self, ShmError> {
        let service_name = names.full(T::KIND);
        let service = services::stream::<T>(node, names)?;
        let event = services::stream_event::<T>(node, names)?;
        let subscriber = service
            .subscriber_builder()
            .buffer_size(services::STREAM_PEER_BUFFER)
            .create()
            .map_err(|e| ShmError::ipc("create subscriber on", &service_name, e))?;
        let listener = event
            .listener_builder()
            .create()
            .map_err(|e| ShmError::ipc("create listener on", &service_name, e))?;
        Ok(Self {
            service_name,
            subscriber,
            listener,
            service,
            _event: event,
        })
    }

    /// How many publishers the stream has now.
    pub(crate) fn publishers(&self) -> usize {
        self.service.dynamic_config().number_of_publishers()
    }

    /// Blocks until a message is announced or `timeout` passes; returns whether one was
    /// announced. A signal interrupting the wait counts as a timeout.
    pub(crate) fn wait(&self, timeout: Duration) -> Result<bool, ShmError> {
        match self.listener.timed_wait(|_| {}, timeout) {
            Ok(count) => Ok(count > 0),
            Err(ListenerWaitError::InterruptSignal) => Ok(false),
            Err(e) => Err(ShmError::ipc("wait for", &self.service_name, e)),
        }
    }

    /// Copies the newest received message into `out`, dropping older ones; returns false when
    /// nothing new arrived. No heap allocation.
    pub(crate) fn take_latest(&self, out: &mut T) -> Result<bool, ShmError> {
        let mut fresh = false;
        while let Some(sample) = self
            .subscriber
            .receive()
            .map_err(|e| ShmError::ipc("receive from", &self.service_name, e))?
        {
            *out = *sample.payload();
            fresh = true;
        }
        Ok(fresh)
    }
}
