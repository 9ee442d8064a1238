//! State-machine behaviour in closed loop with the kinematic simulator: touchdown never
//! confirmed, force-torque spikes, abort in every phase, faults on bad input, restart.

mod walk_support;

use daemon::controller::{
    CommandMode, ControllerConfig, ControllerState, FaultCode, MeasurementFault, Phase,
    StartRefusal,
};
use kinematic_sim::Simulator;
use kinematics::robot::EndEffector;
use walk_support::Harness;

const RATE_HZ: f64 = 200.0;
/// Enough ticks for any phase of the synthetic walk (its phases last a few seconds).
const MAX_TICKS: usize = 20_000;

fn started(robot: &str, hand: bool) -> Harness {
    start(Harness::new(robot, RATE_HZ), hand)
}

/// `h` walking the two-step synthetic walk.
fn start(mut h: Harness, hand: bool) -> Harness {
    let sequence = walk_support::synthetic_walk(&h.robot, 2, 0.08, hand);
    h.start(&sequence);
    h
}

/// Ticks until `phase` is current (panics if the walk ends or faults first).
fn run_until(h: &mut Harness, phase: Phase) {
    for _ in 0..MAX_TICKS {
        h.tick();
        h.assert_safe();
        let status = h.closed.controller.status();
        assert_eq!(status.state, ControllerState::Executing, "{status:?}");
        if status.phase == phase {
            return;
        }
    }
    panic!("phase {phase:?} never reached");
}

/// Ticks the walk to `done`, safe and executing on every tick, calling `observe` after each
/// executing tick.
fn walk_to_done(h: &mut Harness, mut observe: impl FnMut(&Harness)) {
    for _ in 0..MAX_TICKS {
        h.tick();
        h.assert_safe();
        let status = h.closed.controller.status();
        if status.state == ControllerState::Done {
            return;
        }
        assert_eq!(status.state, ControllerState::Executing, "{status:?}");
        observe(h);
    }
    panic!("the walk did not end in {MAX_TICKS} ticks");
}

/// The landing foot's sensor is dead. The kinematic simulator then puts most of the weight on
/// that foot, so with the default `support_force_min_fraction` the feet read as unloaded first
/// (the next test); here that check is relaxed to reach the Lower timeout. Once the lowering
/// has ended without a touchdown, the body comes down after the foot (a leg out of reach), but
/// no more than `standing_crouch_max_m` below its height when the foot was released (here 4 cm,
/// which the lowering's timeout would pass: JVRC-1's body comes down 4.5 cm in it).
#[test]
fn touchdown_never_confirmed_is_a_lower_timeout_fault() {
    let config = ControllerConfig {
        support_force_min_fraction: 0.01,
        standing_crouch_max_m: 0.04,
        ..walk_support::controller_config("jvrc1")
    };
    let mut h = start(Harness::with_config("jvrc1", config, RATE_HZ), false);
    run_until(&mut h, Phase::Unload);
    let released = h.closed.controller.status().com[2];
    run_until(&mut h, Phase::Lower);
    // The force-torque sensor of the landing (right) foot reads nothing from now on.
    let mut ticks = 0;
    let mut lowest = h.closed.controller.status().com[2];
    while h.closed.controller.status().state == ControllerState::Executing && ticks < MAX_TICKS {
        h.tick_with(|w| w[EndEffector::RightFoot as usize] = [0.0; 6]);
        lowest = lowest.min(h.closed.controller.status().com[2]);
        ticks += 1;
    }
    let floor = released - config.standing_crouch_max_m;
    assert!(
        (floor - 0.005..floor + 0.005).contains(&lowest),
        "the body came down to {lowest:.3} m: released at {released:.3} m, floor {floor:.3} m"
    );
    let status = *h.closed.controller.status();
    assert_eq!(status.state, ControllerState::Fault);
    assert_eq!(status.fault, FaultCode::Timeout(Phase::Lower));
    assert!(
        !status.contacts[EndEffector::RightFoot as usize],
        "contact never confirmed"
    );
    assert_eq!(h.closed.command.mode, CommandMode::Hold);
    let held = h.closed.command.q_des.clone();
    for _ in 0..50 {
        h.tick_with(|w| w[EndEffector::RightFoot as usize] = [0.0; 6]);
        assert_eq!(
            h.closed.command.q_des, held,
            "a fault holds the last safe command"
        );
    }
    h.assert_safe();
}

