//! One post-processed sequence submitted to a running walkd and watched from beside it to its
//! end and [`WATCH_AFTER_END_S`] beyond (whether the robot stays up): the status stream as a
//! Fig. 6 trace, the simulator's truth, the dynamic gait's balance telemetry and, if asked, an
//! MCAP recording. `walkctl evaluate` and `walkctl demo` both walk through here.

use std::path::PathBuf;
use std::sync::Arc;
use std::time::{Duration, Instant};

use kinematics::robot::Robot;
use nalgebra::Isometry3;
use shm_types::{DaemonStatus, SimTruth};
use stance::PostProcessedSequence;

use super::WATCH_AFTER_END_S;
use super::telemetry::{AskedForce, StateChange, TelemetryRecorder};
use super::timing::PlannedPhase;
use super::truth::{TruthRecorder, Verdict, state_at};
use super::{BalanceSample, HandSample, Points, TraceSample, align_targets};
use crate::daemon_client::DaemonClient;
use crate::observe::channels::isometry;
use crate::observe::{Recorder, RecorderOutcome};

/// The longest wall time spent on [`WATCH_AFTER_END_S`]: a simulator that stops publishing
/// does not hold the watch up.
const WATCH_WALL_LIMIT: Duration = Duration::from_secs(60);

/// What to record besides the status stream and the simulator's truth.
pub(crate) struct WatchOptions<'a> {
    /// Record the walk (an observer beside walkd) to this MCAP file.
    pub record: Option<PathBuf>,
    /// Record walkd's telemetry: the dynamic gait's ZMP and DCM, the daemon's state changes, the
    /// planned phases and the hands in contact.
    pub telemetry: bool,
    /// How long the walk may take before it counts as stuck.
    pub timeout: Duration,
    /// Called with every status while the walk runs (e.g. a progress line).
    pub on_status: &'a dyn Fn(&DaemonStatus),
    /// Where the controller's world frame lies in the simulator's: the controller sets it up
    /// on the feet it stands on, the simulator puts the robot at a scene's start (identity on
    /// the flat floor). The trace's controller points and the stances' targets are mapped by it,
    /// so the drift, the footholds and the final position compare like with like.
    pub controller_frame: Isometry3<f64>,
}

/// What watching one walk recorded.
pub(crate) struct WatchedWalk {
    /// The status before submission: the walk's clock origin.
    pub start: DaemonStatus,
    /// The walk's last status.
    pub last: DaemonStatus,
    /// Wall time from submission to the end (s).
    pub wall_s: f64,
    /// Simulated time from submission to the walk's last status (s).
    pub sim_s: f64,
    /// Simulated time the robot was watched past the walk's last status (s; at least
    /// [`WATCH_AFTER_END_S`] unless the simulator stalled); `None` without its truth.
    pub watched_after_end_s: Option<f64>,
    /// Monotonic time of the submission (ns).
    pub submitted_ns: u64,
    /// Every state the simulator published meanwhile.
    pub states: Vec<SimTruth>,
    /// The simulator's verdict; `None` when no simulator published its truth (a real robot).
    pub verdict: Option<Verdict>,
    /// The stances' targets in the simulator's world (as the controller aligned the sequence,
    /// mapped by [`WatchOptions::controller_frame`]).
    pub targets: Vec<Points>,
    /// The walk's statuses as a Fig. 6 trace, with the simulator's truth where it pairs.
    pub trace: Vec<TraceSample>,
    /// When each status of the trace was written ([`shm_types::monotonic_ns`]).
    pub status_times: Vec<u64>,
    /// Largest controller-vs-simulator CoM or sole distance (m) and the statuses it is the
    /// maximum over; `None` when no status paired with a simulator state.
    pub drift: Option<(f64, usize)>,
    /// The ZMP and DCM telemetry, with [`WatchOptions::telemetry`].
    pub balance: Vec<BalanceSample>,
    /// The hands' vertical forces, asked and measured, with [`WatchOptions::telemetry`].
    pub hand_forces: Vec<HandSample>,
    /// The ticks at which the daemon's state changed, with [`WatchOptions::telemetry`].
    pub state_changes: Vec<StateChange>,
    /// The dynamic gait's planned support phases, with [`WatchOptions::telemetry`].
    pub(crate) phases: Vec<PlannedPhase>,
    /// Per stance index, whether each hand was in walkd's contact set, with
    /// [`WatchOptions::telemetry`] (`None` without).
    pub hands_held: Option<Vec<[bool; 2]>>,
    /// Per stance index, the force asked of the held hands while walkd held one, with
    /// [`WatchOptions::telemetry`] (empty without).
    pub(crate) hands_asked: Vec<AskedForce>,
    /// The recording, with [`WatchOptions::record`].
    pub recording: Option<RecorderOutcome>,
}

