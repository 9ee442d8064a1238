//! The controller walks without falling under rigid-body physics: `daemon::controller` in closed
//! loop with MuJoCo (`walk_tests::physics`), 500 Hz control, 1 ms physics steps, measurement
//! from the simulated FT sensors, joint encoders and IMU. Each test walks 1 m forward for one
//! robot and affordance set and requires `done` with no fall (base height, torso tilt), the
//! feet on their final targets, and the controller's estimate close to the simulator's truth.
//!
//! KNOWN FAILURE (issue 6): every walk below topples today. The controller integrates its
//! command from the measured joint angle, so a loaded joint gets no holding torque from the
//! position servo; see docs/evaluation.md for the diagnosis and the fix under way. The walks are
//! therefore `#[ignore]`d (cargo reports them as ignored, never as passed); run them with
//! `cargo test --release -p walk-tests --features mujoco --test physics_walk -- --ignored`.
//!
//! Needs the `mujoco` feature of walk-tests (scripts/test.sh enables it). Built without it, the
//! single test below fails and says how to enable it: a physics check that compiled to nothing
//! would otherwise pass silently.

#[cfg(not(feature = "mujoco"))]
#[test]
fn physics_walk_needs_the_mujoco_feature() {
    panic!(
        "walk-tests was built without its `mujoco` feature, so the physics walks did not run: \
         eval \"$(scripts/setup-mujoco.sh)\" and test with --features walk-tests/mujoco \
         (scripts/test.sh does both)"
    );
}

#[cfg(feature = "mujoco")]
mod walks {
    use client::evaluate::write_fig6;
    use stance::AffordanceSet;
    use walk_tests::config;
    use walk_tests::physics::{PhysicsWalkOptions, PhysicsWalkReport, walk_distance};

    /// The walk must end with each simulated sole this close to its final target (m).
    const MAX_FINAL_POSITION_ERROR_M: f64 = 0.03;
    /// The controller's CoM / sole estimate must stay this close to the simulator's truth (m).
    const MAX_DRIFT_M: f64 = 0.05;
    /// Forward distance walked (m).
    const DISTANCE_M: f64 = 1.0;

    /// Walks and writes the run's Fig. 6 (target / controller / simulator) to
    /// `target/tmp/fig6_<robot>_<affordances>.svg`.
    fn walk(robot: &str, affordances: AffordanceSet) -> PhysicsWalkReport {
        let options = PhysicsWalkOptions::default();
        let report = walk_distance(&config(robot), None, DISTANCE_M, affordances, 0, &options)
            .unwrap_or_else(|e| panic!("{robot} {}: {e:#}", affordances.name()));
        let plot = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
            .join(format!("fig6_{robot}_{}.svg", affordances.name()));
        let title = format!(
            "{robot}, {DISTANCE_M} m, {}, in-process MuJoCo ({})",
            affordances.name(),
            report.outcome.label()
        );
        write_fig6(&plot, &title, &report.trace).expect("writing Fig. 6");
        eprintln!(
            "{robot} {} {DISTANCE_M} m: {} after {} stances, sim {:.2} s, wall {:.2} s \
             (controller {:.2} s, physics {:.2} s), final position error {:.4} m, drift CoM \
             {:.4} m feet {:.4} m, walked {:.3} m, max slip {:.4} m, max tilt {:.3} rad, \
             real-time factor {:.1}",
            affordances.name(),
            report.outcome.label(),
            report.stances,
            report.sim_s,
            report.wall_s,
            report.controller_s,
            report.physics_s,
            report.final_position_error_m,
            report.max_com_drift_m,
            report.max_foot_drift_m,
            report.distance_m,
            report.max_contact_slip_m,
            report.max_tilt_rad,
            report.real_time_factor(),
        );
        report
    }

    fn check(robot: &str, affordances: AffordanceSet) {
        let report = walk(robot, affordances);
        let name = format!("{robot} {}", affordances.name());
        assert!(
            report.success(),
            "{name}: ended `{}` ({:?}) at {:.2} s simulated, stance {} of {}",
            report.outcome.label(),
            report.outcome,
            report.sim_s,
            report.stance_reached,
            report.stances
        );
        assert!(
            report.final_position_error_m < MAX_FINAL_POSITION_ERROR_M,
            "{name}: a sole ended {:.4} m from its final target",
            report.final_position_error_m
        );
        assert!(
            report.drift_m() < MAX_DRIFT_M,
            "{name}: controller estimate drifted {:.4} m (CoM) / {:.4} m (soles) from the simulator",
            report.max_com_drift_m,
            report.max_foot_drift_m
        );
        assert!(
            report.distance_m > 0.8 * DISTANCE_M,
            "{name}: the feet moved only {:.3} m",
            report.distance_m
        );
    }

    #[test]
    #[ignore = "known failure, issue 6: the controller does not yet walk under MuJoCo physics"]
    fn jvrc1_walks_1m_feet_only() {
        check("jvrc1", AffordanceSet::Feet);
    }

    #[test]
    #[ignore = "known failure, issue 6: the controller does not yet walk under MuJoCo physics"]
    fn jvrc1_walks_1m_with_left_hand() {
        check("jvrc1", AffordanceSet::FeetLeftHand);
    }

    #[test]
    #[ignore = "known failure, issue 6: the controller does not yet walk under MuJoCo physics"]
    fn jvrc1_walks_1m_with_right_hand() {
        check("jvrc1", AffordanceSet::FeetRightHand);
    }

    #[test]
    #[ignore = "known failure, issue 6: the controller does not yet walk under MuJoCo physics"]
    fn armar4_walks_1m_feet_only() {
        check("armar4", AffordanceSet::Feet);
    }

    #[test]
    #[ignore = "known failure, issue 6: the controller does not yet walk under MuJoCo physics"]
    fn armar4_walks_1m_with_left_hand() {
        check("armar4", AffordanceSet::FeetLeftHand);
    }

    #[test]
    #[ignore = "known failure, issue 6: the controller does not yet walk under MuJoCo physics"]
    fn armar4_walks_1m_with_right_hand() {
        check("armar4", AffordanceSet::FeetRightHand);
    }
}
