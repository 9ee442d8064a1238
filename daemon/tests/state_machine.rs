//! State-machine behaviour in closed loop with the kinematic simulator: touchdown never
//! confirmed, force-torque spikes, abort in every phase, faults on bad input, restart.

mod walk_support;

use daemon::controller::{CommandMode, ControllerState, FaultCode, Phase};
use kinematics::robot::EndEffector;
use walk_support::Harness;

const RATE_HZ: f64 = 200.0;
/// Enough ticks for any phase of the synthetic walk (its phases last a few seconds).
const MAX_TICKS: usize = 20_000;

fn started(robot: &str, hand: bool) -> Harness {
    let mut h = Harness::new(robot, RATE_HZ);
    let sequence = walk_support::synthetic_walk(&h.robot, 2, 0.08, hand);
    h.start(&sequence);
    h
}

/// Ticks until `phase` is current (panics if the walk ends or faults first).
fn run_until(h: &mut Harness, phase: Phase) {
    for _ in 0..MAX_TICKS {
        h.tick();
        h.assert_safe();
        let status = h.controller.status();
        assert_eq!(status.state, ControllerState::Executing, "{status:?}");
        if status.phase == phase {
            return;
        }
    }
    panic!("phase {phase:?} never reached");
}

#[test]
fn touchdown_never_confirmed_is_a_lower_timeout_fault() {
    let mut h = started("jvrc1", false);
    run_until(&mut h, Phase::Lower);
    // The force-torque sensor of the landing (right) foot reads nothing from now on.
    let mut ticks = 0;
    while h.controller.status().state == ControllerState::Executing && ticks < MAX_TICKS {
        h.tick_with(|w| w[EndEffector::RightFoot as usize] = [0.0; 6]);
        ticks += 1;
    }
    let status = *h.controller.status();
    assert_eq!(status.state, ControllerState::Fault);
    assert_eq!(status.fault, FaultCode::Timeout(Phase::Lower));
    assert!(
        !status.contacts[EndEffector::RightFoot as usize],
        "contact never confirmed"
    );
    assert_eq!(h.command.mode, CommandMode::Hold);
    let held = h.command.q_des.clone();
    for _ in 0..50 {
        h.tick_with(|w| w[EndEffector::RightFoot as usize] = [0.0; 6]);
        assert_eq!(h.command.q_des, held, "a fault holds the last safe command");
    }
    h.assert_safe();
}

#[test]
fn force_spikes_while_swinging_or_above_the_ground_are_not_touchdowns() {
    let mut h = started("jvrc1", false);
    run_until(&mut h, Phase::Swing);
    // A sustained spike on the swinging foot: ignored outside the lowering phase.
    let spike = 2.0 * h.robot.model.total_mass() * kinematic_sim::GRAVITY;
    for _ in 0..20 {
        h.tick_with(|w| w[EndEffector::RightFoot as usize][2] = spike);
        h.assert_safe();
        assert_eq!(h.controller.status().phase, Phase::Swing);
        assert!(!h.controller.status().contacts[EndEffector::RightFoot as usize]);
    }
    run_until(&mut h, Phase::Lower);
    // Single-tick spikes while lowering, before the sole reaches the ground: debounced away.
    for k in 0..30 {
        let foot_in_air = !h.sim.measurement().contacts[EndEffector::RightFoot as usize];
        assert!(foot_in_air, "the sole is still above the ground");
        if k % 2 == 0 {
            h.tick_with(|w| w[EndEffector::RightFoot as usize][2] = spike);
        } else {
            h.tick();
        }
        assert_eq!(h.controller.status().phase, Phase::Lower);
        assert!(!h.controller.status().contacts[EndEffector::RightFoot as usize]);
    }
    // The real touchdown is confirmed and the walk finishes.
    for _ in 0..MAX_TICKS {
        h.tick();
        h.assert_safe();
        if h.controller.status().state != ControllerState::Executing {
            break;
        }
    }
    assert_eq!(h.controller.status().state, ControllerState::Done);
}

