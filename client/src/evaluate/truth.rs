//! The simulator's ground truth during a run: recorded from `walk-sim`'s `sim-truth` service on a
//! thread of its own (a lockstep run publishes thousands of states per second, more than a
//! subscriber buffers between two daemon statuses), then paired with the daemon's statuses and
//! turned into the simulator's verdict (fall, tilt, final state).

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use anyhow::Context;
use shm_types::{ServiceNames, SimTruth, TruthSubscriber};

use super::footholds;

/// How often the recorder drains the subscriber.
const DRAIN_PERIOD: Duration = Duration::from_micros(500);

/// How often [`TruthRecorder::wait_for_sim_time`] looks at the newest state.
const WAIT_PERIOD: Duration = Duration::from_millis(5);

/// Records every state `walk-sim` publishes on a prefix until [`TruthRecorder::finish`].
pub(crate) struct TruthRecorder {
    stop: Arc<AtomicBool>,
    /// The newest recorded state's `sim_time_s` as `f64` bits; NaN before the first.
    newest_sim_time: Arc<AtomicU64>,
    handle: JoinHandle<anyhow::Result<Vec<SimTruth>>>,
}

impl TruthRecorder {
    /// Subscribes to `<prefix>/sim-truth`; returns once the subscription exists, so every state
    /// published afterwards is recorded.
    pub(crate) fn start(prefix: &str) -> anyhow::Result<Self> {
        let names = ServiceNames::new(prefix)?;
        let stop = Arc::new(AtomicBool::new(false));
        let stopped = Arc::clone(&stop);
        let newest_sim_time = Arc::new(AtomicU64::new(f64::NAN.to_bits()));
        let newest = Arc::clone(&newest_sim_time);
        let (ready, subscribed) = std::sync::mpsc::channel();
        let handle = std::thread::spawn(move || {
            // iceoryx2 ports stay on the thread that created them.
            let subscriber = match TruthSubscriber::open(&names, "walkctl-evaluate-truth") {
                Ok(subscriber) => {
                    let _ = ready.send(None);
                    subscriber
                }
                Err(error) => {
                    let _ = ready.send(Some(error.to_string()));
                    anyhow::bail!("{error}");
                }
            };
            let mut states = Vec::new();
            loop {
                let last_round = stopped.load(Ordering::Relaxed);
                subscriber.drain(|truth| states.push(*truth))?;
                if let Some(state) = states.last() {
                    newest.store(state.sim_time_s.to_bits(), Ordering::Relaxed);
                }
                if last_round {
                    return Ok(states);
                }
                std::thread::sleep(DRAIN_PERIOD);
            }
        });
        match subscribed.recv() {
            Ok(None) => Ok(Self {
                stop,
                newest_sim_time,
                handle,
            }),
            Ok(Some(error)) => anyhow::bail!("subscribing to the simulator's truth: {error}"),
            Err(_) => anyhow::bail!("the simulator-truth recorder ended before subscribing"),
        }
    }

    /// Simulated time of the newest state recorded (s); `None` before the first.
    fn newest_sim_time(&self) -> Option<f64> {
        let time = f64::from_bits(self.newest_sim_time.load(Ordering::Relaxed));
        (!time.is_nan()).then_some(time)
    }

    /// Keeps recording until the simulator's clock has advanced `span_s` past the newest state
    /// recorded now, or `wall_limit` has passed (a simulator that stalled); at once when nothing
    /// has been recorded (no simulator: a real robot).
    pub(crate) fn wait_for_sim_time(&self, span_s: f64, wall_limit: Duration) {
        let Some(from) = self.newest_sim_time() else {
            return;
        };
        let wall = Instant::now();
        while wall.elapsed() < wall_limit
            && self
                .newest_sim_time()
                .is_some_and(|now| now < from + span_s)
        {
            std::thread::sleep(WAIT_PERIOD);
        }
    }

    /// Stops recording; returns the states in the order published.
    pub(crate) fn finish(self) -> anyhow::Result<Vec<SimTruth>> {
        self.stop.store(true, Ordering::Relaxed);
        self.handle
            .join()
            .map_err(|_| anyhow::anyhow!("the simulator-truth recorder panicked"))?
            .context("recording the simulator's truth")
    }
}

