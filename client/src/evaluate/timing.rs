//! The dynamic gait's timing as walkd's telemetry showed it: each planned single- and
//! double-support phase, its duration and where that duration came from (the sequence's stance
//! durations, those moved into the config's limits, or the config), so a run shows whether its
//! step times came from the sequence.

use serde::Serialize;
use shm_types::{Telemetry, TimingSource, WalkPhase};

/// One planned phase of the dynamic gait.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct PlannedPhase {
    /// Single or double support.
    pub phase: WalkPhase,
    /// Its planned duration (s).
    pub duration_s: f64,
    /// Where the duration came from.
    pub timing: TimingSource,
}

impl PlannedPhase {
    /// The planned phase a tick's telemetry shows, if it is in a support phase of the plan.
    pub(crate) fn of(telemetry: &Telemetry) -> Option<Self> {
        let phase = telemetry.phase.get().ok()?;
        let timing = telemetry.phase_timing.get().ok()?;
        let support = matches!(phase, WalkPhase::SingleSupport | WalkPhase::DoubleSupport);
        (support && timing != TimingSource::None).then_some(Self {
            phase,
            duration_s: telemetry.phase_duration_s,
            timing,
        })
    }
}

/// The phases of a walk summed up: how many took their duration from where, and the median
/// planned single and double support.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct TimingReport {
    /// Phases timed by the sequence as it gave them.
    pub from_sequence: usize,
    /// Phases timed by the sequence, moved into the config's limits.
    pub clamped: usize,
    /// Phases timed by the config.
    pub from_config: usize,
    /// Median planned single support (s); `None` without one.
    pub single_support_s: Option<f64>,
    /// Median planned double support between steps (s: the first and last, from and to rest,
    /// left out); `None` without one.
    pub double_support_s: Option<f64>,
}

impl TimingReport {
    /// The report on `phases` in the order the walk went through them; `None` without any.
    pub(crate) fn of(phases: &[PlannedPhase]) -> Option<Self> {
        if phases.is_empty() {
            return None;
        }
        let count = |timing| phases.iter().filter(|p| p.timing == timing).count();
        let median_of = |phase, phases: &[PlannedPhase]| {
            let mut durations: Vec<f64> = phases
                .iter()
                .filter(|p| p.phase == phase)
                .map(|p| p.duration_s)
                .collect();
            durations.sort_by(f64::total_cmp);
            durations.get(durations.len() / 2).copied()
        };
        let between = phases.get(1..phases.len() - 1).unwrap_or(&[]);
        Some(Self {
            from_sequence: count(TimingSource::Sequence),
            clamped: count(TimingSource::Clamped),
            from_config: count(TimingSource::Config),
            single_support_s: median_of(WalkPhase::SingleSupport, phases),
            double_support_s: median_of(WalkPhase::DoubleSupport, between),
        })
    }

    /// One line for the run row, e.g. `timing 28 sequence, 3 clamped, 2 config, SS 0.48 s, DS
    /// 0.30 s`.
    pub fn describe(&self) -> String {
        let seconds = |s: Option<f64>| s.map_or_else(|| "-".to_owned(), |s| format!("{s:.2} s"));
        format!(
            "timing {} sequence, {} clamped, {} config, SS {}, DS {}",
            self.from_sequence,
            self.clamped,
            self.from_config,
            seconds(self.single_support_s),
            seconds(self.double_support_s)
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn phase(phase: WalkPhase, duration_s: f64, timing: TimingSource) -> PlannedPhase {
        PlannedPhase {
            phase,
            duration_s,
            timing,
        }
    }

    #[test]
    fn a_walk_counts_its_phases_by_source_and_takes_the_medians_between_rest() {
        use TimingSource::{Clamped, Config, Sequence};
        use WalkPhase::{DoubleSupport as Ds, SingleSupport as Ss};
        let phases = [
            phase(Ds, 1.0, Config),
            phase(Ss, 0.5, Sequence),
            phase(Ds, 0.3, Sequence),
            phase(Ss, 0.55, Clamped),
            phase(Ds, 0.2, Sequence),
            phase(Ss, 0.6, Sequence),
            phase(Ds, 1.0, Config),
        ];
        let report = TimingReport::of(&phases).unwrap();
        assert_eq!(
            (report.from_sequence, report.clamped, report.from_config),
            (4, 1, 2)
        );
        assert_eq!(report.single_support_s, Some(0.55));
        // The double supports from and to rest (1.0 s) are left out: 0.2 and 0.3 remain.
        assert_eq!(report.double_support_s, Some(0.3));
        assert!(TimingReport::of(&[]).is_none());
    }

    #[test]
    fn only_planned_support_phases_are_phases() {
        let mut telemetry = Telemetry::ZERO;
        telemetry.phase = WalkPhase::Settle.into();
        telemetry.phase_timing = TimingSource::Config.into();
        assert_eq!(PlannedPhase::of(&telemetry), None);
        telemetry.phase = WalkPhase::SingleSupport.into();
        telemetry.phase_duration_s = 0.5;
        assert_eq!(
            PlannedPhase::of(&telemetry),
            Some(phase(WalkPhase::SingleSupport, 0.5, TimingSource::Config))
        );
        telemetry.phase_timing = TimingSource::None.into();
        assert_eq!(PlannedPhase::of(&telemetry), None);
    }
}
