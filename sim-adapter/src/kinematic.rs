//! [`RobotIo`] over the deterministic kinematic simulator.

use std::sync::Arc;

use kinematic_sim::{KinematicSim, SafetySummary, SimError};
use kinematics::robot::Robot;
use shm_types::SensorSample;

use crate::RobotIo;
use crate::robot_io::fill_sample;

/// The kinematic simulator as a robot: an ideal position servo whose floating base follows the
/// feet in contact; force readings from static equilibrium; an ideal IMU.
pub struct KinematicRobot {
    sim: KinematicSim,
}

impl KinematicRobot {
    /// Starts the simulation in the robot's standing posture.
    pub fn standing(robot: Arc<Robot>) -> Result<Self, SimError> {
        let initial = robot.standing.clone();
        Ok(Self {
            sim: KinematicSim::new(robot, initial)?,
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