/// The state the daemon's tick saw when it wrote a status stamped `timestamp_ns`: the newest
/// state read before then. `None` when there is none, or when the subscriber lost the states
/// right after it (a gap in `seq`), so the newest one recorded may not be the newest published.
pub(crate) fn state_at(states: &[SimTruth], timestamp_ns: u64) -> Option<&SimTruth> {
    let after = states.partition_point(|s| s.timestamp_ns <= timestamp_ns);
    let found = states.get(after.checked_sub(1)?)?;
    match states.get(after) {
        Some(next) if next.seq != found.seq + 1 => None,
        _ => Some(found),
    }
}

/// What the simulator says about a walk submitted at `submitted_ns` (monotonic).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Verdict {
    /// The last state recorded (after the walk ended, the robot holding its last posture).
    pub(crate) end: SimTruth,
    /// Simulated time from submission at which the fall rule first fired (s).
    pub(crate) fell_at_s: Option<f64>,
    /// Largest `base_link` tilt from the vertical since submission (rad).
    pub(crate) max_tilt_rad: f64,
    /// Simulated time from submission at which a sole first rose [`footholds::STEP_HEIGHT_M`] above its
    /// height at submission: the first step's lift-off ([`footholds::swings`]) (s).
    pub(crate) first_step_s: Option<f64>,
    /// Horizontal distance the midpoint of the soles travelled from submission to the end (m).
    pub(crate) walked_m: f64,
}

/// The horizontal midpoint of the two simulated soles.
fn feet_midpoint(state: &SimTruth) -> [f64; 2] {
    [
        (state.left_foot[0] + state.right_foot[0]) / 2.0,
        (state.left_foot[1] + state.right_foot[1]) / 2.0,
    ]
}

impl Verdict {
    /// The verdict of the recorded `states`; `None` when nothing was recorded.
    pub(crate) fn of(states: &[SimTruth], submitted_ns: u64) -> Option<Self> {
        let end = *states.last()?;
        // From the newest state before the submission: where the walk starts.
        let walk = footholds::since_submission(states, submitted_ns);
        let at_submission = &walk[0];
        let submitted_at = at_submission.sim_time_s;
        let first_step_s = footholds::swings(walk)
            .first()
            .map(|swing| swing.lift_s - submitted_at);
        let (start, finish) = (feet_midpoint(at_submission), feet_midpoint(&end));
        let walked_m = (finish[0] - start[0]).hypot(finish[1] - start[1]);
        // The flag is sticky: the end state says whether a fall happened at all, even if the
        // state where it first fired was lost.
        let fell_at_s = end.fallen.is_set().then(|| {
            let first = states.iter().find(|s| s.fallen.is_set()).unwrap_or(&end);
            first.sim_time_s - submitted_at
        });
        Some(Self {
            end,
            fell_at_s,
            max_tilt_rad: states
                .iter()
                .filter(|s| s.timestamp_ns >= submitted_ns)
                .map(|s| s.tilt_rad)
                .fold(0.0, f64::max),
            first_step_s,
            walked_m,
        })
    }

    /// The walking speed of a walk that ended `walk_s` after submission: the distance walked
    /// over the time from the first step to the end (m/s); `None` without a step before it.
    pub(crate) fn speed_m_s(&self, walk_s: f64) -> Option<f64> {
        self.first_step_s
            .filter(|first| *first < walk_s)
            .map(|first| self.walked_m / (walk_s - first))
    }
}

