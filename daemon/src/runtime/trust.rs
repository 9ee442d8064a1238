//! Which adapter walkd trusts, seen from both threads.
//!
//! The control thread's ports take samples from one publisher on `sensors` only: the adapter
//! pinned on the first sample (iceoryx2 identity, [`shm_types::Pin`]); every other publisher's
//! samples are refused there. Finding out whether the pinned adapter is gone and who else
//! publishes means listing the service's publishers, which allocates, so the service thread does
//! it ([`AdapterWatch`]) and the two meet in [`AdapterTrust`], atomics only: the control thread
//! shows the pinned publisher; the service thread says when it is gone (it left `sensors`, or
//! its process died and iceoryx2's dead-node cleanup removed it), so the control thread lets go
//! and pins the next publisher heard, and how many other publishers there are, so the control
//! thread stops a walk and refuses new ones while there are any.

use std::sync::atomic::{AtomicU32, AtomicU64, Ordering, fence};
use std::time::{Duration, Instant};

use shm_types::{DaemonLoopPorts, DaemonServicePorts, Peer, PublisherId};

/// How often the service thread removes dead processes' nodes while the adapter link is stale or
/// another publisher is on `sensors` (listing the nodes reads a directory).
const CLEANUP_EVERY: Duration = Duration::from_secs(1);

/// How long samples of another publisher count as an intruder publishing after the last one
/// was refused (ns): an intruder that leaves before the service thread listed it is still seen.
const FOREIGN_MEMORY_NS: u64 = 100_000_000;

/// The pinned adapter and the service thread's word on it, shared by both threads.
pub struct AdapterTrust {
    /// The pinned publisher's id, high and low half (both 0: none), written by the control
    /// thread between two increments of `version` (a sequence lock: odd while it writes).
    high: AtomicU64,
    low: AtomicU64,
    version: AtomicU64,
    /// Service → control thread: the `version` whose pinned publisher is gone.
    gone: AtomicU64,
    /// Service → control thread: publishers on `sensors` other than the pinned one.
    intruders: AtomicU32,
}

impl AdapterTrust {
    /// Nothing pinned, nobody else publishing.
    pub fn new() -> Self {
        Self {
            high: AtomicU64::new(0),
            low: AtomicU64::new(0),
            version: AtomicU64::new(0),
            gone: AtomicU64::new(u64::MAX),
            intruders: AtomicU32::new(0),
        }
    }

    /// Control thread (the only writer): shows which publisher is pinned now.
    pub fn show(&self, pinned: Option<PublisherId>) {
        let value = pinned.map_or(0, PublisherId::value);
        let version = self.version.load(Ordering::Relaxed);
        self.version.store(version + 1, Ordering::Relaxed);
        fence(Ordering::Release);
        self.high.store((value >> 64) as u64, Ordering::Relaxed);
        self.low.store(value as u64, Ordering::Relaxed);
        self.version.store(version + 2, Ordering::Release);
    }

    /// Service thread: the pinned publisher and the version it was shown in.
    pub fn pinned(&self) -> (u64, Option<PublisherId>) {
        loop {
            let version = self.version.load(Ordering::Acquire);
            if version % 2 == 1 {
                std::hint::spin_loop();
                continue;
            }
            let high = self.high.load(Ordering::Relaxed);
            let low = self.low.load(Ordering::Relaxed);
            fence(Ordering::Acquire);
            if self.version.load(Ordering::Relaxed) == version {
                let value = u128::from(high) << 64 | u128::from(low);
                return (
                    version,
                    (value != 0).then(|| PublisherId::from_value(value)),
                );
            }
        }
    }

    /// Service thread: the publisher shown in `version` is gone.
    pub fn report_gone(&self, version: u64) {
        self.gone.store(version, Ordering::Release);
    }

    /// Control thread: whether the publisher it showed last is gone.
    pub fn pinned_is_gone(&self) -> bool {
        self.gone.load(Ordering::Acquire) == self.version.load(Ordering::Relaxed)
    }

    /// Service thread: how many other publishers are on `sensors`.
    pub fn set_intruders(&self, count: usize) {
        self.intruders
            .store(count.min(u32::MAX as usize) as u32, Ordering::Release);
    }

    /// Control thread: how many other publishers are on `sensors`.
    pub fn intruders(&self) -> u32 {
        self.intruders.load(Ordering::Acquire)
    }
}

impl Default for AdapterTrust {
    fn default() -> Self {
        Self::new()
    }
}

/// The control thread's side: follows the service thread's word and the samples its ports
/// refused. No allocation.
pub struct AdapterFollower {
    shown: Option<PublisherId>,
    refused_seen: u64,
    last_foreign_ns: Option<u64>,
}

impl AdapterFollower {
    /// Nothing pinned or refused yet.
    pub fn new() -> Self {
        Self {
            shown: None,
            refused_seen: 0,
            last_foreign_ns: None,
        }
    }

