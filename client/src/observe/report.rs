//! What an observer saw: per stream, how many messages arrived and how many it lost (gaps in the
//! messages' sequence numbers).

use std::collections::BTreeMap;
use std::fmt;

/// Received and lost messages of one stream, from its sequence numbers.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct SeqTracker {
    /// The first `seq` seen.
    pub first: Option<u64>,
    /// The last `seq` seen.
    pub last: Option<u64>,
    /// Messages received.
    pub received: u64,
    /// Messages missing between the first and the last (gaps).
    pub lost: u64,
    /// Times the sequence started over (a restarted peer).
    pub restarts: u64,
}

impl SeqTracker {
    /// Accounts for a message with `seq`.
    pub fn see(&mut self, seq: u64) {
        self.received += 1;
        match self.last {
            None => self.first = Some(seq),
            Some(last) if seq > last => self.lost += seq - last - 1,
            Some(_) => self.restarts += 1,
        }
        self.last = Some(seq);
    }
}

/// What one observation saw.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct ObserverReport {
    /// Per-tick telemetry.
    pub telemetry: SeqTracker,
    /// Sensor samples.
    pub samples: SeqTracker,
    /// Joint commands.
    pub commands: SeqTracker,
    /// Statuses received.
    pub statuses: u64,
    /// Ticks whose sample the observer did not have, so their link transforms were not logged.
    pub ticks_without_sample: u64,
    /// Other publishers than the pinned ones, by stream (`telemetry: publisher … of pid …`):
    /// messages refused and not recorded.
    pub intruders: BTreeMap<String, u64>,
}

impl ObserverReport {
    /// Whether the observer lost no message.
    pub fn lossless(&self) -> bool {
        self.telemetry.lost == 0 && self.samples.lost == 0 && self.commands.lost == 0
    }

    /// The report as JSON (for `--json` output and the recording's metadata).
    pub fn json(&self) -> serde_json::Value {
        let stream = |s: &SeqTracker| {
            serde_json::json!({
                "received": s.received, "lost": s.lost, "first_seq": s.first,
                "last_seq": s.last, "restarts": s.restarts,
            })
        };
        serde_json::json!({
            "telemetry": stream(&self.telemetry),
            "samples": stream(&self.samples),
            "commands": stream(&self.commands),
            "statuses": self.statuses,
            "ticks_without_sample": self.ticks_without_sample,
            "intruders": self.intruders,
        })
    }
}

impl fmt::Display for ObserverReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let line = |f: &mut fmt::Formatter<'_>, name: &str, s: &SeqTracker| {
            writeln!(
                f,
                "  {name:<10} {:>8} received, {} lost",
                s.received, s.lost
            )
        };
        line(f, "telemetry", &self.telemetry)?;
        line(f, "samples", &self.samples)?;
        line(f, "commands", &self.commands)?;
        write!(f, "  statuses   {:>8} received", self.statuses)?;
        for (intruder, refused) in &self.intruders {
            write!(f, "\n  refused    {refused:>8} from {intruder}")?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gaps_and_restarts_are_counted() {
        let mut tracker = SeqTracker::default();
        for seq in [5, 6, 7, 10, 11, 1, 2] {
            tracker.see(seq);
        }
        assert_eq!(tracker.received, 7);
        assert_eq!(tracker.lost, 2);
        assert_eq!(tracker.restarts, 1);
        assert_eq!((tracker.first, tracker.last), (Some(5), Some(2)));
    }
}