/// The same dead sensor with the default limits: once the feet have read less than
/// `support_force_min_fraction` of the weight for `unloaded_max_s`, the static gait faults and
/// holds, naming the load.
#[test]
fn feet_that_stay_unloaded_while_walking_fault_and_hold() {
    let mut h = started("jvrc1", false);
    let config = walk_support::controller_config("jvrc1");
    run_until(&mut h, Phase::Lower);
    let mut unloaded_ticks = 0;
    while h.closed.controller.status().state == ControllerState::Executing {
        h.tick_with(|w| w[EndEffector::RightFoot as usize] = [0.0; 6]);
        // What the controller reads: the left foot's force only.
        let load = h.closed.sim.measurement().wrenches[EndEffector::LeftFoot as usize][2];
        let weight = h.robot.model.total_mass() * kinematics::ground::GRAVITY;
        if load < config.support_force_min_fraction * weight {
            unloaded_ticks += 1;
        }
        assert!(unloaded_ticks < 1000, "never faulted");
    }
    let status = *h.closed.controller.status();
    assert_eq!(status.state, ControllerState::Fault);
    assert!(
        matches!(
            status.fault,
            FaultCode::InvalidMeasurement(MeasurementFault::Unloaded(_))
        ),
        "{:?}",
        status.fault
    );
    // Faulted after unloaded_max_s of unloaded readings, not before.
    let unloaded_s = unloaded_ticks as f64 / RATE_HZ;
    assert!(
        unloaded_s > config.unloaded_max_s && unloaded_s <= config.unloaded_max_s + 2.0 / RATE_HZ,
        "faulted after {unloaded_s} s unloaded"
    );
    assert_eq!(h.closed.command.mode, CommandMode::Hold);
    h.assert_safe();
}

#[test]
fn force_spikes_while_swinging_or_above_the_ground_are_not_touchdowns() {
    let mut h = started("jvrc1", false);
    run_until(&mut h, Phase::Swing);
    // A sustained spike on the swinging foot: ignored outside the lowering phase.
    let spike = 2.0 * h.robot.model.total_mass() * kinematics::ground::GRAVITY;
    for _ in 0..20 {
        h.tick_with(|w| w[EndEffector::RightFoot as usize][2] = spike);
        h.assert_safe();
        assert_eq!(h.closed.controller.status().phase, Phase::Swing);
        assert!(!h.closed.controller.status().contacts[EndEffector::RightFoot as usize]);
    }
    run_until(&mut h, Phase::Lower);
    // Single-tick spikes while lowering, before the sole reaches the ground: debounced away.
    for k in 0..30 {
        let foot_in_air = !h.closed.sim.measurement().contacts[EndEffector::RightFoot as usize];
        assert!(foot_in_air, "the sole is still above the ground");
        if k % 2 == 0 {
            h.tick_with(|w| w[EndEffector::RightFoot as usize][2] = spike);
        } else {
            h.tick();
        }
        assert_eq!(h.closed.controller.status().phase, Phase::Lower);
        assert!(!h.closed.controller.status().contacts[EndEffector::RightFoot as usize]);
    }
    // The real touchdown is confirmed and the walk finishes.
    walk_to_done(&mut h, |_| {});
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
        h.closed.controller.abort();
        assert_eq!(
            h.closed.controller.status().state,
            ControllerState::Holding,
            "{phase:?}"
        );
        h.tick();
        let held = h.closed.command.q_des.clone();
        for _ in 0..200 {
            h.tick();
            h.assert_safe();
            assert_eq!(h.closed.command.mode, CommandMode::Hold, "{phase:?}");
            assert_eq!(
                h.closed.command.q_des, held,
                "{phase:?}: holding keeps the posture"
            );
            assert_eq!(h.closed.controller.status().state, ControllerState::Holding);
        }
        // From Holding, a new sequence (from wherever the robot stands) runs to the end.
        let sequence = walk_support::synthetic_walk(&h.robot, 2, 0.05, false);
        h.start(&sequence);
        walk_to_done(&mut h, |_| {});
    }
}

