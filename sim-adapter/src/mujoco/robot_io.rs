//! [`RobotIo`] over the MuJoCo simulator, for `walk-sim --physics mujoco`.

use std::path::Path;
use std::sync::Arc;

use kinematic_sim::SafetySummary;
use kinematics::robot::Robot;
use shm_types::SensorSample;

use super::{MujocoError, MujocoOptions, MujocoSim};
use crate::RobotIo;
use crate::robot_io::fill_sample;

/// The MuJoCo simulator as a robot: joint servos under rigid-body dynamics, foot FT from the
/// contact forces, an IMU on the base.
pub struct MujocoRobot {
    sim: MujocoSim,
}

impl MujocoRobot {
    /// Starts the simulation in the robot's standing posture (`urdf`: the file the robot was
    /// loaded from, for its inertials).
    pub fn standing(
        robot: Arc<Robot>,
        urdf: &Path,
        options: MujocoOptions,
    ) -> Result<Self, MujocoError> {
        let initial = robot.standing.clone();
        Ok(Self {
            sim: MujocoSim::new(robot, urdf, &initial, options)?,
        })
    }

    /// The simulator, for ground truth (base height and tilt, CoM, foot poses).
    pub fn sim(&self) -> &MujocoSim {
        &self.sim
    }

    /// Worst safety values since the start (stability margin, slip, falls).
    pub fn summary(&self) -> &SafetySummary {
        self.sim.summary()
    }
}

impl RobotIo for MujocoRobot {
    type Error = MujocoError;

    fn joint_count(&self) -> usize {
        self.sim.robot().model.dof()
    }

    fn read(&mut self, sample: &mut SensorSample) {
        fill_sample(self.sim.measurement(), sample);
    }

    fn write(&mut self, q_des: &[f64], qd_des: &[f64], dt: f64) -> Result<(), MujocoError> {
        self.sim.step(q_des, qd_des, dt)
    }
}
