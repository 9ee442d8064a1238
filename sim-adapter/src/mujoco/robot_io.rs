//! [`RobotIo`] over the MuJoCo simulator, for `walk-sim --physics mujoco`.

use std::path::Path;
use std::sync::Arc;

use kinematic_sim::SafetySummary;
use kinematics::robot::{EndEffector, Robot};
use shm_types::{SensorSample, SimTruth};

use super::{MujocoError, MujocoOptions, MujocoSim};
use crate::RobotIo;
use crate::robot_io::fill_sample;
use crate::truth::{GroundTruth, pose_array};

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

    /// The simulator, for the renderer.
    #[cfg(feature = "render")]
    pub(crate) fn sim_mut(&mut self) -> &mut MujocoSim {
        &mut self.sim
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

impl GroundTruth for MujocoRobot {
    /// The physics state's CoM, sole sites and `base_link`; fallen = [`MujocoSim::has_fallen`]
    /// at any step so far (base below its height fraction or tilted beyond `fall_tilt`).
    fn ground_truth(&mut self, out: &mut SimTruth) {
        let sim = &self.sim;
        out.com = sim.measurement().com.into();
        out.left_foot = pose_array(&sim.end_effector_pose(EndEffector::LeftFoot));
        out.right_foot = pose_array(&sim.end_effector_pose(EndEffector::RightFoot));
        out.base_height_m = sim.base_height();
        out.tilt_rad = sim.torso_tilt();
        out.fallen = sim.summary().fell.into();
    }
}
