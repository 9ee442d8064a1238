//! The balance of a dynamic walk over the real processes: walkd's per-tick telemetry
//! (`<prefix>/telemetry`, read by the observer's [`Source`]) kept on a thread of its own, every
//! [`KEEP_EVERY`]th tick that carries ZMP and DCM, for the balance row of Fig. 6.

use std::sync::mpsc::Receiver;
use std::thread::JoinHandle;

use anyhow::Context;
use shm_types::Telemetry;

use super::fig6::BalanceSample;
use crate::observe::source::{Batch, Source};

/// One telemetry in this many is kept (at 500 Hz: 100 samples a second).
pub(crate) const KEEP_EVERY: u64 = 5;

/// The ticks and ZMP/DCM of a walk's telemetry, until [`BalanceRecorder::finish`].
pub(crate) struct BalanceRecorder {
    source: Source,
    collector: JoinHandle<Vec<Telemetry>>,
}

impl BalanceRecorder {
    /// Subscribes to the daemon on `prefix`; returns once subscribed.
    pub(crate) fn start(prefix: &str) -> anyhow::Result<Self> {
        let (source, batches) = Source::start(prefix)?;
        let collector = std::thread::Builder::new()
            .name("evaluate-balance".to_owned())
            .spawn(move || collect(&batches))
            .context("starting the balance recorder")?;
        Ok(Self { source, collector })
    }

    /// Stops recording; the samples from tick `start_tick` on at `rate_hz`, time from there.
    pub(crate) fn finish(
        self,
        start_tick: u64,
        rate_hz: f64,
    ) -> anyhow::Result<Vec<BalanceSample>> {
        self.source.stop()?;
        let telemetry = self
            .collector
            .join()
            .map_err(|_| anyhow::anyhow!("the balance recorder panicked"))?;
        Ok(telemetry
            .iter()
            .filter(|t| t.tick >= start_tick)
            .map(|t| BalanceSample {
                t: (t.tick - start_tick) as f64 / rate_hz,
                zmp_reference: t.zmp_reference,
                zmp_measured: t.zmp_measured,
                dcm_reference: t.dcm_reference,
                dcm_measured: t.dcm_measured,
            })
            .collect())
    }
}

/// Keeps every [`KEEP_EVERY`]th telemetry with ZMP and DCM until the batches end.
fn collect(batches: &Receiver<Batch>) -> Vec<Telemetry> {
    let mut kept = Vec::new();
    for batch in batches {
        kept.extend(
            batch
                .telemetry
                .into_iter()
                .filter(|t| t.dynamics_valid.is_set() && t.tick % KEEP_EVERY == 0),
        );
    }
    kept
}
