//! The simulator's ground truth: what each simulated robot reports, and its publication on
//! `sim-truth` next to every sensor reading.

use kinematic_sim::Simulator;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use kinematic_sim::KinematicSim;
use kinematics::robot::Robot;
use shm_types::{SensorSample, ServiceNames, SimTruth, TruthPublisher, TruthSubscriber};
use sim_adapter::{GroundTruth, PublishTruth, RobotIo, SimulatedRobot};

const DT: f64 = 0.002;

fn config(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("../configs/{name}.toml"))
}

fn robot(name: &str) -> Arc<Robot> {
    Arc::new(Robot::load(&config(name), None).unwrap_or_else(|e| panic!("{name}: {e}")))
}

/// Standing: both soles on the floor, left of right, the pelvis upright and high.
fn assert_standing(name: &str, truth: &SimTruth) {
    for (foot, pose) in [("left", truth.left_foot), ("right", truth.right_foot)] {
        assert!(pose[2].abs() < 1e-3, "{name} {foot} sole at z {}", pose[2]);
    }
    assert!(
        truth.left_foot[1] > truth.right_foot[1],
        "{name}: {truth:?}"
    );
    assert!(truth.tilt_rad < 0.02, "{name}: tilt {}", truth.tilt_rad);
    assert!(
        truth.base_height_m > 0.5,
        "{name}: base {}",
        truth.base_height_m
    );
    assert!(truth.com[2] > 0.5, "{name}: CoM {:?}", truth.com);
    assert!(!truth.fallen.is_set(), "{name}");
}

#[test]
fn the_kinematic_robot_reports_its_simulated_state() {
    let robot = robot("jvrc1");
    let standing = robot.standing.clone();
    let mut sim = SimulatedRobot::new(KinematicSim::new(robot, standing).unwrap());
    let mut truth = SimTruth {
        terrain_collisions: 99,
        ..SimTruth::ZERO
    };
    sim.ground_truth(&mut truth);
    assert_standing("jvrc1", &truth);
    // The kinematic simulator has no terrain: its legs never collide.
    assert_eq!(truth.terrain_collisions, 0);
}

#[test]
fn every_reading_publishes_the_truth_with_its_time() {
    let prefix = format!("walk-test/sim-adapter/truth/{}", std::process::id());
    let names = ServiceNames::new(&prefix).unwrap();
    let subscriber = TruthSubscriber::open(&names, "evaluator").unwrap();
    let robot = robot("armar4");
    let q: Vec<f64> = robot.standing.joints.iter().copied().collect();
    let qd = vec![0.0; q.len()];
    let standing = robot.standing.clone();
    let mut sim = PublishTruth::new(
        SimulatedRobot::new(KinematicSim::new(robot, standing).unwrap()),
        TruthPublisher::open(&names, "simulator").unwrap(),
    );
    let mut sample = SensorSample::ZERO;
    let before = shm_types::monotonic_ns();
    sim.read(&mut sample);
    for _ in 0..3 {
        sim.write(&q, &qd, DT).unwrap();
    }
    sim.read(&mut sample);
    let mut received = Vec::new();
    subscriber.drain(|truth| received.push(*truth)).unwrap();
    assert_eq!(received.len(), 2);
    assert_eq!([received[0].seq, received[1].seq], [1, 2]);
    assert_eq!(received[0].sim_time_s, 0.0);
    assert!((received[1].sim_time_s - 3.0 * DT).abs() < 1e-12);
    assert!(before <= received[0].timestamp_ns);
    assert!(received[0].timestamp_ns <= received[1].timestamp_ns);
    assert!(received[1].timestamp_ns <= shm_types::monotonic_ns());
    assert_standing("armar4", &received[1]);
    // The reading itself is the robot's, untouched by the wrapper.
    let measured = sim.robot().sim().summary();
    assert!(!measured.fell);
    assert_eq!(sample.q[..q.len()], q[..]);
}

#[cfg(feature = "mujoco")]
#[test]
fn the_mujoco_robot_reports_its_physics_state() {
    use kinematics::robot::EndEffector;
    use sim_adapter::mujoco::{MujocoOptions, MujocoSim};

    let robot = robot("jvrc1");
    let (urdf, standing) = (robot.urdf.clone(), robot.standing.clone());
    let q: Vec<f64> = robot.standing.joints.iter().copied().collect();
    let qd = vec![0.0; q.len()];
    let mut io = SimulatedRobot::new(
        MujocoSim::new(robot, &urdf, &standing, MujocoOptions::default()).unwrap(),
    );
    for _ in 0..100 {
        io.write(&q, &qd, DT).unwrap();
    }
    let mut truth = SimTruth::ZERO;
    io.ground_truth(&mut truth);
    assert_standing("jvrc1", &truth);
    let sim = io.sim();
    assert_eq!(truth.com, <[f64; 3]>::from(sim.measurement().com));
    let left = sim.end_effector_pose(EndEffector::LeftFoot);
    assert_eq!(truth.left_foot[..3], left.translation.vector.as_slice()[..]);
    assert_eq!(truth.base_height_m, sim.base_height());
    assert_eq!(truth.tilt_rad, sim.torso_tilt());
    // The flat floor: the legs have no collision geometry.
    assert_eq!(truth.terrain_collisions, 0);
}
