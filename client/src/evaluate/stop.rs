//! Faults injected into the walks of `walkctl evaluate --inject` and the verdict on how each walk
//! stopped: a fault mid-step must end with the robot standing on both feet, not fallen, its
//! controlled stop over within [`STOP_WITHIN_S`] (docs/safety.md, "Controlled stop").
//!
//! `walk-sim --inject` injects the fault `delay` seconds of simulated time after the walk's
//! `--inject-step`-th lift-off, the delay a fraction of `[gait.dynamic] single_support_s`
//! ([`Moment`]). The stop is timed by walkd itself, to the tick: its status's `stop_s`, the control
//! periods from the fault or request that began the controlled stop to rest (zero for a gait that
//! holds at once). The simulator's truth says whether the robot fell and where its feet ended.

use std::ffi::OsString;

use kinematics::ConfigFile;
use shm_types::process::InjectedFault;
use shm_types::{DaemonState, SimTruth};

use super::telemetry::StateChange;
use super::truth::state_at;
use super::watch::WatchedWalk;

/// A controlled stop must be over this long after it began (simulated s).
pub const STOP_WITHIN_S: f64 = 2.0;

/// A sole counts as down when it ends within this of its height at submission (m).
const FOOT_DOWN_M: f64 = 0.02;

/// When in the single support a fault comes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Moment {
    /// 15 % into the single support.
    Early,
    /// Half way.
    Mid,
    /// 80 % into it (before the earliest accepted touchdown at the usual timings).
    Late,
}

impl Moment {
    /// The fraction of the single support.
    pub fn fraction(self) -> f64 {
        match self {
            Self::Early => 0.15,
            Self::Mid => 0.5,
            Self::Late => 0.8,
        }
    }

    /// Lower-case name.
    pub fn name(self) -> &'static str {
        match self {
            Self::Early => "early",
            Self::Mid => "mid",
            Self::Late => "late",
        }
    }
}

/// `walkctl evaluate`'s fault injection.
#[derive(Debug, Clone, clap::Args)]
pub struct InjectArgs {
    /// Inject each of these faults into every walk (each its own run): nan, joint-out-of-limits,
    /// zero-force, force-dropout, hold, abort, withheld-touchdown. Then a run succeeds when the
    /// robot ends standing on both feet, not fallen, its stop over within 2 s (after one
    /// zero-force sample, which physics produces too, the walk may also go on to its end).
    #[arg(long, value_delimiter = ',')]
    pub inject: Vec<InjectedFault>,
    /// When in the single support: early, mid, late (15, 50, 80 % of `[gait.dynamic]
    /// single_support_s`).
    #[arg(long, value_delimiter = ',', default_value = "early,mid,late")]
    pub inject_at: Vec<Moment>,
    /// The lift-off of a foot the fault follows (1: the walk's first step).
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(1..=1000))]
    pub inject_step: u32,
}

/// One fault injected into one walk.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Injection {
    /// What goes wrong.
    pub fault: InjectedFault,
    /// When in the single support.
    pub moment: Moment,
    /// After which lift-off.
    pub step: u32,
    /// How long after it (s).
    pub delay_s: f64,
}

impl Injection {
    /// `walk-sim`'s arguments for it.
    pub fn sim_args(&self) -> [OsString; 6] {
        [
            "--inject".into(),
            self.fault.name().into(),
            "--inject-step".into(),
            self.step.to_string().into(),
            "--inject-delay".into(),
            format!("{}", self.delay_s).into(),
        ]
    }

    /// `fault@moment`, for tables.
    pub fn label(&self) -> String {
        format!("{}@{}", self.fault.name(), self.moment.name())
    }
}

impl InjectArgs {
    /// The injections to try on each walk of a robot with config `file`: `[None]` without
    /// `--inject`, else every fault at every moment.
    pub fn injections(&self, file: &ConfigFile) -> anyhow::Result<Vec<Option<Injection>>> {
        if self.inject.is_empty() {
            return Ok(vec![None]);
        }
        anyhow::ensure!(
            !self.inject_at.is_empty(),
            "--inject-at needs at least one of early, mid, late"
        );
        let single_support_s = single_support_s(file)?;
        Ok(self
            .inject
            .iter()
            .flat_map(|&fault| {
                self.inject_at.iter().map(move |&moment| {
                    Some(Injection {
                        fault,
                        moment,
                        step: self.inject_step,
                        delay_s: moment.fraction() * single_support_s,
                    })
                })
            })
            .collect())
    }
}

