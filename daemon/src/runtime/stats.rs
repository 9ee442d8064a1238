//! Timing statistics of the control loop, recorded without allocation.

use hdrhistogram::Histogram;
use shm_types::{HISTOGRAM_BUCKETS, LatencySummary, LogHistogram};

/// Largest recorded duration (ns); longer ones saturate.
const MAX_NS: u64 = 10_000_000_000;

/// Deadline misses described in detail (the first ones of a run; later ones are only counted).
pub const MISS_LOG_CAPACITY: usize = 32;

/// Histograms (ns) and counters of the control loop since start.
pub struct LoopStats {
    /// Compute time of `Controller::tick`.
    pub tick: Histogram<u64>,
    /// Sample timestamp → command sent.
    pub latency: Histogram<u64>,
    /// |tick start − nominal sample time| (realtime clock).
    pub jitter: Histogram<u64>,
    /// How late the control thread's timer wake-ups came (realtime clock): the OS floor.
    pub wakeup: Histogram<u64>,
    /// How the first deadline misses came about.
    pub misses: MissLog,
    /// Every deadline miss by its main cause.
    pub miss_causes: MissCauses,
    /// Ticks executed.
    pub ticks: u64,
    /// Periods whose command went out after the period's deadline.
    pub deadline_misses: u64,
    /// Periods that ended without a fresh sample.
    pub stale_periods: u64,
    /// Times the sample watchdog tripped.
    pub watchdog_trips: u64,
    /// Ticks whose telemetry could not be published (observers saw a gap).
    pub telemetry_failures: u64,
}

impl LoopStats {
    /// Empty statistics; all memory is allocated here.
    pub fn new() -> Self {
        let histogram = || {
            Histogram::new_with_bounds(1, MAX_NS, 2).expect("constant histogram bounds are valid")
        };
        Self {
            tick: histogram(),
            latency: histogram(),
            jitter: histogram(),
            wakeup: histogram(),
            misses: MissLog::default(),
            miss_causes: MissCauses::default(),
            ticks: 0,
            deadline_misses: 0,
            stale_periods: 0,
            watchdog_trips: 0,
            telemetry_failures: 0,
        }
    }
}

impl Default for LoopStats {
    fn default() -> Self {
        Self::new()
    }
}

/// The timeline of one period that ended in a deadline miss (ns), so a report can tell an OS
/// wake-up stall from a late adapter or a long tick.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct MissRecord {
    /// When the tick started, since the control loop started.
    pub at_ns: u64,
    /// The period's timer wake-up came this late after its target.
    pub wake_late_ns: u64,
    /// Sample timestamp − the time the grid expected it (negative: early).
    pub sample_offset_ns: i64,
    /// Sample timestamp → the loop had the sample in hand.
    pub pickup_ns: u64,
    /// Controller compute time.
    pub tick_ns: u64,
    /// The command went out this long after the deadline.
    pub late_ns: u64,
}

impl MissRecord {
    /// The largest of the three parts of the time from the expected sample to the command.
    pub fn cause(&self) -> MissCause {
        let adapter = u64::try_from(self.sample_offset_ns).unwrap_or(0);
        if adapter >= self.pickup_ns && adapter >= self.tick_ns {
            MissCause::AdapterLate
        } else if self.pickup_ns >= self.tick_ns {
            MissCause::Pickup
        } else {
            MissCause::Tick
        }
    }
}

/// Where most of a missed period's time went.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MissCause {
    /// The sample was stamped late in its period (the adapter woke or ran late).
    AdapterLate,
    /// The sample was there, but the control thread took long to have it in hand (its wake-up
    /// stalled, or the adapter stalled between stamping and publishing).
    Pickup,
    /// The controller tick took long (compute, or the thread was preempted during it).
    Tick,
}

/// Deadline misses counted by [`MissCause`].
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct MissCauses {
    /// [`MissCause::AdapterLate`].
    pub adapter_late: u64,
    /// [`MissCause::Pickup`].
    pub pickup: u64,
    /// [`MissCause::Tick`].
    pub tick: u64,
}

impl MissCauses {
    /// Counts one miss.
    pub fn count(&mut self, cause: MissCause) {
        match cause {
            MissCause::AdapterLate => self.adapter_late += 1,
            MissCause::Pickup => self.pickup += 1,
            MissCause::Tick => self.tick += 1,
        }
    }
}

