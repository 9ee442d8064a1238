//! The MuJoCo backend with the vendored robots: standing still in the configured posture,
//! balancing on one foot, how far feet creep under a sideways load, determinism, joint tracking,
//! the adapter side and command checks.
//! Needs the `mujoco` feature (and the library: `eval "$(scripts/setup-mujoco.sh)"`).
#![cfg(feature = "mujoco")]

use kinematic_sim::{JointVectorError, Simulator};
use std::f64::consts::PI;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use kinematics::configuration::Configuration;
use kinematics::ik::{IkError, IkOptions, IkSolver, IkTarget};
use kinematics::kinematics::Kinematics;
use kinematics::robot::{EndEffector, Robot};
use nalgebra::{Isometry3, Vector2, Vector3};
use shm_types::SensorSample;
use sim_adapter::RobotIo;
use sim_adapter::SimulatedRobot;
use sim_adapter::mujoco::{MujocoError, MujocoOptions, MujocoSim};

/// Control period the daemon runs at by default (500 Hz): two physics steps per call.
const DT: f64 = 0.002;

fn configs() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../configs")
}

/// The robot and the URDF its config names.
fn robot(name: &str) -> (Arc<Robot>, PathBuf) {
    let config = configs().join(format!("{name}.toml"));
    let robot = Robot::load(&config, None).unwrap_or_else(|e| panic!("{name}: {e}"));
    let urdf = match name {
        "armar4" => "robots/armar4/armar4_fixed_hands.urdf",
        "jvrc1" => "robots/jvrc1/jvrc1.urdf",
        "icub" => "robots/icub/iCubGazeboV2_7.urdf",
        other => panic!("no vendored URDF for {other}"),
    };
    (Arc::new(robot), configs().join(urdf))
}

