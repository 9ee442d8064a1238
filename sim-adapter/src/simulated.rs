//! Any [`Simulator`] as a robot for the adapter loop: its readings become sensor samples, the
//! daemon's setpoints its commands, and its true state the `sim-truth` record. One wrapper for the
//! kinematic simulator and MuJoCo alike.

use kinematic_sim::{KinematicSim, SimMeasurement, Simulator};
use kinematics::robot::EndEffector;
use shm_types::{ActuatorLoad, SensorSample, SimTruth};

use crate::RobotIo;
use crate::truth::{GroundTruth, pose_array, tilt};

/// A simulator behind [`RobotIo`] and [`GroundTruth`]: ideal encoders, the simulator's FT
/// wrenches and an ideal IMU on the floating base.
pub struct SimulatedRobot<S> {
    sim: S,
}

impl<S: Simulator> SimulatedRobot<S> {
    /// The adapter's view of `sim`.
    pub fn new(sim: S) -> Self {
        Self { sim }
    }

    /// The simulator (its safety summary, true poses).
    pub fn sim(&self) -> &S {
        &self.sim
    }
}

impl<S: Simulator> RobotIo for SimulatedRobot<S> {
    type Error = S::Error;

    fn joint_count(&self) -> usize {
        self.sim.robot().model.dof()
    }

    fn read(&mut self, sample: &mut SensorSample) {
        fill_sample(self.sim.measurement(), sample);
    }

    fn write(&mut self, q_des: &[f64], qd_des: &[f64], dt: f64) -> Result<(), S::Error> {
        self.sim.step(q_des, qd_des, dt)
    }
}

/// A simulator's account of how hard its motors work, for the `sim-truth` record: MuJoCo's
/// torques and speeds against the URDF's limits. A simulator without actuator dynamics (the
/// kinematic one) reports nothing.
pub trait MotorLoad {
    /// The load since the start.
    fn actuator_load(&self) -> ActuatorLoad {
        ActuatorLoad::ZERO
    }
}

impl MotorLoad for KinematicSim {}

/// A simulator's count of its legs' collisions with the terrain, for the `sim-truth` record:
/// MuJoCo's leg capsules against a scene's surfaces. A simulator without terrain (the kinematic
/// one) counts none.
pub trait TerrainContacts {
    /// Leg-terrain contact events since the start. No allocation.
    fn terrain_collision_count(&self) -> u64 {
        0
    }
}

impl TerrainContacts for KinematicSim {}

impl<S: Simulator + MotorLoad + TerrainContacts> GroundTruth for SimulatedRobot<S> {
    /// The simulated state's CoM, soles and `base_link`; fallen = the simulator's fall rule fired
    /// at any step so far ([`kinematic_sim::SafetySummary::fell`]: the CoM left the support
    /// polygon in the kinematic simulator; base too low or tilted under MuJoCo); the motors' load;
    /// the legs' terrain collisions.
    fn ground_truth(&mut self, out: &mut SimTruth) {
        let sim = &self.sim;
        let base_link = sim.base_link_pose();
        out.com = sim.measurement().com.into();
        out.left_foot = pose_array(&sim.end_effector_pose(EndEffector::LeftFoot));
        out.right_foot = pose_array(&sim.end_effector_pose(EndEffector::RightFoot));
        out.base_height_m = base_link.translation.z;
        out.tilt_rad = tilt(&base_link);
        out.fallen = sim.summary().fell.into();
        out.actuators = sim.actuator_load();
        out.terrain_collisions = sim.terrain_collision_count();
        let wrenches = &sim.measurement().wrenches;
        for (force, hand) in out.hand_forces.iter_mut().zip(EndEffector::HANDS) {
            force.copy_from_slice(&wrenches[hand as usize][..3]);
        }
    }
}

/// Copies a simulator's sensor readings into `sample`: joint angles and velocities, the four
/// wrenches and the base orientation as an ideal IMU (`[x, y, z, w]`). No allocation.
fn fill_sample(measurement: &SimMeasurement, sample: &mut SensorSample) {
    let n = measurement.q.len();
    sample.q[..n].copy_from_slice(measurement.q.as_slice());
    sample.qd[..n].copy_from_slice(measurement.qd.as_slice());
    sample.wrenches = measurement.wrenches;
    let q = measurement.base_orientation.quaternion();
    sample.imu_orientation = [q.i, q.j, q.k, q.w];
    sample.has_imu = true.into();
}
