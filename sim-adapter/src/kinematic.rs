//! [`RobotIo`] over the deterministic kinematic simulator.

use std::sync::Arc;

use kinematic_sim::{KinematicSim, SafetySummary, SimError};
use kinematics::kinematics::Kinematics;
use kinematics::robot::{EndEffector, Robot};
use shm_types::{SensorSample, SimTruth};

use crate::RobotIo;
use crate::robot_io::fill_sample;
use crate::truth::{GroundTruth, pose_array, tilt};

/// The kinematic simulator as a robot: an ideal position servo whose floating base follows the
/// feet in contact; force readings from static equilibrium; an ideal IMU.
pub struct KinematicRobot {
    sim: KinematicSim,
    /// Forward kinematics of the simulated configuration, for the ground truth.
    truth_kinematics: Kinematics,
}

impl KinematicRobot {
    /// Starts the simulation in the robot's standing posture.
    pub fn standing(robot: Arc<Robot>) -> Result<Self, SimError> {
        let initial = robot.standing.clone();
        let truth_kinematics = Kinematics::new(&robot.model);
        Ok(Self {
            sim: KinematicSim::new(robot, initial)?,
            truth_kinematics,
        })
    }

    /// Worst safety values since the start (stability margin, slip, falls).
    pub fn summary(&self) -> &SafetySummary {
        self.sim.summary()
    }
}

impl RobotIo for KinematicRobot {
    type Error = SimError;

    fn joint_count(&self) -> usize {
        self.sim.robot().model.dof()
    }

    fn read(&mut self, sample: &mut SensorSample) {
        fill_sample(self.sim.measurement(), sample);
    }

    fn write(&mut self, q_des: &[f64], qd_des: &[f64], dt: f64) -> Result<(), SimError> {
        self.sim.step(q_des, qd_des, dt)
    }
}

impl GroundTruth for KinematicRobot {
    /// The simulated configuration's CoM, soles and `base_link`; fallen = the CoM left the
    /// support polygon (the kinematic simulator's rule, [`SafetySummary::fell`]).
    fn ground_truth(&mut self, out: &mut SimTruth) {
        let robot = self.sim.robot();
        let kinematics = &mut self.truth_kinematics;
        kinematics.update(&robot.model, self.sim.configuration());
        let base_link = kinematics.link_pose(robot.base_link);
        out.com = self.sim.measurement().com.into();
        out.left_foot =
            pose_array(&kinematics.frame_pose(&robot.model, robot.frame(EndEffector::LeftFoot)));
        out.right_foot =
            pose_array(&kinematics.frame_pose(&robot.model, robot.frame(EndEffector::RightFoot)));
        out.base_height_m = base_link.translation.z;
        out.tilt_rad = tilt(base_link);
        out.fallen = self.sim.summary().fell.into();
    }
}
