//! The two ends of a high-rate stream (`sensors`, `commands`): a publisher that wakes its
//! listeners after every message, and a subscriber that waits for that wake-up and keeps only
//! the newest message of the one publisher it trusts. Shared by the daemon and the adapter,
//! which use it in opposite directions.

use core::time::Duration;

use iceoryx2::port::listener::Listener;
use iceoryx2::port::listener::ListenerWaitError;
use iceoryx2::port::notifier::Notifier;
use iceoryx2::prelude::*;

use super::topic::TopicSender;
use super::trust::{Taken, TrustedReceiver};
use crate::services::{self, IpcNode, StreamPayload};
use crate::{ServiceNames, ShmError};

/// Sending end: publish + notify.
pub(crate) struct StreamSender<T: StreamPayload> {
    sender: TopicSender<T>,
    notifier: Notifier<ipc::Service>,
}

impl<T: StreamPayload> StreamSender<T> {
    /// Opens (or creates) the stream of `T` under `names` and its event, as their sender.
    pub(crate) fn open(node: &IpcNode, names: &ServiceNames) -> Result<Self, ShmError> {
        let sender = TopicSender::open(node, names, 2)?;
        let notifier = services::stream_event::<T>(node, names)?
            .notifier_builder()
            .create()
            .map_err(|e| ShmError::ipc("create notifier on", sender.name(), e))?;
        Ok(Self { sender, notifier })
    }

    /// Fills a message in shared memory in place, sends it and wakes the listeners.
    /// No heap allocation.
    pub(crate) fn send(&self, fill: impl FnOnce(&mut T)) -> Result<(), ShmError> {
        self.sender.send(fill)?;
        self.notifier
            .notify()
            .map_err(|e| ShmError::ipc("notify on", self.sender.name(), e))?;
        Ok(())
    }
}

/// Receiving end: wait for the wake-up, take the newest message of the pinned publisher
/// ([`TrustedReceiver`]).
pub(crate) struct StreamReceiver<T: StreamPayload> {
    receiver: TrustedReceiver<T>,
    listener: Listener<ipc::Service>,
}

impl<T: StreamPayload> StreamReceiver<T> {
    /// Opens (or creates) the stream of `T` under `names` and its event, as their receiver;
    /// `reviews_itself` as in [`TrustedReceiver`].
    pub(crate) fn open(
        node: &IpcNode,
        names: &ServiceNames,
        reviews_itself: bool,
    ) -> Result<Self, ShmError> {
        let receiver =
            TrustedReceiver::open(node, names, services::STREAM_PEER_BUFFER, reviews_itself)?;
        let listener = services::stream_event::<T>(node, names)?
            .listener_builder()
            .create()
            .map_err(|e| ShmError::ipc("create listener on", receiver.name(), e))?;
        Ok(Self { receiver, listener })
    }

    /// The receiving end: its pin, roster and publishers.
    pub(crate) fn trusted(&self) -> &TrustedReceiver<T> {
        &self.receiver
    }

    /// Blocks until a message is announced or `timeout` passes; returns whether one was
    /// announced. A signal interrupting the wait counts as a timeout.
    pub(crate) fn wait(&self, timeout: Duration) -> Result<bool, ShmError> {
        match self.listener.timed_wait(|_| {}, timeout) {
            Ok(count) => Ok(count > 0),
            Err(ListenerWaitError::InterruptSignal) => Ok(false),
            Err(e) => Err(ShmError::ipc("wait for", self.receiver.name(), e)),
        }
    }

    /// Copies the newest message of the pinned publisher into `out`, dropping older ones and
    /// refusing other publishers' messages. No heap allocation without reviews of its own.
    pub(crate) fn take_latest(&self, out: &mut T) -> Result<Taken, ShmError> {
        self.receiver.take_latest(out)
    }
}