/// Submits `sequence` to the walkd `client` talks to on `prefix` and watches it to its end.
pub(crate) fn watch_walk(
    client: &DaemonClient,
    prefix: &str,
    robot: &Arc<Robot>,
    sequence: &PostProcessedSequence,
    options: &WatchOptions,
) -> anyhow::Result<WatchedWalk> {
    let observer = options
        .record
        .as_ref()
        .map(|file| Recorder::start(prefix, Arc::clone(robot), file))
        .transpose()?;
    let recorder = TruthRecorder::start(prefix)?;
    let telemetry = options
        .telemetry
        .then(|| TelemetryRecorder::start(prefix))
        .transpose()?;
    let start = client.status()?;
    let mut targets = super::stance_points(robot, sequence);
    align_targets(
        &mut targets,
        sequence,
        &[isometry(&start.left_foot), isometry(&start.right_foot)],
    );
    // Into the simulator's frame, where the footholds and Fig. 6 compare them with its truth.
    for target in &mut targets {
        *target = target.transformed(&options.controller_frame);
    }
    let wall = Instant::now();
    let submitted_ns = shm_types::monotonic_ns();
    let id = client.submit_json(&sequence.to_json_string())?;
    let (mut trace, mut status_times) = (Vec::new(), Vec::new());
    let last = client.wait_for_sequence(id, options.timeout, |status| {
        (options.on_status)(status);
        if status.sequence_id == id {
            let mut sample = sample(status, &start, &targets);
            sample.controller = sample.controller.transformed(&options.controller_frame);
            trace.push(sample);
            status_times.push(status.timestamp_ns);
        }
    })?;
    let wall_s = wall.elapsed().as_secs_f64();
    recorder.wait_for_sim_time(WATCH_AFTER_END_S, WATCH_WALL_LIMIT);
    let recording = observer.map(Recorder::finish).transpose()?;
    let states = recorder.finish()?;
    let (balance, state_changes, phases, hands_held, hands_asked, hand_forces) = match telemetry {
        Some(recorder) => {
            let recorded = recorder.finish(start.ticks, start.rate_hz)?;
            (
                recorded.samples,
                recorded.state_changes,
                recorded.phases,
                Some(recorded.hands_held),
                recorded.hands_asked,
                recorded.hand_forces,
            )
        }
        None => Default::default(),
    };
    let drift = pair_with_truth(&mut trace, &status_times, &states);
    // Simulated time from the submission to the tick of the last status: by the simulator's
    // clock where it published its truth (the ticks between the status read before submitting
    // and the submission are no part of the walk), else by walkd's ticks.
    let end = state_at(&states, last.timestamp_ns);
    let sim_s = match (state_at(&states, submitted_ns), end) {
        (Some(submitted), Some(end)) => end.sim_time_s - submitted.sim_time_s,
        _ => last.ticks.saturating_sub(start.ticks) as f64 / last.rate_hz,
    };
    let watched_after_end_s = end
        .zip(states.last())
        .map(|(end, newest)| newest.sim_time_s - end.sim_time_s);
    Ok(WatchedWalk {
        sim_s,
        watched_after_end_s,
        verdict: Verdict::of(&states, submitted_ns),
        start,
        last,
        wall_s,
        submitted_ns,
        states,
        targets,
        trace,
        status_times,
        drift,
        balance,
        hand_forces,
        state_changes,
        phases,
        hands_held,
        hands_asked,
        recording,
    })
}

/// The trace sample of `status`, timed from `start`, against the target of its stance.
fn sample(status: &DaemonStatus, start: &DaemonStatus, targets: &[Points]) -> TraceSample {
    let index = (status.stance_index as usize).min(targets.len() - 1);
    TraceSample {
        t: (status.ticks.saturating_sub(start.ticks)) as f64 / status.rate_hz,
        stance_index: status.stance_index,
        target: targets[index],
        controller: Points::from_status(&status.com, &status.left_foot, &status.right_foot),
        sim: None,
    }
}

/// Puts the simulator's state into every trace sample whose status (written at `status_times`)
/// pairs with one; returns the largest controller-vs-simulator distance of the CoM or a sole
/// and the number of paired samples, or `None` when none paired.
fn pair_with_truth(
    trace: &mut [TraceSample],
    status_times: &[u64],
    states: &[SimTruth],
) -> Option<(f64, usize)> {
    let mut drift: Option<(f64, usize)> = None;
    for (sample, &time) in trace.iter_mut().zip(status_times) {
        let Some(state) = state_at(states, time) else {
            continue;
        };
        let sim = Points::from_truth(state);
        let (com, feet) = sample.controller.distances(&sim);
        let (largest, samples) = drift.unwrap_or((0.0, 0));
        drift = Some((largest.max(com).max(feet), samples + 1));
        sample.sim = Some(sim);
    }
    drift
}
