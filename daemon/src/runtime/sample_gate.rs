//! Which received samples the control loop may use.
//!
//! The ports take samples from one publisher only, the adapter pinned on the first sample
//! ([`shm_types::Pin`]); the samples of any other publisher never get here, and the gate counts
//! them as refused, naming their publisher. Every process stamps with the same clock
//! (`CLOCK_MONOTONIC`), so a sample stamped in the future, or older than one already used, can
//! only come from a broken or hostile adapter. It is refused and counted, and the loop carries
//! on as if it had not come: the period grid never follows a timestamp it has not reached
//! itself. A sample of a newly pinned publisher (the one before is gone) is a new adapter run;
//! the pinned adapter starting its sequence over is refused: an adapter restart is accepted
//! only from a new publisher, once the one before is gone.

use core::fmt::Write;

use shm_types::{FixedText, Pin, PublisherId, SensorSample};

/// How far in the future a sample may be stamped (ns): clock reads on two CPUs, nothing more.
pub const FUTURE_TOLERANCE_NS: u64 = 200_000;

/// What to do with a received sample.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Verdict {
    /// Use it.
    Accept,
    /// Use it: it is the first of a new adapter run.
    Restarted,
    /// Drop it (counted, and described in [`SampleGate::last_rejection`]).
    Reject,
}

/// Judges samples by their publisher, time stamps and sequence numbers; no allocation.
pub struct SampleGate {
    /// The publisher of the samples judged so far.
    publisher: Option<PublisherId>,
    last_seq: Option<u64>,
    last_stamp_ns: u64,
    rejected: u64,
    last_rejection: FixedText<96>,
    /// Samples the ports refused as another publisher's, as counted last.
    foreign: u64,
}

impl SampleGate {
    /// A gate that has seen no sample yet.
    pub fn new() -> Self {
        Self {
            publisher: None,
            last_seq: None,
            last_stamp_ns: 0,
            rejected: 0,
            last_rejection: FixedText::EMPTY,
            foreign: 0,
        }
    }

    /// Counts the samples the ports' `pin` refused since the last call (another publisher's) as
    /// rejected, naming the publisher of the last one.
    pub fn count_foreign(&mut self, pin: &Pin) {
        let refused = pin.refused();
        if refused <= self.foreign {
            return;
        }
        self.rejected = self.rejected.saturating_add(refused - self.foreign);
        self.foreign = refused;
        if let Some(from) = pin.last_refused() {
            self.describe(format_args!(
                "samples of publisher {from} refused: not the adapter walkd follows"
            ));
        }
    }

    /// Judges `sample` of the pinned publisher `publisher`, received at `now_ns`.
    pub fn judge(
        &mut self,
        sample: &SensorSample,
        publisher: Option<PublisherId>,
        now_ns: u64,
    ) -> Verdict {
        let stamp = sample.timestamp_ns;
        if stamp > now_ns.saturating_add(FUTURE_TOLERANCE_NS) {
            let ahead = (stamp - now_ns) as f64 * 1e-9;
            return self.reject(format_args!(
                "sample {} stamped {ahead:.3e} s in the future",
                sample.seq
            ));
        }
        if stamp < self.last_stamp_ns {
            let behind = (self.last_stamp_ns - stamp) as f64 * 1e-9;
            return self.reject(format_args!(
                "sample {} stamped {behind:.3e} s before the previous one",
                sample.seq
            ));
        }
        let restarted = publisher != self.publisher;
        if restarted {
            self.publisher = publisher;
        } else if let Some(last) = self.last_seq.filter(|last| sample.seq <= *last) {
            return self.reject(format_args!(
                "sample {} of the pinned adapter after {last}: its sequence went back",
                sample.seq
            ));
        }
        let first = self.last_seq.is_none();
        self.last_seq = Some(sample.seq);
        self.last_stamp_ns = stamp;
        if restarted && !first {
            Verdict::Restarted
        } else {
            Verdict::Accept
        }
    }

    fn reject(&mut self, why: core::fmt::Arguments) -> Verdict {
        self.rejected = self.rejected.saturating_add(1);
        self.describe(why);
        Verdict::Reject
    }

    fn describe(&mut self, why: core::fmt::Arguments) {
        self.last_rejection.clear();
        // FixedText cuts at its capacity and never fails.
        let _ = self.last_rejection.write_fmt(why);
    }

    /// Samples refused so far.
    pub fn rejected(&self) -> u64 {
        self.rejected
    }

    /// Why the last sample was refused.
    pub fn last_rejection(&self) -> &FixedText<96> {
        &self.last_rejection
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(seq: u64, timestamp_ns: u64) -> SensorSample {
        SensorSample {
            seq,
            timestamp_ns,
            ..SensorSample::ZERO
        }
    }

    /// The publishers the test's pin pins: `ids[0]` first, then `ids[1]`.
    fn pins() -> (Pin, [PublisherId; 2]) {
        let ids = [PublisherId::from_value(0xa1), PublisherId::from_value(0xb2)];
        let mut pin = Pin::new();
        pin.admit(ids[0]);
        (pin, ids)
    }

    #[test]
    fn future_and_backward_stamps_are_refused() {
        let (pin, _) = pins();
        let adapter = pin.pinned();
        let mut gate = SampleGate::new();
        let now = 10_000_000_000;
        assert_eq!(
            gate.judge(&sample(1, now - 1000), adapter, now),
            Verdict::Accept
        );
        assert_eq!(
            gate.judge(&sample(2, now + 20_000_000_000), adapter, now),
            Verdict::Reject
        );
        assert!(gate.last_rejection().as_str().contains("in the future"));
        assert_eq!(
            gate.judge(&sample(3, u64::MAX), adapter, now),
            Verdict::Reject
        );
        assert_eq!(
            gate.judge(&sample(4, now - 5000), adapter, now),
            Verdict::Reject
        );
        assert!(
            gate.last_rejection()
                .as_str()
                .contains("before the previous")
        );
        assert_eq!(gate.rejected(), 3);
        assert_eq!(gate.judge(&sample(5, now), adapter, now), Verdict::Accept);
    }

    /// Issue 20: a restart (sequence from 1) is a new run only from a newly pinned publisher;
    /// the pinned adapter going back is refused, and so are other publishers' samples (counted).
    #[test]
    fn only_a_new_publisher_restarts_and_other_publishers_are_counted() {
        let (mut pin, [adapter, intruder]) = pins();
        let mut gate = SampleGate::new();
        let now = 10_000_000_000;
        assert_eq!(
            gate.judge(&sample(5, now), pin.pinned(), now),
            Verdict::Accept
        );
        assert_eq!(
            gate.judge(&sample(1, now + 100), pin.pinned(), now + 200),
            Verdict::Reject
        );
        assert!(gate.last_rejection().as_str().contains("went back"));

        for _ in 0..3 {
            pin.admit(intruder);
        }
        gate.count_foreign(&pin);
        assert_eq!(gate.rejected(), 4);
        let text = gate.last_rejection().as_str();
        assert!(text.contains(&intruder.to_string()), "{text}");
        gate.count_foreign(&pin);
        assert_eq!(gate.rejected(), 4, "refusals counted twice");

        // The adapter is gone: the other publisher is pinned, and its run starts over.
        pin.release();
        pin.admit(intruder);
        assert_eq!(
            gate.judge(&sample(1, now + 300), pin.pinned(), now + 400),
            Verdict::Restarted
        );
        assert_eq!(
            gate.judge(&sample(2, now + 500), pin.pinned(), now + 600),
            Verdict::Accept
        );
        assert_ne!(pin.pinned(), Some(adapter));
    }
}
