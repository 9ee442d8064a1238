//! Who sent a message, and which publisher a receiver trusts.
//!
//! iceoryx2 gives every publisher port an id unique on the machine. A subscriber learns which
//! publisher a message came from by the connection it came through ([`Sample::origin`]), not
//! from the payload or from the header the publisher wrote, so a process that uses iceoryx2's
//! API cannot send in another publisher's name. A receiver pins the first publisher it hears
//! ([`Pin`]) and refuses the messages of every other one. The pin is let go only once the pinned
//! publisher is gone: it left the service, or its process died and its resources were removed
//! ([`review`]); then the next publisher heard is pinned.
//!
//! [`Sample::origin`]: iceoryx2::sample::Sample::origin

use core::cell::{Cell, RefCell};
use core::fmt;

use iceoryx2::identifiers::{UniqueNodeId, UniquePublisherId};
use iceoryx2::prelude::*;

use super::topic::TopicReceiver;
use crate::services::{self, Access, IpcNode, PubSub, Topic};
use crate::{ServiceNames, ShmError};

/// The iceoryx2 id of a publisher port: unique on the machine, never reused.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct PublisherId(u128);

impl PublisherId {
    /// The id with `value` (as [`value`](Self::value) gave it, e.g. read back from where it was
    /// kept).
    pub const fn from_value(value: u128) -> Self {
        Self(value)
    }

    /// The id iceoryx2 gave the publisher (`UniquePublisherId::value`).
    pub const fn value(self) -> u128 {
        self.0
    }
}

impl fmt::Display for PublisherId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{:x}", self.0)
    }
}

impl From<UniquePublisherId> for PublisherId {
    fn from(id: UniquePublisherId) -> Self {
        Self(id.value())
    }
}

/// A publisher as far as it is known: its id always (from the connection a message came
/// through); its node and process once iceoryx2 listed it on the service.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Peer {
    /// The publisher port.
    pub publisher: PublisherId,
    node: Option<UniqueNodeId>,
    /// The process that created the publisher's node.
    pub pid: Option<i32>,
}

impl Peer {
    /// A publisher known only by its id.
    pub fn unlisted(publisher: PublisherId) -> Self {
        Self {
            publisher,
            node: None,
            pid: None,
        }
    }

    /// The id of the publisher's node (0: not listed).
    pub fn node(&self) -> u128 {
        self.node.map_or(0, |node| node.value())
    }
}

/// `publisher 1f… of pid 4242`, or `publisher 1f…` when its process is not known.
impl fmt::Display for Peer {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "publisher {}", self.publisher)?;
        if let Some(pid) = self.pid {
            write!(f, " of pid {pid}")?;
        }
        Ok(())
    }
}

/// What a receiver does with a message, by its publisher.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Admission {
    /// From the pinned publisher: use it.
    Trusted,
    /// The first message heard since nothing was pinned: its publisher is pinned now; use it.
    Pinned,
    /// From another publisher: refuse it.
    Refused,
}

/// The publisher a receiver trusts, and what it refused from others. Plain data, no allocation:
/// the real-time control loop keeps one.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Pin {
    pinned: Option<PublisherId>,
    refused: u64,
    last_refused: Option<PublisherId>,
}

impl Pin {
    /// Nothing pinned, nothing refused.
    pub const fn new() -> Self {
        Self {
            pinned: None,
            refused: 0,
            last_refused: None,
        }
    }

    /// Judges a message from `origin`, pinning it if nothing is pinned.
    pub fn admit(&mut self, origin: PublisherId) -> Admission {
        match self.pinned {
            None => {
                self.pinned = Some(origin);
                Admission::Pinned
            }
            Some(pinned) if pinned == origin => Admission::Trusted,
            Some(_) => {
                self.refused = self.refused.saturating_add(1);
                self.last_refused = Some(origin);
                Admission::Refused
            }
        }
    }

    /// The publisher trusted now.
    pub fn pinned(&self) -> Option<PublisherId> {
        self.pinned
    }

    /// The pinned publisher is gone: the next one heard is pinned.
    pub fn release(&mut self) {
        self.pinned = None;
    }

    /// Messages refused so far (saturating).
    pub fn refused(&self) -> u64 {
        self.refused
    }

    /// The publisher of the last message refused.
    pub fn last_refused(&self) -> Option<PublisherId> {
        self.last_refused
    }
}

/// The messages a receiver refused because another publisher than the pinned one sent them.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Refusals {
    /// Messages refused so far (saturating).
    pub count: u64,
    /// The publisher of the last one.
    pub last: Option<Peer>,
}

/// The publishers of a service now, seen from a receiver that pinned one of them.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Roster {
    /// The pinned publisher, while it is on the service.
    pub pinned: Option<Peer>,
    /// A publisher was pinned and is gone: it left the service, or its process died (its
    /// resources were then removed).
    pub pinned_gone: bool,
    /// Every other publisher on the service.
    pub others: Vec<Peer>,
}

