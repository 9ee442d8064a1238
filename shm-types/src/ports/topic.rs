//! The two plain ends of a publish-subscribe service ([`Topic`]): a publisher and a subscriber,
//! each with the service's full name for its errors. The role ports build on them.
//!
//! A port keeps its service alive (iceoryx2 ports share the service's state), so neither holds the
//! port factory it was created from.

use iceoryx2::port::publisher::{Publisher, PublisherCreateError};
use iceoryx2::port::subscriber::{Subscriber, SubscriberCreateError};
use iceoryx2::prelude::*;

use super::trust::PublisherId;
use crate::services::{self, Access, IpcNode, PubSub, Topic};
use crate::{ServiceNames, ShmError};

/// A publisher on the service of `T`.
pub(crate) struct TopicSender<T: Topic> {
    name: String,
    publisher: Publisher<ipc::Service, T, ()>,
}

impl<T: Topic> TopicSender<T> {
    /// Opens (or creates) the service of `T` under `names` and publishes on it, loaning at most
    /// `loans` messages at once.
    pub(crate) fn open(
        node: &IpcNode,
        names: &ServiceNames,
        loans: usize,
    ) -> Result<Self, ShmError> {
        let name = names.full(T::KIND);
        let service = services::publish_subscribe::<T>(node, names, Access::OpenOrCreate)?;
        let publisher = service
            .publisher_builder()
            .max_loaned_samples(loans)
            .create()
            .map_err(|e| match e {
                PublisherCreateError::ExceedsMaxSupportedPublishers => ShmError::ServiceFull {
                    service: name.clone(),
                    port: "publisher",
                    limit: service.static_config().max_publishers(),
                },
                other => ShmError::ipc("create publisher on", &name, other),
            })?;
        Ok(Self { name, publisher })
    }

    /// The service's full name.
    pub(crate) fn name(&self) -> &str {
        &self.name
    }

    /// Loans a message in shared memory, lets `fill` write it in place and sends it: the
    /// publishing step of every high-rate sender (no heap allocation, no copy of the payload).
    pub(crate) fn send(&self, fill: impl FnOnce(&mut T)) -> Result<(), ShmError> {
        let mut sample = self
            .publisher
            .loan()
            .map_err(|e| ShmError::ipc("loan a sample on", &self.name, e))?;
        fill(sample.payload_mut());
        sample
            .send()
            .map(|_| ())
            .map_err(|e| ShmError::ipc("send on", &self.name, e))
    }

    /// Sends a copy of `message`.
    pub(crate) fn send_copy(&self, message: &T) -> Result<(), ShmError> {
        self.publisher
            .send_copy(*message)
            .map(|_| ())
            .map_err(|e| ShmError::ipc("send on", &self.name, e))
    }
}

/// A subscriber of the service of `T`.
pub(crate) struct TopicReceiver<T: Topic> {
    name: String,
    subscriber: Subscriber<ipc::Service, T, ()>,
}

impl<T: Topic> TopicReceiver<T> {
    /// Opens (or creates) the service of `T` under `names` and subscribes to it (see
    /// [`subscribe`](Self::subscribe)).
    pub(crate) fn open(
        node: &IpcNode,
        names: &ServiceNames,
        buffer: usize,
    ) -> Result<Self, ShmError> {
        let service = services::publish_subscribe::<T>(node, names, Access::OpenOrCreate)?;
        Self::subscribe(names, &service, buffer)
    }

    /// Subscribes to `service`, the service of `T` under `names`, holding at most `buffer`
    /// unread messages; a service without a free subscriber slot is [`ShmError::ServiceFull`].
    pub(crate) fn subscribe(
        names: &ServiceNames,
        service: &PubSub<T>,
        buffer: usize,
    ) -> Result<Self, ShmError> {
        let name = names.full(T::KIND);
        let subscriber = service
            .subscriber_builder()
            .buffer_size(buffer)
            .create()
            .map_err(|e| match e {
                SubscriberCreateError::ExceedsMaxSupportedSubscribers => ShmError::ServiceFull {
                    service: name.clone(),
                    port: "subscriber",
                    limit: service.static_config().max_subscribers(),
                },
                other => ShmError::ipc("create subscriber on", &name, other),
            })?;
        Ok(Self { name, subscriber })
    }

    /// The service's full name.
    pub(crate) fn name(&self) -> &str {
        &self.name
    }

    /// Passes every message received since the last call to `each`, oldest first; returns how
    /// many. No heap allocation.
    pub(crate) fn drain(&self, mut each: impl FnMut(&T)) -> Result<usize, ShmError> {
        self.drain_from(|_, message| each(message))
    }

    /// Passes every message received since the last call to `each` with its publisher (the
    /// connection it came through, not what the publisher wrote), oldest first per publisher;
    /// returns how many. No heap allocation.
    pub(crate) fn drain_from(
        &self,
        mut each: impl FnMut(PublisherId, &T),
    ) -> Result<usize, ShmError> {
        let mut count = 0;
        while let Some(sample) = self
            .subscriber
            .receive()
            .map_err(|e| ShmError::ipc("receive from", &self.name, e))?
        {
            each(sample.origin().into(), sample.payload());
            count += 1;
        }
        Ok(count)
    }
}