#[test]
fn start_is_refused_while_executing_and_in_fault_until_reset() {
    let mut h = started("jvrc1", false);
    h.tick();
    let config = walk_support::controller_config("jvrc1");
    let sequence = walk_support::synthetic_walk(&h.robot, 1, 0.05, false);
    let prepared = daemon::controller::Controller::prepare(&h.robot, &config, &sequence).unwrap();
    let (refused, why) = h.closed.controller.start(Box::new(prepared)).unwrap_err();
    assert_eq!(why, StartRefusal::Busy);
    // A non-finite measurement faults the controller; it then refuses until reset.
    let q: Vec<f64> = h
        .closed
        .sim
        .measurement()
        .q
        .iter()
        .map(|_| f64::NAN)
        .collect();
    let measurement = daemon::controller::Measurement {
        q: &q,
        qd: h.closed.sim.measurement().qd.as_slice(),
        wrenches: &h.closed.sim.measurement().wrenches,
        imu_orientation: None,
    };
    let before = h.closed.command.q_des.clone();
    assert!(
        h.closed
            .controller
            .tick(&measurement, h.dt, &mut h.closed.command)
    );
    assert_eq!(h.closed.controller.status().state, ControllerState::Fault);
    assert_eq!(
        h.closed.controller.status().fault,
        FaultCode::InvalidMeasurement(MeasurementFault::NonFiniteAngle(0))
    );
    assert_eq!(
        h.closed.command.q_des, before,
        "holds the last safe command"
    );
    assert_eq!(h.closed.command.mode, CommandMode::Hold);
    let (refused, why) = h.closed.controller.start(refused).unwrap_err();
    assert_eq!(why, StartRefusal::Faulted);
    h.closed.controller.reset().unwrap();
    assert_eq!(h.closed.controller.status().state, ControllerState::Holding);
    // The last measurement was invalid: a walk starts only from a valid one.
    let (refused, why) = h.closed.controller.start(refused).unwrap_err();
    assert_eq!(why, StartRefusal::NoMeasurement);
    h.tick();
    assert!(h.closed.controller.start(refused).is_ok());
    walk_to_done(&mut h, |_| {});
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

/// One tick on the simulator's measurement with the IMU reading `imu` instead; it commands.
fn tick_with_imu(h: &mut Harness, imu: nalgebra::UnitQuaternion<f64>) {
    let m = h.closed.sim.measurement().clone();
    let measurement = daemon::controller::Measurement {
        q: m.q.as_slice(),
        qd: m.qd.as_slice(),
        wrenches: &m.wrenches,
        imu_orientation: Some(imu),
    };
    assert!(
        h.closed
            .controller
            .tick(&measurement, h.dt, &mut h.closed.command)
    );
}

#[test]
fn an_imu_tilted_away_from_leg_odometry_is_a_tipping_fault_that_holds() {
    let mut h = started("jvrc1", false);
    for _ in 0..50 {
        h.tick();
    }
    assert_eq!(
        h.closed.controller.status().state,
        ControllerState::Executing
    );
    let config = walk_support::controller_config("jvrc1");
    let m = h.closed.sim.measurement().clone();
    // The IMU reports the base turned about the vertical by twice the detection angle (a stance
    // foot slipping round: no tipping), then rolled just under, then just over, that angle.
    let turned = |roll: f64, yaw: f64| {
        nalgebra::UnitQuaternion::from_euler_angles(roll, 0.0, yaw) * m.base_orientation
    };
    let detection = config.tipping_detection_rad;
    for (imu, tipping) in [
        (turned(0.0, 2.0 * detection), false),
        (turned(0.9 * detection, 0.0), false),
        (turned(1.1 * detection, 0.0), true),
    ] {
        let before = h.closed.command.q_des.clone();
        tick_with_imu(&mut h, imu);
        if tipping {
            assert_eq!(h.closed.controller.status().state, ControllerState::Fault);
            assert_eq!(h.closed.controller.status().fault, FaultCode::Tipping);
            assert_eq!(h.closed.command.q_des, before, "holds the last command");
            assert_eq!(h.closed.command.mode, CommandMode::Hold);
        } else {
            assert_eq!(
                h.closed.controller.status().state,
                ControllerState::Executing
            );
        }
    }
}

/// A static walk tipping mid-swing (the IMU rolled from leg odometry past `catch_tilt_rad`,
/// short of the tipping fault's angle) does not go on, nor freeze its swing foot in the air: it
/// puts it down, then holds in the tipping fault, standing on both feet. Tipping towards the
/// swing foot, the foot lands further out by about how far the tilt carried the CoM (MuJoCo:
/// ARMAR-4 putting it straight down rolled over it, `physics_walk`); tipping away, the foot
/// comes straight down rather than across the standing one.
#[test]
fn a_robot_tipping_mid_swing_puts_its_swing_foot_down_then_holds() {
    let config = walk_support::controller_config("jvrc1");
    let roll = (config.catch_tilt_rad + config.tipping_detection_rad) / 2.0;
    let (caught, landed, com_height) = tip_mid_swing(roll, true);
    let outwards = landed - caught;
    assert!(
        outwards > 0.5 * roll * com_height,
        "tipped {roll} rad towards it, the foot landed {outwards} m further out \
         ({caught} → {landed} m from the standing foot)"
    );
    let (caught, landed, _) = tip_mid_swing(roll, false);
    assert!(
        (landed - caught).abs() < 0.01,
        "tipped away from it, the foot came down {caught} → {landed} m from the standing foot"
    );
}

/// Walks JVRC-1 into its first swing, tips the IMU by `roll` (rad) towards the swing foot's side
/// (`towards`) or away from it, and ticks until the catch has landed and holds. Returns the
/// swing sole's horizontal distance from the standing one when tipped and when landed, and the
/// CoM height above the soles (m).
fn tip_mid_swing(roll: f64, towards: bool) -> (f64, f64, f64) {
    let mut h = started("jvrc1", false);
    run_until(&mut h, Phase::Swing);
    for _ in 0..20 {
        h.tick();
    }
    let status = *h.closed.controller.status();
    assert_eq!(status.phase, Phase::Swing, "{status:?}");
    let (swinging, standing) = if status.contacts[EndEffector::LeftFoot as usize] {
        (EndEffector::RightFoot, EndEffector::LeftFoot)
    } else {
        (EndEffector::LeftFoot, EndEffector::RightFoot)
    };
    let sole = |h: &Harness, foot| h.closed.sim.end_effector_pose(foot).translation.vector;
    let apart = |h: &Harness| (sole(h, swinging) - sole(h, standing)).xy().norm();
    let lifted = sole(&h, swinging).z;
    assert!(lifted > 0.01, "the swing foot is in the air: {lifted} m");
    let com_height = status.com[2] - sole(&h, standing).z;
    let config = walk_support::controller_config("jvrc1");
    assert!(config.catch_tilt_rad < roll && roll < config.tipping_detection_rad);
    // A roll about +x tips the robot towards −y, the right foot's side.
    let right = swinging == EndEffector::RightFoot;
    let sign = if right == towards { 1.0 } else { -1.0 };
    let m = h.closed.sim.measurement().clone();
    let tipped =
        nalgebra::UnitQuaternion::from_euler_angles(sign * roll, 0.0, 0.0) * m.base_orientation;
    let caught = apart(&h);
    tick_with_imu(&mut h, tipped);
    let status = *h.closed.controller.status();
    assert_eq!(status.state, ControllerState::ControlledStop, "{status:?}");
    assert_eq!(status.fault, FaultCode::Tipping);
    assert_eq!(status.phase, Phase::Swing, "the swing turns into a catch");
    assert_eq!(h.closed.command.mode, CommandMode::Track, "the foot moves");
    // Down within two seconds: 0.15 s to the standing sole's plane (or the ground met on the
    // way), then lowered as every foot is until force-torque confirms the touchdown.
    let mut ticks = 0;
    while h.closed.controller.status().state == ControllerState::ControlledStop {
        assert!(
            ticks < 2 * RATE_HZ as usize,
            "still landing after two seconds"
        );
        h.tick();
        h.assert_safe();
        ticks += 1;
    }
    let status = *h.closed.controller.status();
    assert_eq!(status.state, ControllerState::Fault, "{status:?}");
    assert_eq!(
        status.fault,
        FaultCode::Tipping,
        "the catch ends in the tipping fault"
    );
    assert!(
        status.contacts[EndEffector::LeftFoot as usize]
            && status.contacts[EndEffector::RightFoot as usize],
        "stands on both feet: {status:?}"
    );
    let landed = sole(&h, swinging).z;
    assert!(landed < 0.005, "landed: {landed} m");
    assert_eq!(h.closed.command.mode, CommandMode::Hold);
    (caught, apart(&h), com_height)
}

#[test]
fn the_base_roll_and_pitch_rates_keep_their_own_bound_through_a_walk() {
    let config = walk_support::controller_config("armar4");
    assert!(
        config.max_base_tilt_speed < config.max_base_speed,
        "ARMAR-4 bounds its pelvis tilt rate below the base speed"
    );
    let mut h = started("armar4", false);
    let mut previous = h.closed.sim.measurement().base_orientation;
    let mut fastest_tilt: f64 = 0.0;
    walk_to_done(&mut h, |h| {
        let qp = h.closed.controller.last_problem();
        for k in 0..6 {
            let bound = if k == 3 || k == 4 {
                config.max_base_tilt_speed
            } else {
                config.max_base_speed
            };
            assert_eq!(
                (qp.x_min()[k], qp.x_max()[k]),
                (-bound, bound),
                "base velocity component {k}"
            );
        }
        // World-frame angular velocity of the simulated base over the tick: roll and pitch rate.
        let orientation = h.closed.sim.measurement().base_orientation;
        let omega = (orientation * previous.inverse()).scaled_axis() / h.dt;
        fastest_tilt = fastest_tilt.max(omega.x.abs()).max(omega.y.abs());
        previous = orientation;
    });
    assert!(
        fastest_tilt <= config.max_base_tilt_speed * 1.05,
        "base tilted at {fastest_tilt} rad/s, bound {}",
        config.max_base_tilt_speed
    );
}

/// The synthetic walk with the left hand, except that the hand lets go again after its first
/// stance in contact and the feet walk on without it.
fn walk_releasing_the_hand(h: &Harness) -> stance::PostProcessedSequence {
    held_walk_edited(h, |stances, _| {
        for stance in &mut stances[2..] {
            stance.contacts[EndEffector::LeftHand as usize] = false;
        }
    })
}

/// The 4-step synthetic walk with the left hand held, its stances and targets changed by `edit`.
fn held_walk_edited(
    h: &Harness,
    edit: impl FnOnce(&mut [stance::Stance], &mut [[nalgebra::Isometry3<f64>; 4]]),
) -> stance::PostProcessedSequence {
    let held = walk_support::synthetic_walk(&h.robot, 4, 0.08, true);
    let mut stances = held.stances().to_vec();
    let mut targets: Vec<_> = (0..held.len()).map(|i| *held.targets(i)).collect();
    edit(&mut stances, &mut targets);
    stance::PostProcessedSequence::new(
        held.robot().to_owned(),
        held.joint_names().to_vec(),
        held.environment().clone(),
        stances,
        targets,
    )
    .unwrap()
}

/// The left hand's pose in the pelvis's planar (x, y, yaw) frame, in the simulator.
fn hand_in_pelvis_frame(h: &Harness) -> nalgebra::Isometry3<f64> {
    let model = &h.robot.model;
    let mut kinematics = kinematics::kinematics::Kinematics::new(model);
    kinematics.update(model, h.closed.sim.configuration());
    let pelvis = kinematics::ground::planar_frame([kinematics.link_pose(h.robot.base_link)]);
    let hand = kinematics.frame_pose(model, h.robot.frame(EndEffector::LeftHand));
    pelvis.inverse() * hand
}

#[test]
fn a_released_hand_is_carried_with_the_pelvis_only_when_configured() {
    for carry in [true, false] {
        let mut config = walk_support::controller_config("jvrc1");
        config.carry_released_hands = carry;
        let mut h = Harness::with_config("jvrc1", config, RATE_HZ);
        let sequence = walk_releasing_the_hand(&h);
        h.start(&sequence);
        let mut at_release = None;
        let mut moved: f64 = 0.0;
        walk_to_done(&mut h, |h| {
            if h.closed.controller.status().stance_index >= 2 {
                let relative = hand_in_pelvis_frame(h);
                let first = *at_release.get_or_insert(relative);
                let offset = relative.translation.vector - first.translation.vector;
                moved = moved.max(offset.norm());
            }
        });
        // Held, the hand is 3 cm ahead of where the standing posture puts it: carried it stays
        // there relative to the pelvis (up to the pose task's lag while the pelvis moves, 5.4
        // mm measured); left to the posture task it swings back (3.7 cm measured).
        if carry {
            assert!(
                moved < 0.01,
                "carried hand moved {moved} m against the pelvis"
            );
        } else {
            assert!(
                moved > 0.025,
                "released hand moved only {moved} m against the pelvis"
            );
        }
    }
}

/// The synthetic walk with the left hand held from its second stance on, at a grasp 0.6 m
/// further out than the standing posture puts it: beyond the arm's reach.
fn walk_reaching_too_far(h: &Harness) -> stance::PostProcessedSequence {
    held_walk_edited(h, |stances, targets| {
        let left_hand = EndEffector::LeftHand as usize;
        for (stance, target) in stances.iter().zip(targets) {
            if stance.contacts[left_hand] {
                target[left_hand].translation.vector.y += 0.6;
            }
        }
    })
}

#[test]
fn a_hand_that_cannot_reach_its_contact_is_let_go_and_the_walk_goes_on() {
    let mut h = Harness::new("jvrc1", RATE_HZ);
    let sequence = walk_reaching_too_far(&h);
    let left_hand = EndEffector::LeftHand as usize;
    let planned_runs = 1;
    assert!(
        sequence
            .stances()
            .iter()
            .filter(|s| s.contacts[left_hand])
            .count()
            > 2
    );
    h.start(&sequence);
    let mut reaches = 0;
    let mut previous = Phase::None;
    walk_to_done(&mut h, |h| {
        let status = h.closed.controller.status();
        assert!(
            !status.contacts[left_hand],
            "stance {}: the hand never reached, yet counts as a contact",
            status.stance_index
        );
        if status.phase == Phase::Reach && previous != Phase::Reach {
            reaches += 1;
        }
        previous = status.phase;
    });
    // One reach, given up once: the rest of its contact run is walked without the hand.
    assert_eq!(reaches, planned_runs);
    assert_eq!(h.closed.controller.status().reaches_given_up, planned_runs);
}

/// The heading about the vertical of a status pose `[x, y, z, qx, qy, qz, qw]` (rad).
fn heading_of(pose: &[f64; 7]) -> f64 {
    kinematics::ground::yaw(&nalgebra::UnitQuaternion::from_quaternion(
        nalgebra::Quaternion::new(pose[6], pose[3], pose[4], pose[5]),
    ))
}

#[test]
fn the_estimate_turns_onto_the_imu_heading_no_faster_than_its_bound() {
    // The feet turned together on the ground by `turn`: leg odometry cannot see it, the IMU
    // does. The estimate (and the anchored feet with it) follows the IMU at
    // `heading_correction_speed`, or not at all at 0.
    let turn = 0.02;
    for speed in [0.0, 0.05] {
        let config = ControllerConfig {
            heading_correction_speed: speed,
            ..walk_support::controller_config("jvrc1")
        };
        let mut h = walk_support::Harness::with_config("jvrc1", config, RATE_HZ);
        h.tick();
        let m = h.closed.sim.measurement().clone();
        let imu = nalgebra::UnitQuaternion::from_euler_angles(0.0, 0.0, turn) * m.base_orientation;
        let measurement = daemon::controller::Measurement {
            q: m.q.as_slice(),
            qd: m.qd.as_slice(),
            wrenches: &m.wrenches,
            imu_orientation: Some(imu),
        };
        let start = heading_of(&h.closed.controller.status().left_foot);
        let mut previous = start;
        // Twice the time the bounded speed needs.
        let ticks = (2.0 * turn / 0.05 / h.dt).ceil() as usize;
        for _ in 0..ticks {
            let _ = h
                .closed
                .controller
                .tick(&measurement, h.dt, &mut h.closed.command);
            let now = heading_of(&h.closed.controller.status().left_foot);
            assert!(
                (now - previous).abs() <= speed * h.dt + 1e-9,
                "speed {speed}: turned {} rad in one tick",
                now - previous
            );
            previous = now;
        }
        let expected = if speed > 0.0 { turn } else { 0.0 };
        assert!(
            (previous - start - expected).abs() < 1e-6,
            "speed {speed}: the left foot's estimated heading turned {} rad, not {expected}",
            previous - start
        );
        assert_eq!(h.closed.controller.status().state, ControllerState::Idle);
    }
}

/// A stair higher than a gait is set to take (`max_step_up_m`, `max_step_down_m` of
/// `[controller]` for the static gait, of `[gait.dynamic]` for the dynamic one) is refused
/// before anything moves, naming the stance, the foot, the height and the key. JVRC-1's dynamic
/// gait climbs 0.15 m stairs (on its toes) and walks down 0.185 m ones under MuJoCo; up 0.185 m
/// it tipped at the first stair and fell after the fault. ARMAR-4's dynamic gait takes no stair.
/// A step's height is the riser, the landing above or below the other foot: one foot per
/// 0.10 m stair, each foot rises 0.20 m from its last sole, and is taken. JVRC-1's static gait
/// takes the 10° ramp's steps, not a 0.10 m stair.
#[test]
fn stairs_higher_than_a_gait_takes_are_refused_naming_the_step_and_the_key() {
    use stance::Gait;
    let prepare = |scene: &str, gait: Gait| prepare_on_scene("jvrc1", scene, gait);
    assert_eq!(prepare("stairs-up-15cm.toml", Gait::Dynamic), Ok(()));
    assert_eq!(prepare("stairs-up-10cm.toml", Gait::Dynamic), Ok(()));
    assert_eq!(prepare("stairs-down-10cm.toml", Gait::Dynamic), Ok(()));
    assert_eq!(prepare("stairs-down-15cm.toml", Gait::Dynamic), Ok(()));
    assert_eq!(prepare("stairs-down-18cm.toml", Gait::Dynamic), Ok(()));
    assert_eq!(prepare("ramp-10deg.toml", Gait::Static), Ok(()));
    for (robot, scene, gait, step, key) in [
        (
            "jvrc1",
            "stairs-up-18cm.toml",
            Gait::Dynamic,
            "steps up 0.185 m",
            "[gait.dynamic] max_step_up_m = 0.15,",
        ),
        (
            "armar4",
            "stairs-down-10cm.toml",
            Gait::Dynamic,
            "steps down 0.100 m",
            "[gait.dynamic] max_step_down_m = 0.01,",
        ),
        (
            "jvrc1",
            "stairs-up-10cm.toml",
            Gait::Static,
            "steps up 0.100 m",
            "[controller] max_step_up_m = 0.06,",
        ),
        (
            "jvrc1",
            "stairs-down-10cm.toml",
            Gait::Static,
            "steps down 0.100 m",
            "[controller] max_step_down_m = 0.06,",
        ),
    ] {
        let refusal = prepare_on_scene(robot, scene, gait).expect_err(scene);
        assert!(
            refusal.starts_with("sequence refused: stance ")
                && refusal.contains("foot ")
                && refusal.contains(step)
                && refusal.contains(key),
            "{scene}: {refusal}"
        );
    }
}

/// A hand on a railing is refused where the gait is not set to hold one (`hold_railings`, docs/
/// scenes.md, "Hands on railings"): holding `railing.toml`'s rail, JVRC-1's dynamic gait and
/// ARMAR-4's both fell in 4 of 4 walks (MuJoCo). JVRC-1's static gait holds it; without a
/// railing in the scene a held hand touches nothing, and every gait walks it.
#[test]
fn a_hand_on_a_railing_is_refused_where_the_gait_holds_none_naming_the_hand_and_the_key() {
    use stance::{AffordanceSet, Gait};
    let right = AffordanceSet::FeetRightHand;
    assert_eq!(
        prepare_on_scene_with("jvrc1", "railing.toml", Gait::Static, right),
        Ok(())
    );
    assert_eq!(
        prepare_on_scene_with("jvrc1", "railing.toml", Gait::Dynamic, AffordanceSet::Feet),
        Ok(())
    );
    for (robot, gait, key) in [
        (
            "jvrc1",
            Gait::Dynamic,
            "[gait.dynamic] hold_railings = false",
        ),
        (
            "armar4",
            Gait::Dynamic,
            "[gait.dynamic] hold_railings = false",
        ),
        ("armar4", Gait::Static, "[controller] hold_railings = false"),
    ] {
        let refusal = prepare_on_scene_with(robot, "railing.toml", gait, right)
            .expect_err("a held hand on a railing");
        assert!(
            refusal.starts_with("sequence refused: stance ")
                && refusal.contains("right_hand holds a railing")
                && refusal.contains(key),
            "{robot} {gait:?}: {refusal}"
        );
    }
}

/// The post-processed walk (seed 0, feet) of robot `robot_name`, over the whole of the scene
/// file `scene`, prepared by its controller for `gait`: the refusal's message, if any.
fn prepare_on_scene(robot_name: &str, scene: &str, gait: stance::Gait) -> Result<(), String> {
    prepare_on_scene_with(robot_name, scene, gait, stance::AffordanceSet::Feet)
}

/// [`prepare_on_scene`] with the walk's support `affordances`.
fn prepare_on_scene_with(
    robot_name: &str,
    scene: &str,
    gait: stance::Gait,
    affordances: stance::AffordanceSet,
) -> Result<(), String> {
    use stance::{PostProcessParams, Scene, WalkRequest};
    let robot = walk_support::robot(robot_name);
    let file = kinematics::ConfigFile::load(&walk_support::config_path(robot_name)).unwrap();
    let config = walk_support::controller_config(robot_name);
    let gaits = daemon::controller::GaitConfig::from_config(&file).unwrap();
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../configs/scenes");
    let scene = Scene::from_path(&path.join(scene)).expect("scene loads");
    let params = PostProcessParams::from_config_for(&file, gait).unwrap();
    let request = WalkRequest {
        distance: scene.path_length(),
        affordances,
        seed: 0,
        speed: None,
    };
    let environment = scene.walk_environment();
    let walk = stance::walk_in(&robot, &params, &request, &environment, |options| {
        stance::generate(&robot, options)
    })
    .expect("walks on the scene");
    daemon::controller::Controller::prepare_gait(&robot, &config, &gaits, &walk, gait)
        .map(|_| ())
        .map_err(|refusal| refusal.to_string())
}

/// A surface steeper than a gait is set to stand on (`max_slope_rad`) is refused before anything
/// moves, naming the stance, the foot, the slope and the key: ARMAR-4's static gait, set to 5°
/// slopes (on the 10° ramp it walked 2 of 10 walks, and fell in one with no fault first), takes
/// the 5° ramp and refuses the 10° one its steps (at most 0.05 m) would take; JVRC-1's walks it.
#[test]
fn a_ramp_steeper_than_a_gait_takes_is_refused_naming_the_slope_and_the_key() {
    use stance::Gait;
    assert_eq!(
        prepare_on_scene("jvrc1", "ramp-10deg.toml", Gait::Static),
        Ok(())
    );
    assert_eq!(
        prepare_on_scene("jvrc1", "ramp-15deg.toml", Gait::Dynamic),
        Ok(())
    );
    assert_eq!(
        prepare_on_scene("armar4", "stairs-up-10cm.toml", Gait::Static),
        Ok(())
    );
    assert_eq!(
        prepare_on_scene("armar4", "ramp-5deg.toml", Gait::Static),
        Ok(())
    );
    let refusal = prepare_on_scene("armar4", "ramp-10deg.toml", Gait::Static).unwrap_err();
    assert!(
        refusal.starts_with("sequence refused: stance ")
            && refusal.contains("foot stands on a slope of 0.175 rad (10.0°)")
            && refusal.contains("[controller] max_slope_rad = 0.09,"),
        "{refusal}"
    );
}