fn standing_sim(name: &str) -> MujocoSim {
    let (robot, urdf) = robot(name);
    let initial = robot.standing.clone();
    MujocoSim::new(robot, &urdf, &initial, MujocoOptions::default())
        .unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// Worst deviations while holding the standing posture for `seconds`.
struct Hold {
    max_height_change: f64,
    max_tilt: f64,
    final_force_error: f64,
    final_left_share: f64,
    /// Largest |left + right − m·g| / m·g over the second half of the hold: a servo that
    /// chatters shows here.
    max_settled_force_error: f64,
}

fn hold_standing(sim: &mut MujocoSim, seconds: f64) -> Hold {
    let q: Vec<f64> = sim.robot().standing.joints.iter().copied().collect();
    let qd = vec![0.0; q.len()];
    let start_height = sim.base_height();
    let mut hold = Hold {
        max_height_change: 0.0,
        max_tilt: 0.0,
        final_force_error: 0.0,
        final_left_share: 0.0,
        max_settled_force_error: 0.0,
    };
    let weight = sim.robot().model.total_mass() * 9.81;
    let steps = (seconds / DT).round() as usize;
    for step in 0..steps {
        sim.step(&q, &qd, DT).expect("step");
        if step >= steps / 2 {
            let w = &sim.measurement().wrenches;
            hold.max_settled_force_error = hold
                .max_settled_force_error
                .max((w[0][2] + w[1][2] - weight).abs() / weight);
        }
        hold.max_height_change = hold
            .max_height_change
            .max((sim.base_height() - start_height).abs());
        hold.max_tilt = hold.max_tilt.max(sim.torso_tilt());
    }
    let w = &sim.measurement().wrenches;
    let (left, right) = (w[0][2], w[1][2]);
    hold.final_force_error = (left + right - weight).abs() / weight;
    hold.final_left_share = left / (left + right);
    hold
}

fn assert_stands(name: &str) {
    let mut sim = standing_sim(name);
    let hold = hold_standing(&mut sim, 2.0);
    assert!(
        hold.max_height_change < 0.003,
        "{name}: base height moved {} m",
        hold.max_height_change
    );
    assert!(
        hold.max_tilt < 1f64.to_radians(),
        "{name}: torso tilted {} rad",
        hold.max_tilt
    );
    assert!(
        hold.final_force_error < 0.01,
        "{name}: foot forces off m·g by {}",
        hold.final_force_error
    );
    assert!(
        hold.max_settled_force_error < 0.05,
        "{name}: foot forces swing off m·g by {} in the last second",
        hold.max_settled_force_error
    );
    assert!(
        (0.4..=0.6).contains(&hold.final_left_share),
        "{name}: left foot carries {} of the weight",
        hold.final_left_share
    );
    let m = sim.measurement();
    assert_eq!(
        m.contacts,
        [true, true, false, false],
        "{name}: both feet and only the feet touch"
    );
    assert!(
        m.safety.stability_margin > 0.0,
        "{name}: CoM outside the support polygon"
    );
    assert!(
        !sim.summary().fell && !sim.has_fallen(),
        "{name}: counted as fallen"
    );
    // The IMU agrees with the true base orientation.
    assert!(
        m.base_orientation.angle_to(&m.base.rotation) < 1e-9,
        "{name}: IMU orientation"
    );
}

#[test]
fn armar4_stands_in_its_standing_posture() {
    assert_stands("armar4");
}

#[test]
fn jvrc1_stands_in_its_standing_posture() {
    assert_stands("jvrc1");
}

/// The third robot, whose 37 N·m knees and ankles get scaled-down servos (`mjcf::servo_scale`).
#[test]
fn icub_stands_in_its_standing_posture() {
    assert_stands("icub");
}

/// Full state after a short scripted run, as raw bits.
fn scripted_run_bits(name: &str) -> Vec<u64> {
    let mut sim = standing_sim(name);
    let standing: Vec<f64> = sim.robot().standing.joints.iter().copied().collect();
    let qd = vec![0.0; standing.len()];
    for k in 0..250 {
        let q: Vec<f64> = standing
            .iter()
            .map(|q| q + 0.02 * (k as f64 * 0.05).sin())
            .collect();
        sim.step(&q, &qd, DT).expect("step");
    }
    let m = sim.measurement();
    let base = m.base.to_homogeneous();
    m.q.iter()
        .chain(m.qd.iter())
        .chain(m.wrenches.iter().flatten())
        .chain(base.iter())
        .chain(m.com.iter())
        .map(|v| v.to_bits())
        .collect()
}

#[test]
fn two_runs_give_bit_identical_states() {
    for name in ["armar4", "jvrc1"] {
        assert_eq!(scripted_run_bits(name), scripted_run_bits(name), "{name}");
    }
}

/// Moves the torso and arm joints by up to `delta` rad (towards their farther limit) along a
/// half-cosine over `duration`, with matching velocity feed-forward, then holds; returns the
/// largest tracking error during the motion and after settling, and the worst tilt.
fn track_motion(name: &str, delta: f64, duration: f64) -> (f64, f64, f64) {
    let mut sim = standing_sim(name);
    let robot = sim.robot().clone();
    let start: Vec<f64> = robot.standing.joints.iter().copied().collect();
    let mut offsets = vec![0.0; start.len()];
    let limits = robot.model.joint_limits();
    for &j in robot
        .joint_groups
        .arms
        .iter()
        .chain(&robot.joint_groups.torso)
    {
        let (up, down) = (limits[j].upper - start[j], start[j] - limits[j].lower);
        offsets[j] = if up >= down {
            delta.min(0.8 * up)
        } else {
            -delta.min(0.8 * down)
        };
    }
    let (mut q, mut qd) = (start.clone(), vec![0.0; start.len()]);
    let (mut motion_error, mut worst_tilt): (f64, f64) = (0.0, 0.0);
    let steps = (duration / DT).round() as usize;
    for k in 1..=steps {
        let t = k as f64 * DT;
        let s = 0.5 * (1.0 - (PI * t / duration).cos());
        let ds = 0.5 * PI / duration * (PI * t / duration).sin();
        for j in 0..q.len() {
            q[j] = start[j] + offsets[j] * s;
            qd[j] = offsets[j] * ds;
        }
        sim.step(&q, &qd, DT).expect("step");
        motion_error = motion_error.max(max_error(&sim, &q));
        worst_tilt = worst_tilt.max(sim.torso_tilt());
    }
    qd.fill(0.0);
    for _ in 0..250 {
        sim.step(&q, &qd, DT).expect("step");
        worst_tilt = worst_tilt.max(sim.torso_tilt());
    }
    (motion_error, max_error(&sim, &q), worst_tilt)
}

fn max_error(sim: &MujocoSim, q_des: &[f64]) -> f64 {
    sim.measurement()
        .q
        .iter()
        .zip(q_des)
        .map(|(q, d)| (q - d).abs())
        .fold(0.0, f64::max)
}

#[test]
fn commanded_arm_and_torso_motion_is_tracked() {
    for name in ["armar4", "jvrc1"] {
        let (during, settled, tilt) = track_motion(name, 0.2, 1.0);
        assert!(
            during < 0.01,
            "{name}: tracking error {during} rad during the motion"
        );
        assert!(
            settled < 0.005,
            "{name}: tracking error {settled} rad after settling"
        );
        assert!(tilt < 2f64.to_radians(), "{name}: torso tilted {tilt} rad");
    }
}

#[test]
fn bad_commands_are_refused_with_the_reason() {
    let mut sim = standing_sim("jvrc1");
    let n = sim.robot().model.dof();
    let ok = vec![0.0; n];
    let short = vec![0.0; n - 1];
    assert!(matches!(
        sim.step(&short, &ok, DT),
        Err(MujocoError::JointVector(JointVectorError::Length {
            field: "q_des",
            ..
        }))
    ));
    let mut nan = sim.robot().standing.joints.as_slice().to_vec();
    nan[3] = f64::NAN;
    let err = sim.step(&nan, &ok, DT).unwrap_err();
    assert!(
        matches!(
            err,
            MujocoError::JointVector(JointVectorError::NonFinite {
                field: "q_des",
                index: 3,
                ..
            })
        ),
        "{err}"
    );
    assert!(
        err.to_string()
            .contains(&sim.robot().model.joint_names()[3]),
        "{err}"
    );
    let standing = sim.robot().standing.joints.as_slice().to_vec();
    assert!(matches!(
        sim.step(&standing, &ok, 0.0),
        Err(MujocoError::BadTimeStep(_))
    ));
    assert!(matches!(
        sim.step(&standing, &ok, f64::NAN),
        Err(MujocoError::BadTimeStep(_))
    ));
    assert_eq!(
        sim.time(),
        0.0,
        "refused commands must not advance the simulation"
    );
}

#[test]
fn steps_that_are_not_multiples_of_the_time_step_carry_the_remainder() {
    let mut sim = standing_sim("jvrc1");
    let q = sim.robot().standing.joints.as_slice().to_vec();
    let qd = vec![0.0; q.len()];
    let timestep = sim.options().timestep;
    let mut expected_steps = Vec::new();
    for _ in 0..4 {
        sim.step(&q, &qd, 1.5 * timestep).expect("step");
        expected_steps.push((sim.time() / timestep).round() as usize);
    }
    // 1.5, 3, 4.5, 6 time steps commanded: 1, 3, 4, 6 taken.
    assert_eq!(expected_steps, [1, 3, 4, 6]);
}

#[test]
fn a_urdf_that_does_not_match_the_robot_is_refused() {
    let (jvrc, _) = robot("jvrc1");
    let (_, armar_urdf) = robot("armar4");
    let initial = jvrc.standing.clone();
    let err = MujocoSim::new(jvrc, &armar_urdf, &initial, MujocoOptions::default())
        .err()
        .expect("mismatched URDF must be refused");
    assert!(matches!(err, MujocoError::ModelMismatch(_)), "{err}");
}

/// A whole-body posture from IK with both soles at `soles` and the CoM over `com_xy` (the base
/// link's position target is moved by the CoM error for a few passes; its orientation is left
/// free), or `None` when the joint limits do not allow it.
fn posture_with_com_over(
    robot: &Robot,
    soles: [Isometry3<f64>; 2],
    com_xy: Vector2<f64>,
) -> Option<Configuration> {
    let mut model = robot.model.clone();
    let pelvis = model
        .add_frame("pelvis_target", robot.base_link, Isometry3::identity())
        .unwrap();
    let feet = [
        robot.frame(EndEffector::LeftFoot),
        robot.frame(EndEffector::RightFoot),
    ];
    let mut kinematics = Kinematics::new(&model);
    kinematics.update(&model, &robot.standing);
    let mut pelvis_pose = kinematics.frame_pose(&model, pelvis);
    let mut solver = IkSolver::new(&model);
    let mut configuration = robot.standing.clone();
    let options = IkOptions {
        tolerance: 1e-7,
        ..IkOptions::default()
    };
    for _ in 0..8 {
        let target = |frame, pose, orientation_weight| IkTarget {
            frame,
            pose,
            position_weight: 1.0,
            orientation_weight,
        };
        let targets = [
            target(feet[0], soles[0], 1.0),
            target(feet[1], soles[1], 1.0),
            target(pelvis, pelvis_pose, 0.0),
        ];
        let posture = Some(&robot.standing.joints);
        configuration = match solver.solve(&model, &targets, &configuration, posture, &options) {
            Ok(solution) => solution.configuration,
            Err(IkError::NotConverged(best)) => best.configuration,
            Err(e) => panic!("{}: IK: {e}", robot.name),
        };
        kinematics.update(&model, &configuration);
        let error = com_xy - kinematics.com().xy();
        pelvis_pose.translation.x += error.x;
        pelvis_pose.translation.y += error.y;
    }
    let sole_error = |slot: usize| {
        (kinematics.frame_pose(&model, feet[slot]).translation.vector
            - soles[slot].translation.vector)
            .norm()
    };
    let reached = (kinematics.com().xy() - com_xy).norm() < 2e-3
        && sole_error(0) < 1e-5
        && sole_error(1) < 1e-5;
    reached.then_some(configuration)
}

/// Moves the servos from `from` to `to` along a half-cosine with velocity feed-forward.
fn move_joints(sim: &mut MujocoSim, from: &[f64], to: &[f64], duration: f64) {
    let (mut q, mut qd) = (from.to_vec(), vec![0.0; from.len()]);
    let steps = (duration / DT).round() as usize;
    for k in 1..=steps {
        let phase = PI * k as f64 * DT / duration;
        let (s, ds) = (0.5 * (1.0 - phase.cos()), 0.5 * PI / duration * phase.sin());
        for j in 0..q.len() {
            q[j] = from[j] + (to[j] - from[j]) * s;
            qd[j] = (to[j] - from[j]) * ds;
        }
        sim.step(&q, &qd, DT).expect("step");
    }
    qd.fill(0.0);
    for _ in 0..(0.5 / DT) as usize {
        sim.step(to, &qd, DT).expect("step");
    }
}

/// Shifts the CoM over the left sole, lifts the right foot 3 cm, puts it back and returns to
/// standing: the robot balances on one foot, the FT readings follow the load, no foot slips.
fn balance_on_left_foot(name: &str) {
    let mut sim = standing_sim(name);
    let robot = sim.robot().clone();
    let mut kinematics = Kinematics::new(&robot.model);
    kinematics.update(&robot.model, &robot.standing);
    let soles = [EndEffector::LeftFoot, EndEffector::RightFoot]
        .map(|foot| kinematics.frame_pose(&robot.model, robot.frame(foot)));
    // The CoM as close to the left sole's centre as the joint limits allow: ARMAR-4's ±0.06 rad
    // ankle roll keeps its pelvis from reaching the centre.
    let inward = (soles[1].translation.vector - soles[0].translation.vector)
        .xy()
        .normalize();
    let mut lifted_sole = soles[1];
    lifted_sole.translation.z += 0.03;
    let (shifted, lifted) = [0.0, 0.1, 0.2, 0.3, 0.35, 0.4]
        .into_iter()
        .find_map(|fraction| {
            let inset = fraction * robot.sole.width;
            let com = soles[0].translation.vector.xy() + inward * inset;
            let shifted = posture_with_com_over(&robot, soles, com)?;
            let lifted = posture_with_com_over(&robot, [soles[0], lifted_sole], com)?;
            Some((shifted, lifted))
        })
        .unwrap_or_else(|| panic!("{name}: no posture puts the CoM over the left sole"));
    let standing = robot.standing.joints.as_slice();
    let (shifted_q, lifted_q) = (shifted.joints.as_slice(), lifted.joints.as_slice());
    let weight = robot.model.total_mass() * 9.81;

    move_joints(&mut sim, standing, shifted_q, 1.5);
    // Both feet still touch, so how the load splits depends on the servos; the CoM must be over
    // the left sole and the left foot carry more.
    let m = sim.measurement();
    let left_sole = sim
        .end_effector_pose(EndEffector::LeftFoot)
        .translation
        .vector
        .xy();
    let inside = 0.5 * robot.sole.width - (m.com.xy() - left_sole).dot(&inward);
    assert!(
        inside > 0.005,
        "{name}: CoM only {inside} m inside the left sole"
    );
    assert!(
        m.wrenches[0][2] > m.wrenches[1][2],
        "{name}: left foot not the loaded one"
    );

    move_joints(&mut sim, shifted_q, lifted_q, 1.0);
    let m = sim.measurement();
    assert_eq!(
        m.contacts[..2],
        [true, false],
        "{name}: only the left foot touches"
    );
    assert!(
        (m.wrenches[0][2] - weight).abs() < 0.02 * weight,
        "{name}: left foot {} N, m·g {weight} N",
        m.wrenches[0][2]
    );
    assert_eq!(
        m.wrenches[1], [0.0; 6],
        "{name}: the lifted foot reads no force"
    );
    let right = sim.end_effector_pose(EndEffector::RightFoot);
    assert!(
        right.translation.z > 0.02,
        "{name}: right sole only {} m up",
        right.translation.z
    );
    assert!(
        m.safety.stability_margin > 0.0,
        "{name}: CoM left the stance foot"
    );
    let lean = m.base.rotation.angle_to(&lifted.base.rotation);
    assert!(
        lean < 1f64.to_radians(),
        "{name}: base {lean} rad off the commanded posture"
    );

    move_joints(&mut sim, lifted_q, shifted_q, 1.0);
    move_joints(&mut sim, shifted_q, standing, 1.5);
    assert_eq!(
        sim.measurement().contacts[..2],
        [true, true],
        "{name}: both feet down again"
    );
    assert!(
        sim.summary().max_contact_slip < 2e-3,
        "{name}: a foot slipped {} m",
        sim.summary().max_contact_slip
    );
    assert!(!sim.summary().fell, "{name}: fell");
}

#[test]
fn armar4_balances_on_one_foot() {
    balance_on_left_foot("armar4");
}

#[test]
fn icub_balances_on_one_foot() {
    balance_on_left_foot("icub");
}

#[test]
fn jvrc1_balances_on_one_foot() {
    balance_on_left_foot("jvrc1");
}

#[test]
fn the_adapter_side_reads_what_the_simulator_measures() {
    let (robot, urdf) = robot("jvrc1");
    let mut io = SimulatedRobot::new(
        MujocoSim::new(
            robot.clone(),
            &urdf,
            &robot.standing,
            MujocoOptions::default(),
        )
        .expect("model builds"),
    );
    let n = io.joint_count();
    assert_eq!(n, robot.model.dof());
    let q = robot.standing.joints.as_slice().to_vec();
    for _ in 0..100 {
        io.write(&q, &vec![0.0; n], DT).expect("step");
    }
    let mut sample = SensorSample::ZERO;
    io.read(&mut sample);
    let m = io.sim().measurement();
    assert_eq!(&sample.q[..n], m.q.as_slice());
    assert_eq!(&sample.qd[..n], m.qd.as_slice());
    assert_eq!(sample.wrenches, m.wrenches);
    assert!(sample.has_imu.is_set());
    let orientation = m.base_orientation.quaternion();
    assert_eq!(
        sample.imu_orientation,
        [orientation.i, orientation.j, orientation.k, orientation.w]
    );
    let weight = robot.model.total_mass() * 9.81;
    assert!((sample.wrenches[0][2] + sample.wrenches[1][2] - weight).abs() < 0.01 * weight);
}

/// How far (m) JVRC-1's feet slide in 2 s while it stands pushed sideways at the pelvis by a
/// tenth of its weight (its feet then carry that force, a tenth of what friction, μ = 1, holds),
/// from 0.5 s after the push starts (the contacts' elastic give is over by then).
fn sideways_creep(options: MujocoOptions) -> f64 {
    let (robot, urdf) = robot("jvrc1");
    let initial = robot.standing.clone();
    let mut sim = MujocoSim::new(robot.clone(), &urdf, &initial, options).unwrap();
    hold_standing(&mut sim, 0.5);
    let weight = robot.model.total_mass() * 9.81;
    sim.set_pelvis_force(Vector3::new(0.0, 0.1 * weight, 0.0));
    hold_standing(&mut sim, 0.5);
    let feet = [EndEffector::LeftFoot, EndEffector::RightFoot];
    let start = feet.map(|f| sim.end_effector_pose(f).translation.vector);
    hold_standing(&mut sim, 2.0);
    assert!(!sim.has_fallen());
    feet.iter()
        .zip(start)
        .map(|(&f, s)| {
            (sim.end_effector_pose(f).translation.vector - s)
                .xy()
                .norm()
        })
        .fold(0.0, f64::max)
}

#[test]
fn a_sole_loaded_sideways_inside_its_friction_cone_stays_put_at_the_default_impratio() {
    let holding = sideways_creep(MujocoOptions::default());
    let creeping = sideways_creep(MujocoOptions {
        impratio: 1.0,
        ..MujocoOptions::default()
    });
    // Measured: 0.05 mm at the default `impratio` 20, 1.2 mm at MuJoCo's own default 1.
    assert!(holding < 1e-4, "the feet crept {holding} m in 2 s");
    assert!(
        creeping > 10.0 * holding,
        "the default creeps {creeping} m, not much more than {holding} m"
    );
}
