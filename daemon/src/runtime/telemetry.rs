//! Fills the `telemetry` message of a control tick from the controller's
//! [`ControllerTelemetry`](crate::controller::ControllerTelemetry) (the loop adds its
//! bookkeeping). Allocation-free: it runs on the control thread, after the tick's command was sent.

use shm_types::{Code, DaemonState, Flag, SUPPORT_VERTICES, Telemetry, TimingSource, WalkPhase};
use stance::Gait;

use crate::controller::{BalanceStatus, ControllerStatus, ControllerTelemetry, Phase, PhaseTiming};

/// Writes the daemon's `state` and what the `controller` estimated and aimed at into `out`:
/// every field but the loop's bookkeeping (`seq` to `deadline_misses`, which the loop writes), so
/// a reused buffer keeps nothing stale.
pub(super) fn fill(out: &mut Telemetry, state: DaemonState, controller: &ControllerTelemetry) {
    let status = &controller.status;
    out.state = Code::new(state);
    out.phase = Code::new(wire_phase(status.phase));
    out.stance_index = status.stance_index;
    out.stance_count = status.stance_count;
    out.base = controller.base;
    out.com = status.com;
    out.end_effectors = controller.end_effectors;
    for (i, target) in controller.targets.iter().enumerate() {
        out.target_set[i] = Flag::new(target.is_some());
        out.targets[i] = target.unwrap_or(controller.end_effectors[i]);
        out.contacts[i] = Flag::new(status.contacts[i]);
    }
    out.com_target_set = Flag::new(controller.com_target.is_some());
    out.com_target = controller.com_target.unwrap_or([0.0; 2]);
    let vertices = controller.support.vertices();
    let count = vertices.len().min(SUPPORT_VERTICES);
    out.support[..count].copy_from_slice(&vertices[..count]);
    out.support[count..].fill([0.0; 2]);
    out.support_count = count as u32;
    let dynamic = controller.gait == Gait::Dynamic;
    let balance = if dynamic {
        status.balance
    } else {
        BalanceStatus::default()
    };
    out.dynamics_valid = Flag::new(dynamic);
    out.zmp_reference = balance.zmp_reference;
    out.zmp_measured = balance.zmp_measured;
    out.dcm_reference = balance.dcm_reference;
    out.dcm_measured = balance.dcm_measured;
    let (duration_s, timing) = planned_phase(status, dynamic);
    out.phase_duration_s = duration_s;
    out.phase_timing = Code::new(timing);
    out.hand_forces_desired = controller.hand_forces_desired;
}

/// The planned duration of the footstep-plan phase under way and its source; none outside one
/// (the static gait, not executing, settling).
fn planned_phase(status: &ControllerStatus, dynamic: bool) -> (f64, TimingSource) {
    let in_plan = matches!(
        status.phase,
        Phase::DoubleSupport | Phase::SingleSupport | Phase::LateTouchdown | Phase::LateLiftOff
    );
    match status.balance.planned_phase {
        Some(planned) if dynamic && in_plan => (planned.duration_s, wire_timing(planned.timing)),
        _ => (0.0, TimingSource::None),
    }
}

/// The wire code of a phase's timing source.
fn wire_timing(timing: PhaseTiming) -> TimingSource {
    match timing {
        PhaseTiming::Configured => TimingSource::Config,
        PhaseTiming::Sequence => TimingSource::Sequence,
        PhaseTiming::Clamped => TimingSource::Clamped,
    }
}

/// The wire code of a controller phase.
fn wire_phase(phase: Phase) -> WalkPhase {
    match phase {
        Phase::None => WalkPhase::None,
        Phase::ShiftCom => WalkPhase::ShiftCom,
        Phase::Unload => WalkPhase::Unload,
        Phase::Lift => WalkPhase::Lift,
        Phase::Swing => WalkPhase::Swing,
        Phase::Lower => WalkPhase::Lower,
        Phase::Reach => WalkPhase::Reach,
        Phase::Settle => WalkPhase::Settle,
        Phase::DoubleSupport => WalkPhase::DoubleSupport,
        Phase::SingleSupport => WalkPhase::SingleSupport,
        Phase::LateTouchdown => WalkPhase::LateTouchdown,
        Phase::LateLiftOff => WalkPhase::LateLiftOff,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_phase_has_the_wire_code_of_its_name() {
        for phase in [
            Phase::None,
            Phase::ShiftCom,
            Phase::Unload,
            Phase::Lift,
            Phase::Swing,
            Phase::Lower,
            Phase::Reach,
            Phase::Settle,
            Phase::DoubleSupport,
            Phase::SingleSupport,
            Phase::LateTouchdown,
            Phase::LateLiftOff,
        ] {
            assert_eq!(wire_phase(phase).name(), phase.name());
        }
    }

    #[test]
    fn every_timing_has_the_wire_code_of_its_name() {
        for timing in [
            PhaseTiming::Configured,
            PhaseTiming::Sequence,
            PhaseTiming::Clamped,
        ] {
            assert_eq!(wire_timing(timing).name(), timing.name());
        }
    }

    #[test]
    fn a_planned_phase_shows_only_while_the_dynamic_gait_walks_it() {
        let mut status = ControllerStatus {
            phase: Phase::SingleSupport,
            ..ControllerStatus::default()
        };
        status.balance.planned_phase = Some(Default::default());
        status.balance.planned_phase.as_mut().unwrap().duration_s = 0.8;
        assert_eq!(planned_phase(&status, true), (0.8, TimingSource::Config));
        assert_eq!(planned_phase(&status, false), (0.0, TimingSource::None));
        status.phase = Phase::Settle;
        assert_eq!(planned_phase(&status, true), (0.0, TimingSource::None));
    }
}