/// The first [`MISS_LOG_CAPACITY`] miss records, stored inline (no allocation).
#[derive(Debug, Clone, Default)]
pub struct MissLog {
    records: [MissRecord; MISS_LOG_CAPACITY],
    len: usize,
}

impl MissLog {
    /// Keeps `record` if there is room left.
    pub fn push(&mut self, record: MissRecord) {
        if let Some(slot) = self.records.get_mut(self.len) {
            *slot = record;
            self.len += 1;
        }
    }

    /// The records kept, oldest first.
    pub fn records(&self) -> &[MissRecord] {
        &self.records[..self.len]
    }
}

/// Records `ns` into `histogram`, saturating at the upper bound. No allocation.
pub fn record(histogram: &mut Histogram<u64>, ns: u64) {
    histogram.saturating_record(ns.max(1));
}

/// p50 / p99 / max of a histogram in microseconds (zeros when empty).
pub fn summarize(histogram: &Histogram<u64>) -> LatencySummary {
    if histogram.is_empty() {
        return LatencySummary::default();
    }
    let us = |ns: u64| (ns as f64 / 1000.0) as f32;
    LatencySummary {
        p50: us(histogram.value_at_quantile(0.5)),
        p99: us(histogram.value_at_quantile(0.99)),
        max: us(histogram.max()),
    }
}

/// The coarse power-of-two histogram (µs) of `histogram` for the status message.
/// No allocation (iterates the recorded buckets in place).
pub fn log_histogram(histogram: &Histogram<u64>) -> LogHistogram {
    let mut out = LogHistogram::default();
    for value in histogram.iter_recorded() {
        let us = histogram.lowest_equivalent(value.value_iterated_to()) / 1000;
        let bucket = (u64::BITS - us.leading_zeros()).saturating_sub(1) as usize;
        out.counts[bucket.min(HISTOGRAM_BUCKETS - 1)] += value.count_at_value();
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn summary_reports_microseconds() {
        let mut stats = LoopStats::new();
        assert_eq!(summarize(&stats.tick), LatencySummary::default());
        for i in 1..=100u64 {
            record(&mut stats.tick, i * 1000);
        }
        let summary = summarize(&stats.tick);
        assert!((summary.p50 - 50.0).abs() < 1.0, "{summary:?}");
        assert!((summary.p99 - 99.0).abs() < 1.5, "{summary:?}");
        assert!((summary.max - 100.0).abs() < 1.0, "{summary:?}");
        let buckets = log_histogram(&stats.tick);
        assert_eq!(buckets.counts.iter().sum::<u64>(), 100);
        assert_eq!(buckets.counts[5], 32, "32..=63 us fall into [32, 64) us");
        assert_eq!(buckets.counts[6], 37, "64..=100 us fall into [64, 128) us");
        record(&mut stats.tick, u64::MAX);
        assert!(summarize(&stats.tick).max >= 9.9e6);
    }

    #[test]
    fn a_miss_is_blamed_on_its_largest_part() {
        let miss = |sample_offset_ns, pickup_ns, tick_ns| MissRecord {
            sample_offset_ns,
            pickup_ns,
            tick_ns,
            ..MissRecord::default()
        };
        assert_eq!(
            miss(480_000, 10_000, 20_000).cause(),
            MissCause::AdapterLate
        );
        assert_eq!(miss(-50_000, 900_000, 20_000).cause(), MissCause::Pickup);
        assert_eq!(miss(-50_000, 10_000, 600_000).cause(), MissCause::Tick);
        let mut causes = MissCauses::default();
        causes.count(MissCause::Pickup);
        causes.count(MissCause::Pickup);
        assert_eq!(causes.pickup, 2);
        assert_eq!(causes.adapter_late + causes.tick, 0);
    }

    #[test]
    fn miss_log_keeps_the_first_records_only() {
        let mut log = MissLog::default();
        for i in 0..MISS_LOG_CAPACITY as u64 + 5 {
            log.push(MissRecord {
                at_ns: i,
                ..MissRecord::default()
            });
        }
        assert_eq!(log.records().len(), MISS_LOG_CAPACITY);
        assert_eq!(log.records()[0].at_ns, 0);
        assert_eq!(
            log.records()[MISS_LOG_CAPACITY - 1].at_ns,
            MISS_LOG_CAPACITY as u64 - 1
        );
    }
}