impl Roster {
    /// The listed publisher with id `publisher`, or it unlisted.
    pub fn peer(&self, publisher: PublisherId) -> Peer {
        self.pinned
            .iter()
            .chain(&self.others)
            .find(|peer| peer.publisher == publisher)
            .copied()
            .unwrap_or(Peer::unlisted(publisher))
    }
}

/// Lists the publishers of `service` and tells whether `pinned` is still among them. With
/// `clean_dead`, the resources of dead processes' nodes are removed first, so a killed
/// publisher no longer counts (iceoryx2's dead-node detection). Allocates: not for a real-time
/// loop.
pub(crate) fn review<T: Topic>(
    service: &PubSub<T>,
    pinned: Option<PublisherId>,
    clean_dead: bool,
) -> Roster {
    if clean_dead {
        services::remove_dead_nodes();
    }
    let mut roster = Roster::default();
    service.dynamic_config().list_publishers(|details| {
        let peer = Peer {
            publisher: details.publisher_id.into(),
            node: Some(details.node_id),
            pid: details
                .node_id
                .pid::<ipc::Service>()
                .ok()
                .map(|pid| pid.value()),
        };
        if Some(peer.publisher) == pinned {
            roster.pinned = Some(peer);
        } else {
            roster.others.push(peer);
        }
        CallbackProgression::Continue
    });
    roster.pinned_gone = pinned.is_some() && roster.pinned.is_none();
    roster
}

/// How often a receiver that reviews its own publishers does so while others send to it.
const REVIEW_EVERY_NS: u64 = 50_000_000;

/// A subscriber that pins the first publisher it hears and refuses the messages of the others.
/// Without a review policy its draining allocates nothing (walkd's control thread; another thread
/// reviews the service for it); with one it reviews the service itself when a refused message
/// arrives, at most every 50 ms, so it lets go of a publisher that is gone and takes the next.
pub(crate) struct TrustedReceiver<T: Topic> {
    receiver: TopicReceiver<T>,
    service: PubSub<T>,
    pin: Cell<Pin>,
    reviews: Option<Reviews>,
}

/// A receiver's own reviews: when the next one is due, and the last roster.
struct Reviews {
    next_ns: Cell<u64>,
    roster: RefCell<Roster>,
}

impl<T: Topic> TrustedReceiver<T> {
    /// Subscribes to `service`, the service of `T` under `names` (see
    /// [`TopicReceiver::subscribe`]); `reviews_itself` as in the type's docs.
    pub(crate) fn subscribe(
        names: &ServiceNames,
        service: PubSub<T>,
        buffer: usize,
        reviews_itself: bool,
    ) -> Result<Self, ShmError> {
        Ok(Self {
            receiver: TopicReceiver::subscribe(names, &service, buffer)?,
            service,
            pin: Cell::new(Pin::new()),
            reviews: reviews_itself.then(|| Reviews {
                next_ns: Cell::new(0),
                roster: RefCell::new(Roster::default()),
            }),
        })
    }

    /// Opens (or creates) the service of `T` under `names` and subscribes to it.
    pub(crate) fn open(
        node: &IpcNode,
        names: &ServiceNames,
        buffer: usize,
        reviews_itself: bool,
    ) -> Result<Self, ShmError> {
        let service = services::publish_subscribe::<T>(node, names, Access::OpenOrCreate)?;
        Self::subscribe(names, service, buffer, reviews_itself)
    }

    /// The service's full name.
    pub(crate) fn name(&self) -> &str {
        self.receiver.name()
    }

    /// The pin: which publisher is trusted, what was refused.
    pub(crate) fn pin(&self) -> Pin {
        self.pin.get()
    }

    /// Lets go of the pinned publisher if it is still `publisher` (it is gone).
    pub(crate) fn release(&self, publisher: PublisherId) {
        let mut pin = self.pin.get();
        if pin.pinned() == Some(publisher) {
            pin.release();
            self.pin.set(pin);
        }
    }

    /// What this receiver refused; the last sender as far as its reviews know it.
    pub(crate) fn refusals(&self) -> Refusals {
        let pin = self.pin.get();
        Refusals {
            count: pin.refused(),
            last: pin.last_refused().map(|last| match &self.reviews {
                Some(reviews) => reviews.roster.borrow().peer(last),
                None => Peer::unlisted(last),
            }),
        }
    }

