//! What `walkctl evaluate` keeps of walkd's per-tick telemetry over the real processes
//! (`<prefix>/telemetry`, read by the observer's [`Source`]), on a thread of its own: every
//! [`KEEP_EVERY`]th tick that carries ZMP and DCM, for the balance row of Fig. 6, every tick
//! at which the daemon's state changed (to time a controlled stop to the tick), every planned
//! support phase the dynamic gait entered ([`super::timing`]), the stances in which each hand
//! was in the controller's contact set ([`super::hands::reaches_given_up`]), the force asked
//! of the held hands there ([`super::hands::asked_share`]), and every [`KEEP_EVERY`]th tick's
//! hand forces, asked and measured, for the hands row of Fig. 6.

use std::sync::mpsc::Receiver;
use std::thread::JoinHandle;

use anyhow::Context;
use kinematics::robot::EndEffector;
use shm_types::{DaemonState, Telemetry};

use super::fig6::{BalanceSample, HandSample};
use super::timing::PlannedPhase;
use crate::observe::source::{Batch, Source};

/// One telemetry in this many is kept (at 500 Hz: 100 samples a second).
pub(crate) const KEEP_EVERY: u64 = 5;

/// Stance indices past this are not tracked for the hands (a corrupt index cannot make the
/// recorder allocate without bound; walkd takes at most `[runtime] max_stances`, 10 000 by
/// default).
const MAX_STANCES: usize = 1_000_000;

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
    hands_held: Vec<[bool; 2]>,
    hands_asked: Vec<AskedForce>,
    /// Tick, forces asked and measured (left, right hand; N).
    hand_forces: Vec<(u64, [f64; 2], [f64; 2])>,
}

/// The vertical force asked of the held hands over the ticks of one stance index at which walkd
/// held a hand (`Telemetry::hand_forces_desired`, both hands summed).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct AskedForce {
    /// The sum over those ticks (N).
    pub sum_n: f64,
    /// How many ticks.
    pub ticks: u64,
}

/// What a walk's telemetry showed, from the tick it started.
pub(crate) struct RecordedTelemetry {
    /// ZMP and DCM, for Fig. 6.
    pub samples: Vec<BalanceSample>,
    /// The daemon's state changes.
    pub state_changes: Vec<StateChange>,
    /// The dynamic gait's planned support phases, in order.
    pub phases: Vec<PlannedPhase>,
    /// By stance index (the stance walkd moved towards): whether the left and the right hand
    /// were in its contact set at any tick.
    pub hands_held: Vec<[bool; 2]>,
    /// By stance index: the force asked of the held hands while walkd held one.
    pub hands_asked: Vec<AskedForce>,
    /// The hands' vertical forces, asked and measured, for Fig. 6.
    pub hand_forces: Vec<HandSample>,
}

/// The ticks and ZMP/DCM of a walk's telemetry, until [`TelemetryRecorder::finish`].
pub(crate) struct TelemetryRecorder {
    source: Source,
    collector: JoinHandle<Kept>,
}

impl TelemetryRecorder {
    /// Subscribes to the daemon on `prefix`; returns once subscribed.
    pub(crate) fn start(prefix: &str) -> anyhow::Result<Self> {
        let (source, batches) = Source::start(prefix)?;
        let collector = std::thread::Builder::new()
            .name("evaluate-telemetry".to_owned())
            .spawn(move || collect(&batches))
            .context("starting the telemetry recorder")?;
        Ok(Self { source, collector })
    }

    /// Stops recording; the samples from tick `start_tick` on at `rate_hz`, time from there,
    /// the state changes from that tick on, and the planned phases.
    pub(crate) fn finish(self, start_tick: u64, rate_hz: f64) -> anyhow::Result<RecordedTelemetry> {
        self.source.stop()?;
        let kept = self
            .collector
            .join()
            .map_err(|_| anyhow::anyhow!("the telemetry recorder panicked"))?;
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
        let hand_forces = kept
            .hand_forces
            .iter()
            .filter(|(tick, ..)| *tick >= start_tick)
            .map(|&(tick, asked, measured)| HandSample {
                t: (tick - start_tick) as f64 / rate_hz,
                asked,
                measured,
            })
            .collect();
        Ok(RecordedTelemetry {
            samples: balance,
            state_changes: changes,
            phases: kept.phases,
            hands_held: kept.hands_held,
            hands_asked: kept.hands_asked,
            hand_forces,
        })
    }
}