/// `[gait.dynamic] single_support_s` of a robot config.
fn single_support_s(file: &ConfigFile) -> anyhow::Result<f64> {
    file.section("gait")
        .and_then(|gait| gait.get("dynamic"))
        .and_then(|dynamic| dynamic.get("single_support_s"))
        .and_then(|value| value.as_float())
        .filter(|s| s.is_finite() && *s > 0.0)
        .ok_or_else(|| {
            anyhow::anyhow!(
                "{}: --inject times its faults by [gait.dynamic] single_support_s, which it does \
                 not set",
                file.origin()
            )
        })
}

/// How a walk with an injected fault stopped.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StopReport {
    /// The fault.
    pub injection: Injection,
    /// walkd's time from the fault or request to the end of its controlled stop (s; 0: it held at
    /// once); `None` when the walk went on to its end.
    pub stop_s: Option<f64>,
    /// The daemon's state at the end.
    pub ended: DaemonState,
    /// Both simulated soles ended within [`FOOT_DOWN_M`] of their heights at submission.
    pub feet_down: bool,
    /// The simulator's fall rule fired.
    pub fell: bool,
    /// Largest `base_link` tilt from the vertical from the stop on (rad).
    pub max_tilt_rad: f64,
}

impl StopReport {
    /// The robot ended standing on both feet, not fallen, holding, its stop over in time; or,
    /// for a fault walkd need not stop for, it walked on to the end.
    pub fn success(&self) -> bool {
        let stopped = self.stop_s.is_some_and(|s| s <= STOP_WITHIN_S)
            && matches!(self.ended, DaemonState::Holding | DaemonState::Fault);
        let walked_on = !self.injection.fault.must_stop() && self.ended == DaemonState::Done;
        (stopped || walked_on) && self.feet_down && !self.fell
    }

    /// One line: the stop's time, tilt and end.
    pub fn describe(&self) -> String {
        format!(
            "{}: {} {} tilt {:.3} rad, {}{}",
            self.injection.label(),
            if self.success() { "ok" } else { "FAIL" },
            self.stop_s
                .map_or_else(|| "walked on".to_owned(), |s| format!("stop {s:.2} s")),
            self.max_tilt_rad,
            self.ended.name(),
            match (self.fell, self.feet_down) {
                (true, _) => ", fell",
                (false, false) => ", not on both feet",
                _ => "",
            }
        )
    }
}

/// Judges `walk`, into which `injection` was injected.
pub(crate) fn judge(injection: Injection, walk: &WatchedWalk) -> StopReport {
    let ended = walk.last.state.get().unwrap_or(DaemonState::Executing);
    let stopped = matches!(ended, DaemonState::Holding | DaemonState::Fault);
    let faulted_at =
        first_state_after(&walk.state_changes, DaemonState::Executing).unwrap_or(walk.submitted_ns);
    let after: Vec<&SimTruth> = walk
        .states
        .iter()
        .filter(|s| s.timestamp_ns >= faulted_at)
        .collect();
    let at_submission = state_at(&walk.states, walk.submitted_ns).or(walk.states.first());
    let feet_down = match (at_submission, walk.states.last()) {
        (Some(start), Some(end)) => {
            (end.left_foot[2] - start.left_foot[2]).abs() <= FOOT_DOWN_M
                && (end.right_foot[2] - start.right_foot[2]).abs() <= FOOT_DOWN_M
        }
        _ => false,
    };
    StopReport {
        injection,
        stop_s: stopped.then_some(walk.last.stop_s),
        ended,
        feet_down,
        fell: walk.states.last().is_some_and(|s| s.fallen.is_set()),
        max_tilt_rad: after.iter().map(|s| s.tilt_rad).fold(0.0, f64::max),
    }
}

/// The sample time (ns) of the first tick after one in `state` that was in another state: when
/// the walk left `executing`.
fn first_state_after(changes: &[StateChange], state: DaemonState) -> Option<u64> {
    changes
        .windows(2)
        .find(|w| w[0].state == state && w[1].state != state)
        .map(|w| w[1].sample_timestamp_ns)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn change(tick: u64, state: DaemonState) -> StateChange {
        StateChange {
            tick,
            sample_timestamp_ns: tick * 1000,
            state,
        }
    }

    #[test]
    fn the_walk_left_executing_at_its_first_other_state() {
        let changes = [
            change(1, DaemonState::Holding),
            change(5, DaemonState::Executing),
            change(90, DaemonState::ControlledStop),
            change(700, DaemonState::Fault),
        ];
        let left = first_state_after(&changes, DaemonState::Executing);
        assert_eq!(left, Some(90_000));
        let walking = [change(5, DaemonState::Executing)];
        assert_eq!(first_state_after(&walking, DaemonState::Executing), None);
    }
}