    /// Passes every message from the pinned publisher received since the last call to `each`,
    /// oldest first, and refuses the others; returns what was taken.
    pub(crate) fn drain(&self, mut each: impl FnMut(&T)) -> Result<Taken, ShmError> {
        let mut taken = Taken::Nothing;
        self.receiver.drain_from(|origin, message| {
            let mut pin = self.pin.get();
            let mut admission = pin.admit(origin);
            if admission == Admission::Refused && self.review_if_due(&mut pin) {
                admission = pin.admit(origin);
            }
            self.pin.set(pin);
            match admission {
                Admission::Trusted => taken = taken.max(Taken::Trusted),
                Admission::Pinned => taken = Taken::FromNewPublisher,
                Admission::Refused => return,
            }
            each(message);
        })?;
        Ok(taken)
    }

    /// Copies the newest message from the pinned publisher into `out`, dropping older ones.
    pub(crate) fn take_latest(&self, out: &mut T) -> Result<Taken, ShmError> {
        self.drain(|message| *out = *message)
    }

    /// With reviews of its own and one due: reviews the service; returns whether the pinned
    /// publisher was gone and `pin` let go of it.
    fn review_if_due(&self, pin: &mut Pin) -> bool {
        let Some(reviews) = &self.reviews else {
            return false;
        };
        let now = crate::monotonic_ns();
        if now < reviews.next_ns.get() {
            return false;
        }
        reviews.next_ns.set(now + REVIEW_EVERY_NS);
        let roster = review(&self.service, pin.pinned(), true);
        let gone = roster.pinned_gone;
        *reviews.roster.borrow_mut() = roster;
        if gone {
            pin.release();
        }
        gone
    }
}

/// What one call of a trusted receiver took.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Taken {
    /// No message from the pinned publisher.
    Nothing,
    /// Messages from the publisher pinned before.
    Trusted,
    /// Messages from a publisher pinned in this call (a new one: the first, or the one after a
    /// pinned publisher that is gone).
    FromNewPublisher,
}

impl Taken {
    /// Whether a message was taken.
    pub fn any(self) -> bool {
        self != Self::Nothing
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ports::topic::TopicSender;
    use crate::{DaemonStatus, ServiceNames};

    fn status(seq: u64) -> DaemonStatus {
        DaemonStatus {
            ticks: seq,
            ..DaemonStatus::INITIAL
        }
    }

    fn received(receiver: &TrustedReceiver<DaemonStatus>) -> (Vec<u64>, Taken) {
        let mut ticks = Vec::new();
        let taken = receiver.drain(|s| ticks.push(s.ticks)).unwrap();
        (ticks, taken)
    }

    #[test]
    fn the_first_publisher_is_pinned_and_others_are_refused_until_it_is_gone() {
        let prefix = format!("walk-test/shm-types/trust/{}", std::process::id());
        let names = ServiceNames::new(&prefix).unwrap();
        let (node, _) = services::create_node("receiver").unwrap();
        let receiver = TrustedReceiver::<DaemonStatus>::open(&node, &names, 2, true).unwrap();
        let (first_node, _) = services::create_node("first").unwrap();
        let first = TopicSender::<DaemonStatus>::open(&first_node, &names, 1).unwrap();
        let (second_node, _) = services::create_node("second").unwrap();
        let second = TopicSender::<DaemonStatus>::open(&second_node, &names, 1).unwrap();

        first.send_copy(&status(1)).unwrap();
        assert_eq!(received(&receiver), (vec![1], Taken::FromNewPublisher));
        let pinned = receiver.pin().pinned().unwrap();
        second.send_copy(&status(100)).unwrap();
        first.send_copy(&status(2)).unwrap();
        assert_eq!(received(&receiver), (vec![2], Taken::Trusted));
        let refusals = receiver.refusals();
        assert_eq!(refusals.count, 1);
        let intruder = refusals.last.unwrap();
        assert_ne!(intruder.publisher, pinned);
        assert_eq!(intruder.pid, Some(std::process::id() as i32), "{intruder}");
        assert!(intruder.to_string().contains("of pid"), "{intruder}");

        // The pinned publisher leaves: the next message of the other one is taken, from a new
        // publisher.
        drop(first);
        std::thread::sleep(core::time::Duration::from_millis(60));
        second.send_copy(&status(101)).unwrap();
        assert_eq!(received(&receiver), (vec![101], Taken::FromNewPublisher));
        assert_eq!(receiver.pin().pinned(), Some(intruder.publisher));
    }

    #[test]
    fn a_pin_counts_what_it_refuses() {
        let (a, b) = (PublisherId(1), PublisherId(2));
        let mut pin = Pin::new();
        assert_eq!(pin.admit(a), Admission::Pinned);
        assert_eq!(pin.admit(a), Admission::Trusted);
        assert_eq!(pin.admit(b), Admission::Refused);
        assert_eq!((pin.refused(), pin.last_refused()), (1, Some(b)));
        pin.release();
        assert_eq!(pin.admit(b), Admission::Pinned);
        assert_eq!(pin.pinned(), Some(b));
    }
}