/// The outcome of a walk the daemon ended with `daemon_outcome`, overruled by a fall the simulator
/// saw `fell_at_s` after submission.
pub(crate) fn judged_outcome(fell_at_s: Option<f64>, daemon_outcome: &str) -> String {
    match fell_at_s {
        Some(t) => format!("fell at {t:.1} s (daemon: {daemon_outcome})"),
        None => daemon_outcome.to_owned(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn state(seq: u64, timestamp_ns: u64) -> SimTruth {
        SimTruth {
            seq,
            timestamp_ns,
            ..SimTruth::ZERO
        }
    }

    #[test]
    fn a_status_pairs_with_the_newest_state_read_before_it() {
        let states = [state(1, 100), state(2, 200), state(3, 300)];
        assert_eq!(state_at(&states, 99), None);
        assert_eq!(state_at(&states, 100).map(|s| s.seq), Some(1));
        assert_eq!(state_at(&states, 250).map(|s| s.seq), Some(2));
        assert_eq!(state_at(&states, 1000).map(|s| s.seq), Some(3));
    }

    #[test]
    fn a_state_followed_by_a_gap_is_not_trusted() {
        let states = [state(1, 100), state(2, 200), state(7, 700)];
        assert_eq!(state_at(&states, 150).map(|s| s.seq), Some(1));
        assert_eq!(state_at(&states, 300), None);
        assert_eq!(state_at(&states, 800).map(|s| s.seq), Some(7));
    }
}

#[cfg(test)]
mod verdict_tests {
    use super::*;

    fn state(seq: u64, tilt_rad: f64, fallen: bool) -> SimTruth {
        SimTruth {
            seq,
            timestamp_ns: seq * 1000,
            sim_time_s: seq as f64 * 0.5,
            tilt_rad,
            fallen: fallen.into(),
            ..SimTruth::ZERO
        }
    }

    #[test]
    fn the_first_fallen_state_dates_the_fall_from_submission() {
        let states = [
            state(1, 0.3, false),
            state(2, 0.01, false),
            state(3, 0.2, false),
            state(4, 0.7, true),
            state(5, 3.1, true),
        ];
        let verdict = Verdict::of(&states, 2000).unwrap();
        assert_eq!(verdict.fell_at_s, Some(1.0));
        assert_eq!(verdict.max_tilt_rad, 3.1);
        assert_eq!(verdict.end.seq, 5);
        assert_eq!(
            judged_outcome(verdict.fell_at_s, "done"),
            "fell at 1.0 s (daemon: done)"
        );
    }

    #[test]
    fn an_upright_walk_keeps_the_daemon_outcome() {
        let states = [
            state(1, 0.3, false),
            state(2, 0.01, false),
            state(3, 0.02, false),
        ];
        let verdict = Verdict::of(&states, 2000).unwrap();
        assert_eq!(verdict.fell_at_s, None);
        assert_eq!(verdict.max_tilt_rad, 0.02);
        assert_eq!(
            judged_outcome(verdict.fell_at_s, "fault: timeout"),
            "fault: timeout"
        );
        assert_eq!(Verdict::of(&[], 0), None);
    }
}

#[cfg(test)]
mod step_tests {
    use super::*;

    /// A state at `t` s with the left sole at (x, 0, left_z) and the right one at (x, -0.2, 0).
    fn state(seq: u64, x: f64, left_z: f64) -> SimTruth {
        let mut state = SimTruth {
            seq,
            timestamp_ns: seq * 1000,
            sim_time_s: seq as f64 * 0.1,
            ..SimTruth::ZERO
        };
        state.left_foot[..3].copy_from_slice(&[x, 0.0, left_z]);
        state.right_foot[..3].copy_from_slice(&[x, -0.2, 0.0]);
        state
    }

    #[test]
    fn the_first_step_is_a_sole_rising_above_its_height_at_submission() {
        let states = [
            state(1, 0.0, 0.0),
            state(2, 0.0, 0.005),
            state(3, 0.0, 0.02),
            state(4, 0.3, 0.0),
            state(5, 0.4, 0.0),
        ];
        let verdict = Verdict::of(&states, 1000).unwrap();
        assert!((verdict.first_step_s.unwrap() - 0.2).abs() < 1e-12);
        assert!((verdict.walked_m - 0.4).abs() < 1e-12);
        assert!((verdict.speed_m_s(1.2).unwrap() - 0.4).abs() < 1e-12);
        assert_eq!(verdict.speed_m_s(0.1), None);
        let standing = [state(1, 0.0, 0.0), state(2, 0.0, 0.004)];
        assert_eq!(Verdict::of(&standing, 1000).unwrap().first_step_s, None);
    }
}
