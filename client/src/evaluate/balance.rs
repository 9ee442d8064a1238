//! The balance of a dynamic walk over the real processes: walkd's per-tick telemetry
//! (`<prefix>/telemetry`, read by the observer's [`Source`]) kept on a thread of its own, every
//! [`KEEP_EVERY`]th tick that carries ZMP and DCM, for the balance row of Fig. 6, every tick
//! at which the daemon's state changed (to time a controlled stop to the tick), and every planned
//! support phase the dynamic gait entered ([`super::timing`]).

use std::sync::mpsc::Receiver;
use std::thread::JoinHandle;

use anyhow::Context;
use shm_types::{DaemonState, Telemetry};

use super::fig6::BalanceSample;
use super::timing::PlannedPhase;
use crate::observe::source::{Batch, Source};

/// One telemetry in this many is kept (at 500 Hz: 100 samples a second).
pub(crate) const KEEP_EVERY: u64 = 5;

/// A tick at which the daemon's state changed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct StateChange {
    /// The tick.
    pub tick: u64,
    /// `timestamp_ns` of the sample the tick answered (pairs with the simulator's truth).
    pub sample_timestamp_ns: u64,
    /// The state after the tick.
    pub state: DaemonState,
}

/// What the recorder kept.
#[derive(Default)]
struct Kept {
    balance: Vec<Telemetry>,
    changes: Vec<StateChange>,
    phases: Vec<PlannedPhase>,
}

/// What a walk's telemetry showed, from the tick it started.
pub(crate) struct RecordedBalance {
    /// ZMP and DCM, for Fig. 6.
    pub samples: Vec<BalanceSample>,
    /// The daemon's state changes.
    pub state_changes: Vec<StateChange>,
    /// The dynamic gait's planned support phases, in order.
    pub phases: Vec<PlannedPhase>,
}

/// The ticks and ZMP/DCM of a walk's telemetry, until [`BalanceRecorder::finish`].
pub(crate) struct BalanceRecorder {
    source: Source,
    collector: JoinHandle<Kept>,
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

    /// Stops recording; the samples from tick `start_tick` on at `rate_hz`, time from there,
    /// the state changes from that tick on, and the planned phases.
    pub(crate) fn finish(self, start_tick: u64, rate_hz: f64) -> anyhow::Result<RecordedBalance> {
        self.source.stop()?;
        let kept = self
            .collector
            .join()
            .map_err(|_| anyhow::anyhow!("the balance recorder panicked"))?;
        let balance = kept
            .balance
            .iter()
            .filter(|t| t.tick >= start_tick)
            .map(|t| BalanceSample {
                t: (t.tick - start_tick) as f64 / rate_hz,
                zmp_reference: t.zmp_reference,
                zmp_measured: t.zmp_measured,
                dcm_reference: t.dcm_reference,
                dcm_measured: t.dcm_measured,
            })
            .collect();
        let changes = kept
            .changes
            .into_iter()
            .filter(|c| c.tick >= start_tick)
            .collect();
        Ok(RecordedBalance {
            samples: balance,
            state_changes: changes,
            phases: kept.phases,
        })
    }
}

/// Keeps every [`KEEP_EVERY`]th telemetry with ZMP and DCM, every state change and every new
/// planned phase, until the batches end.
fn collect(batches: &Receiver<Batch>) -> Kept {
    let mut kept = Kept::default();
    let mut state = None;
    for batch in batches {
        for telemetry in batch.telemetry {
            let now = telemetry.state.get().ok();
            if now.is_some() && now != state {
                state = now;
                kept.changes.extend(now.map(|state| StateChange {
                    tick: telemetry.tick,
                    sample_timestamp_ns: telemetry.sample_timestamp_ns,
                    state,
                }));
            }
            let phase = PlannedPhase::of(&telemetry);
            if phase.is_some() && phase.as_ref() != kept.phases.last() {
                kept.phases.extend(phase);
            }
            if telemetry.dynamics_valid.is_set() && telemetry.tick % KEEP_EVERY == 0 {
                kept.balance.push(telemetry);
            }
        }
    }
    kept
}