/// Keeps every [`KEEP_EVERY`]th telemetry with ZMP and DCM, every state change, every new
/// planned phase, the hands in contact per stance and every [`KEEP_EVERY`]th tick's hand forces
/// (measured: the answered sample's palm wrenches, when it came in the same batch, else the
/// latest), until the batches end.
fn collect(batches: &Receiver<Batch>) -> Kept {
    let mut kept = Kept::default();
    let mut state = None;
    let mut measured = [0.0; 2];
    for batch in batches {
        let palms = |sample: &shm_types::SensorSample| {
            EndEffector::HANDS.map(|hand| sample.wrenches[hand as usize][2])
        };
        for telemetry in batch.telemetry {
            if let Some(sample) = batch.samples.iter().find(|s| s.seq == telemetry.sample_seq) {
                measured = palms(sample);
            } else if let Some(sample) = batch.samples.last() {
                measured = palms(sample);
            }
            if telemetry.tick % KEEP_EVERY == 0 {
                kept.hand_forces
                    .push((telemetry.tick, telemetry.hand_forces_desired, measured));
            }
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
            let hands = EndEffector::HANDS.map(|hand| telemetry.contacts[hand as usize].is_set());
            let stance = telemetry.stance_index as usize;
            if hands.contains(&true) && stance < MAX_STANCES {
                if kept.hands_held.len() <= stance {
                    kept.hands_held.resize(stance + 1, [false; 2]);
                    kept.hands_asked.resize(stance + 1, AskedForce::default());
                }
                for (held, now) in kept.hands_held[stance].iter_mut().zip(hands) {
                    *held |= now;
                }
                let asked = &mut kept.hands_asked[stance];
                asked.sum_n += telemetry.hand_forces_desired.iter().sum::<f64>();
                asked.ticks += 1;
            }
            if telemetry.dynamics_valid.is_set() && telemetry.tick % KEEP_EVERY == 0 {
                kept.balance.push(telemetry);
            }
        }
    }
    kept
}

#[cfg(test)]
mod tests {
    use super::*;
    use shm_types::Flag;

    /// A telemetry towards `stance_index` with the hands held as given, each held hand asked
    /// for 10 N.
    fn telemetry(stance_index: u32, left_hand: bool, right_hand: bool) -> Telemetry {
        let mut telemetry = Telemetry::ZERO;
        telemetry.stance_index = stance_index;
        telemetry.contacts[EndEffector::LeftHand as usize] = Flag::from(left_hand);
        telemetry.contacts[EndEffector::RightHand as usize] = Flag::from(right_hand);
        telemetry.hand_forces_desired =
            [left_hand, right_hand].map(|held| 10.0 * f64::from(u8::from(held)));
        telemetry
    }

    #[test]
    fn the_hands_in_contact_are_kept_per_stance() {
        let (send, receive) = std::sync::mpsc::channel();
        let batch = |telemetry| Batch {
            telemetry,
            samples: Vec::new(),
            commands: Vec::new(),
            statuses: Vec::new(),
            refused: Vec::new(),
        };
        send.send(batch(vec![
            telemetry(0, false, false),
            telemetry(2, false, true),
            telemetry(2, false, false),
        ]))
        .unwrap();
        send.send(batch(vec![telemetry(3, true, false)])).unwrap();
        // A corrupt stance index is not tracked (no allocation without bound).
        send.send(batch(vec![telemetry(u32::MAX, true, true)]))
            .unwrap();
        drop(send);
        let kept = collect(&receive);
        assert_eq!(
            kept.hands_held,
            [[false; 2], [false; 2], [false, true], [true, false]]
        );
        // Every tick of the helper is tick 0, so each is kept for Fig. 6 (none measured).
        assert_eq!(kept.hand_forces.len(), 5);
        assert_eq!(kept.hand_forces[1], (0, [0.0, 10.0], [0.0; 2]));
        // The force asked, over the ticks that held a hand only.
        let asked = |sum_n, ticks| AskedForce { sum_n, ticks };
        assert_eq!(
            kept.hands_asked,
            [asked(0.0, 0), asked(0.0, 0), asked(10.0, 1), asked(10.0, 1)]
        );
    }

    #[test]
    fn every_fifth_tick_keeps_the_hand_forces_asked_and_measured_by_its_sample() {
        let (send, receive) = std::sync::mpsc::channel();
        let mut sample = shm_types::SensorSample::ZERO;
        sample.seq = 7;
        sample.wrenches[EndEffector::RightHand as usize][2] = 42.0;
        let at = |tick, sample_seq| {
            let mut telemetry = telemetry(1, false, true);
            telemetry.tick = tick;
            telemetry.sample_seq = sample_seq;
            telemetry
        };
        send.send(Batch {
            telemetry: vec![at(5, 7), at(6, 7)],
            samples: vec![sample],
            commands: Vec::new(),
            statuses: Vec::new(),
            refused: Vec::new(),
        })
        .unwrap();
        drop(send);
        assert_eq!(
            collect(&receive).hand_forces,
            [(5, [0.0, 10.0], [0.0, 42.0])]
        );
    }
}
