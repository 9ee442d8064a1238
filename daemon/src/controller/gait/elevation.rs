//! The elevation the pendulum stands on, over the plan: what the CoM height is measured from
//! when the walk climbs or descends (stairs, ramps).
//!
//! Each phase's support elevation is the mean height of its planned feet on the ground. During a
//! phase the elevation moves linearly from its own to the next phase's, so the CoM rises (or
//! sinks) steadily over every step instead of jumping at each contact change: a stair's rise is
//! spread over the single support before the touchdown on it and the double support after. On
//! flat ground every phase is at the same elevation and the CoM height is constant.

use super::footsteps::SupportPhase;

/// The support elevation (world z, m) and its rate (m/s) at `clock` (s, plan clock) in phase
/// `phase`; after the last phase, the last phase's elevation at rest. Reads the phases as they
/// are, so a plan cut short by a stop ends at its new last phase.
pub(crate) fn support_elevation(phases: &[SupportPhase], phase: usize, clock: f64) -> (f64, f64) {
    let Some(current) = phases.get(phase) else {
        return (phases.last().map_or(0.0, elevation), 0.0);
    };
    let from = elevation(current);
    let to = phases.get(phase + 1).map_or(from, elevation);
    let progress = ((clock - current.start_s) / current.duration_s).clamp(0.0, 1.0);
    let rate = if (0.0..1.0).contains(&progress) {
        (to - from) / current.duration_s
    } else {
        0.0
    };
    (from + (to - from) * progress, rate)
}

/// Mean height of a phase's planned feet on the ground.
fn elevation(phase: &SupportPhase) -> f64 {
    let (sum, count) = phase
        .feet
        .iter()
        .flatten()
        .fold((0.0, 0.0), |(sum, n), foot| {
            (sum + foot.translation.z, n + 1.0)
        });
    if count > 0.0 { sum / count } else { 0.0 }
}

#[cfg(test)]
mod tests {
    use nalgebra::Isometry3;

    use super::*;
    use crate::controller::gait::footsteps::Support;

    fn phase(start_s: f64, feet: [Option<f64>; 2]) -> SupportPhase {
        SupportPhase {
            support: Support::Double { lift_off: None },
            start_s,
            duration_s: 1.0,
            feet: feet.map(|z| z.map(|z| Isometry3::translation(0.0, 0.0, z))),
            timing: crate::controller::status::PhaseTiming::Configured,
        }
    }

    #[test]
    fn the_elevation_climbs_steadily_through_each_phase() {
        // Both feet on the floor, one on the floor, then one on a 0.1 m step.
        let phases = [
            phase(0.0, [Some(0.0), Some(0.0)]),
            phase(1.0, [Some(0.0), None]),
            phase(2.0, [Some(0.0), Some(0.1)]),
        ];
        assert_eq!(support_elevation(&phases, 0, 0.5), (0.0, 0.0));
        let (z, rate) = support_elevation(&phases, 1, 1.5);
        assert!((z - 0.025).abs() < 1e-12 && (rate - 0.05).abs() < 1e-12);
        // The last phase holds its elevation, also after it ends.
        assert_eq!(support_elevation(&phases, 2, 2.5), (0.05, 0.0));
        assert_eq!(support_elevation(&phases, 3, 9.0), (0.05, 0.0));
    }

    #[test]
    fn flat_ground_is_one_constant_elevation() {
        let phases = [
            phase(0.0, [Some(0.0), Some(0.0)]),
            phase(1.0, [None, Some(0.0)]),
        ];
        for (p, t) in [(0, 0.0), (0, 0.7), (1, 1.2), (2, 5.0)] {
            assert_eq!(support_elevation(&phases, p, t), (0.0, 0.0));
        }
    }
}