    /// Lets the ports go of a pinned adapter the service thread found gone, and shows it the
    /// adapter pinned now. Returns whether another publisher is on `sensors`: listed there by the
    /// service thread, or its samples refused within the last [`FOREIGN_MEMORY_NS`].
    pub fn check(&mut self, ports: &DaemonLoopPorts, trust: &AdapterTrust, now_ns: u64) -> bool {
        let pin = ports.sensor_pin();
        let released = match pin.pinned() {
            Some(pinned) if self.shown == Some(pinned) && trust.pinned_is_gone() => {
                ports.release_sensor_pin(pinned);
                true
            }
            _ => false,
        };
        let pinned = ports.sensor_pin().pinned();
        if pinned != self.shown {
            trust.show(pinned);
            self.shown = pinned;
        }
        // Samples refused just before the pinned adapter was found gone were the next
        // adapter's (a restart), not an intruder's.
        if pin.refused() > self.refused_seen && !released {
            self.last_foreign_ns = Some(now_ns);
        }
        self.refused_seen = pin.refused();
        trust.intruders() > 0
            || self
                .last_foreign_ns
                .is_some_and(|at| now_ns.saturating_sub(at) < FOREIGN_MEMORY_NS)
    }
}

impl Default for AdapterFollower {
    fn default() -> Self {
        Self::new()
    }
}

/// The service thread's review of `sensors`: who is pinned, who else publishes.
pub struct AdapterWatch {
    pinned: Option<Peer>,
    intruders: Vec<Peer>,
    next_cleanup: Instant,
    /// The version of the pin last reported gone (until the control thread lets go of it).
    reported_gone: Option<u64>,
}

impl AdapterWatch {
    /// Nothing seen yet.
    pub fn new() -> Self {
        Self {
            pinned: None,
            intruders: Vec::new(),
            next_cleanup: Instant::now(),
            reported_gone: None,
        }
    }

    /// Lists the publishers on `sensors` and tells the control thread (through `trust`) whether
    /// its pinned adapter is gone and how many others publish; logs each intruder when it comes
    /// and goes. With `link_stale` or others publishing, removes dead processes' nodes first (at
    /// most every [`CLEANUP_EVERY`]), so a killed adapter or intruder stops counting.
    pub fn review(&mut self, ports: &DaemonServicePorts, trust: &AdapterTrust, link_stale: bool) {
        let clean_dead =
            (link_stale || !self.intruders.is_empty()) && Instant::now() >= self.next_cleanup;
        if clean_dead {
            self.next_cleanup = Instant::now() + CLEANUP_EVERY;
        }
        let (version, pinned) = trust.pinned();
        let roster = ports.review_sensors(pinned, clean_dead);
        if roster.pinned_gone && self.reported_gone != Some(version) {
            tracing::info!(
                publisher = %pinned.map_or(String::new(), |p| p.to_string()),
                "the adapter walkd followed is gone: the next publisher on sensors is trusted"
            );
            trust.report_gone(version);
            self.reported_gone = Some(version);
        }
        // With nothing pinned (or the pinned adapter gone) the next sample decides which is the
        // adapter; until then only more than one publisher means another process publishes.
        let following = roster.pinned.is_some();
        let intruders = if following || roster.others.len() > 1 {
            roster.others
        } else {
            Vec::new()
        };
        trust.set_intruders(if following {
            intruders.len()
        } else {
            intruders.len().saturating_sub(1)
        });
        for peer in &intruders {
            if !self.intruders.iter().any(|p| p.publisher == peer.publisher) {
                tracing::warn!(
                    publisher = %peer.publisher,
                    node = %format_args!("{:x}", peer.node()),
                    pid = ?peer.pid,
                    "another publisher on sensors: its samples are refused, walks are stopped \
                     and refused until it is gone"
                );
            }
        }
        for peer in &self.intruders {
            if !intruders.iter().any(|p| p.publisher == peer.publisher) {
                tracing::info!(publisher = %peer.publisher, "the other publisher on sensors is gone");
            }
        }
        self.pinned = roster.pinned;
        self.intruders = intruders;
    }

    /// What the status says while another process publishes on `sensors`, naming it.
    pub fn notice(&self) -> Option<String> {
        let first = self.intruders.first()?;
        let mut text = match &self.pinned {
            Some(pinned) => format!(
                "intruder on sensors: {first}, not the adapter walkd follows{}",
                pinned
                    .pid
                    .map_or(String::new(), |pid| format!(" (pid {pid})"))
            ),
            None => format!(
                "{} publishers on sensors, {first} among them: only one adapter may publish",
                self.intruders.len()
            ),
        };
        if self.pinned.is_some() && self.intruders.len() > 1 {
            text.push_str(&format!(" and {} more", self.intruders.len() - 1));
        }
        Some(text)
    }
}

impl Default for AdapterWatch {
    fn default() -> Self {
        Self::new()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_pinned_publisher_crosses_threads_whole_and_gone_means_the_one_shown() {
        let trust = AdapterTrust::new();
        assert!(!trust.pinned_is_gone());
        assert_eq!(trust.pinned().1, None);
        let id = PublisherId::from_value(0x1234_5678_9abc_def0_0fed_cba9_8765_4321);
        trust.show(Some(id));
        let (version, pinned) = trust.pinned();
        assert_eq!(pinned, Some(id));
        trust.report_gone(version);
        assert!(trust.pinned_is_gone());
        trust.show(None);
        assert!(
            !trust.pinned_is_gone(),
            "a new pin is not the one reported gone"
        );
        std::thread::scope(|scope| {
            scope.spawn(|| {
                for i in 1..10_000u128 {
                    trust.show(Some(PublisherId::from_value(i << 64 | i)));
                }
            });
            for _ in 0..10_000 {
                if let (_, Some(id)) = trust.pinned() {
                    let value = id.value();
                    assert_eq!(value >> 64, value & u128::from(u64::MAX), "torn read");
                }
            }
        });
    }
}