#[test]
fn abort_in_every_phase_holds_safely_and_a_new_sequence_can_start() {
    for phase in [
        Phase::ShiftCom,
        Phase::Reach,
        Phase::Unload,
        Phase::Lift,
        Phase::Swing,
        Phase::Lower,
        Phase::Settle,
    ] {
        let mut h = started("jvrc1", true);
        run_until(&mut h, phase);
        for _ in 0..5 {
            h.tick();
        }
        h.controller.abort();
        assert_eq!(
            h.controller.status().state,
            ControllerState::Holding,
            "{phase:?}"
        );
        h.tick();
        let held = h.command.q_des.clone();
        for _ in 0..200 {
            h.tick();
            h.assert_safe();
            assert_eq!(h.command.mode, CommandMode::Hold, "{phase:?}");
            assert_eq!(
                h.command.q_des, held,
                "{phase:?}: holding keeps the posture"
            );
            assert_eq!(h.controller.status().state, ControllerState::Holding);
        }
        // From Holding, a new sequence (from wherever the robot stands) runs to the end.
        let sequence = walk_support::synthetic_walk(&h.robot, 2, 0.05, false);
        h.start(&sequence);
        for _ in 0..MAX_TICKS {
            h.tick();
            h.assert_safe();
            if h.controller.status().state != ControllerState::Executing {
                break;
            }
        }
        assert_eq!(
            h.controller.status().state,
            ControllerState::Done,
            "{phase:?}: {:?}",
            h.controller.status()
        );
    }
}

#[test]
fn start_is_refused_while_executing_and_in_fault_until_reset() {
    let mut h = started("jvrc1", false);
    h.tick();
    let config = walk_support::controller_config("jvrc1");
    let sequence = walk_support::synthetic_walk(&h.robot, 1, 0.05, false);
    let prepared = daemon::controller::Controller::prepare(&h.robot, &config, &sequence).unwrap();
    let refused = h.controller.start(Box::new(prepared)).unwrap_err();
    // A non-finite measurement faults the controller; it then refuses until reset.
    let q: Vec<f64> = h.sim.measurement().q.iter().map(|_| f64::NAN).collect();
    let measurement = daemon::controller::Measurement {
        q: &q,
        qd: h.sim.measurement().qd.as_slice(),
        wrenches: &h.sim.measurement().wrenches,
        imu_orientation: None,
    };
    let before = h.command.q_des.clone();
    h.controller.tick(&measurement, h.dt, &mut h.command);
    assert_eq!(h.controller.status().state, ControllerState::Fault);
    assert_eq!(h.controller.status().fault, FaultCode::InvalidMeasurement);
    assert_eq!(h.command.q_des, before, "holds the last safe command");
    assert_eq!(h.command.mode, CommandMode::Hold);
    let refused = h.controller.start(refused).unwrap_err();
    h.controller.reset();
    assert_eq!(h.controller.status().state, ControllerState::Holding);
    assert!(h.controller.start(refused).is_ok());
    for _ in 0..MAX_TICKS {
        h.tick();
        h.assert_safe();
        if h.controller.status().state != ControllerState::Executing {
            break;
        }
    }
    assert_eq!(h.controller.status().state, ControllerState::Done);
}

#[test]
fn sequences_with_an_overlong_step_or_another_robot_are_refused() {
    let robot = walk_support::robot("jvrc1");
    let config = walk_support::controller_config("jvrc1");
    let long = walk_support::synthetic_walk(&robot, 2, config.max_step_m + 0.05, false);
    let refusal = daemon::controller::Controller::prepare(&robot, &config, &long).unwrap_err();
    assert!(refusal.to_string().contains("max_step_m"), "{refusal}");
    let armar = walk_support::robot("armar4");
    let other = walk_support::synthetic_walk(&armar, 1, 0.05, false);
    assert!(daemon::controller::Controller::prepare(&robot, &config, &other).is_err());
}

#[test]
fn an_imu_that_disagrees_with_leg_odometry_is_a_tipping_fault_that_holds() {
    let mut h = started("jvrc1", false);
    for _ in 0..50 {
        h.tick();
    }
    assert_eq!(h.controller.status().state, ControllerState::Executing);
    let config = walk_support::controller_config("jvrc1");
    let m = h.sim.measurement().clone();
    // The IMU reports the base rolled just under, then just over, the detection angle.
    let roll = |angle: f64| {
        nalgebra::UnitQuaternion::from_euler_angles(angle, 0.0, 0.0) * m.base_orientation
    };
    for (angle, tipping) in [
        (0.9 * config.tipping_detection_rad, false),
        (1.1 * config.tipping_detection_rad, true),
    ] {
        let measurement = daemon::controller::Measurement {
            q: m.q.as_slice(),
            qd: m.qd.as_slice(),
            wrenches: &m.wrenches,
            imu_orientation: Some(roll(angle)),
        };
        let before = h.command.q_des.clone();
        h.controller.tick(&measurement, h.dt, &mut h.command);
        if tipping {
            assert_eq!(h.controller.status().state, ControllerState::Fault);
            assert_eq!(h.controller.status().fault, FaultCode::Tipping);
            assert_eq!(h.command.q_des, before, "holds the last command");
            assert_eq!(h.command.mode, CommandMode::Hold);
        } else {
            assert_eq!(h.controller.status().state, ControllerState::Executing);
        }
    }
}
