//! Which received samples the control loop may use.
//!
//! Every process stamps with the same clock (`CLOCK_MONOTONIC`), so a sample stamped in the
//! future, or older than one already used, can only come from a broken or hostile adapter. It
//! is refused and counted, and the loop carries on as if it had not come: the period grid never
//! follows a timestamp it has not reached itself. A sample whose sequence number does not grow
//! while its time does is a new adapter run (a restart).

use core::fmt::Write;

use shm_types::{FixedText, SensorSample};

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

/// Judges samples by their time stamps and sequence numbers; no allocation.
pub struct SampleGate {
    last_seq: Option<u64>,
    last_stamp_ns: u64,
    rejected: u64,
    last_rejection: FixedText<96>,
}

impl SampleGate {
    /// A gate that has seen no sample yet.
    pub fn new() -> Self {
        Self {
            last_seq: None,
            last_stamp_ns: 0,
            rejected: 0,
            last_rejection: FixedText::EMPTY,
        }
    }

    /// Judges `sample`, received at `now_ns`.
    pub fn judge(&mut self, sample: &SensorSample, now_ns: u64) -> Verdict {
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
        let restarted = self.last_seq.is_some_and(|last| sample.seq <= last);
        self.last_seq = Some(sample.seq);
        self.last_stamp_ns = stamp;
        if restarted {
            Verdict::Restarted
        } else {
            Verdict::Accept
        }
    }

    fn reject(&mut self, why: core::fmt::Arguments) -> Verdict {
        self.rejected = self.rejected.saturating_add(1);
        self.last_rejection.clear();
        // FixedText cuts at its capacity and never fails.
        let _ = self.last_rejection.write_fmt(why);
        Verdict::Reject
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

    #[test]
    fn future_and_backward_stamps_are_refused_and_restarts_noticed() {
        let mut gate = SampleGate::new();
        let now = 10_000_000_000;
        assert_eq!(gate.judge(&sample(1, now - 1000), now), Verdict::Accept);
        assert_eq!(
            gate.judge(&sample(2, now + 20_000_000_000), now),
            Verdict::Reject
        );
        assert!(gate.last_rejection().as_str().contains("in the future"));
        assert_eq!(gate.judge(&sample(3, u64::MAX), now), Verdict::Reject);
        assert_eq!(gate.judge(&sample(4, now - 5000), now), Verdict::Reject);
        assert!(
            gate.last_rejection()
                .as_str()
                .contains("before the previous")
        );
        assert_eq!(gate.rejected(), 3);
        assert_eq!(gate.judge(&sample(5, now), now), Verdict::Accept);
        // A new adapter run starts counting again, later in time.
        assert_eq!(
            gate.judge(&sample(1, now + 100), now + 200),
            Verdict::Restarted
        );
        assert_eq!(
            gate.judge(&sample(2, now + 300), now + 400),
            Verdict::Accept
        );
    }
}
