//! The interface of a simulated robot: what a controller's closed loop and an adapter need from
//! any simulator, so the same loop and the same adapter serve the kinematic simulator and MuJoCo.

use std::sync::Arc;

use kinematics::robot::{EndEffector, Robot};
use nalgebra::Isometry3;

use crate::{KinematicSim, SafetySummary, SimError, SimMeasurement};

/// A simulated robot driven by joint commands.
pub trait Simulator {
    /// Why a command or time step could not be applied.
    type Error: std::error::Error + Send + Sync + 'static;

    /// The robot being simulated.
    fn robot(&self) -> &Arc<Robot>;

    /// Advances by `dt` with the joint servos tracking `q_des` / `qd_des` (model joint order).
    fn step(&mut self, q_des: &[f64], qd_des: &[f64], dt: f64) -> Result<(), Self::Error>;

    /// Sensor readings (joints, wrenches, IMU), ground truth and safety metrics of now.
    fn measurement(&self) -> &SimMeasurement;

    /// Worst safety values since the start.
    fn summary(&self) -> &SafetySummary;

    /// True world pose of an end-effector frame.
    fn end_effector_pose(&self, effector: EndEffector) -> Isometry3<f64>;

    /// True world pose of the configured `base_link` (the pelvis).
    fn base_link_pose(&self) -> Isometry3<f64>;

    /// Simulated time since the start (s).
    fn time(&self) -> f64;
}

/// Joints follow the command ideally (a perfect position servo, stopped at the limits), the base
/// follows the feet in contact, contacts, forces and metrics are updated each step.
///
/// A controller that moves the robot never sends the same setpoint twice: each one moves on by
/// its rate `qd_des`. One given again with a non-zero rate is a command that did not come (an
/// adapter in real time applies its last setpoint again while the controller is a period late).
/// The joints hold, as an ideal servo does, but the ZMP's motion history skips the step: a real
/// robot's servos ride through one missing setpoint, while the ideal ones stop dead, which at
/// walking pace put the ZMP 0.1-1 m off the feet for that one step.
impl Simulator for KinematicSim {
    type Error = SimError;

    fn robot(&self) -> &Arc<Robot> {
        &self.robot
    }

    fn step(&mut self, q_des: &[f64], qd_des: &[f64], dt: f64) -> Result<(), SimError> {
        self.check_command("q_des", q_des)?;
        self.check_command("qd_des", qd_des)?;
        if !(dt.is_finite() && dt > 0.0) {
            return Err(SimError::BadTimeStep(dt));
        }
        let missed = self.missed_command(q_des, qd_des);
        let mut violations = 0;
        let limits = self.robot.model.joint_limits();
        for (j, (&target, limit)) in q_des.iter().zip(limits).enumerate() {
            let q = target.clamp(limit.lower, limit.upper);
            if q != target {
                violations += 1;
            }
            self.measurement.qd[j] = (q - self.configuration.joints[j]) / dt;
            self.configuration.joints[j] = q;
        }
        self.place_base();
        self.update_contacts();
        self.finish_step(violations, (!missed).then_some(dt));
        self.time += dt;
        Ok(())
    }

    fn measurement(&self) -> &SimMeasurement {
        &self.measurement
    }

    fn summary(&self) -> &SafetySummary {
        &self.summary
    }

    fn end_effector_pose(&self, effector: EndEffector) -> Isometry3<f64> {
        self.pose(effector)
    }

    fn base_link_pose(&self) -> Isometry3<f64> {
        *self.kinematics.link_pose(self.robot.base_link)
    }

    fn time(&self) -> f64 {
        self.time
    }
}
