//! Timing statistics of the control loop, recorded without allocation.

use hdrhistogram::Histogram;
use shm_types::{HISTOGRAM_BUCKETS, LatencySummary, LogHistogram};

/// Largest recorded duration (ns); longer ones saturate.
const MAX_NS: u64 = 10_000_000_000;

/// Histograms (ns) and counters of the control loop since start.
pub struct LoopStats {
    /// Compute time of `Controller::tick`.
    pub tick: Histogram<u64>,
    /// Sample timestamp → command sent.
    pub latency: Histogram<u64>,
    /// |tick start − nominal sample time| (realtime clock).
    pub jitter: Histogram<u64>,
    /// Ticks executed.
    pub ticks: u64,
    /// Periods whose command went out after the period's deadline.
    pub deadline_misses: u64,
    /// Periods that ended without a fresh sample.
    pub stale_periods: u64,
    /// Times the sample watchdog tripped.
    pub watchdog_trips: u64,
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
            ticks: 0,
            deadline_misses: 0,
            stale_periods: 0,
            watchdog_trips: 0,
        }
    }
}

impl Default for LoopStats {
    fn default() -> Self {
        Self::new()
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
}
