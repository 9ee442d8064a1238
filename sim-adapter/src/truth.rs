//! The simulator's ground truth on IPC: what only a simulated robot can report (its true CoM,
//! sole poses, base height and tilt, and whether it fell), published next to every sensor sample
//! so evaluation clients can measure the controller's drift and judge falls.

use nalgebra::Isometry3;
use shm_types::{SensorSample, SimTruth, TruthPublisher};

use crate::RobotIo;

/// A simulated robot that knows its true state.
pub trait GroundTruth {
    /// Writes the true CoM, sole poses, base height, tilt and fall flag of the current state into
    /// `out`; `seq`, `timestamp_ns` and `sim_time_s` are left to the caller. No allocation.
    fn ground_truth(&mut self, out: &mut SimTruth);
}

/// A simulated robot whose every sensor reading also publishes its true state on `sim-truth`.
///
/// The truth is read in [`RobotIo::read`], i.e. from the state the next sensor sample is taken
/// from, and stamped just before that sample is published. A failed publication is logged once
/// and does not stop the robot: the truth is for evaluation, the control loop does not need it.
pub struct PublishTruth<R> {
    robot: R,
    publisher: TruthPublisher,
    truth: SimTruth,
    publish_failed: bool,
}

impl<R> PublishTruth<R> {
    /// Publishes `robot`'s truth through `publisher`.
    pub fn new(robot: R, publisher: TruthPublisher) -> Self {
        Self {
            robot,
            publisher,
            truth: SimTruth::ZERO,
            publish_failed: false,
        }
    }

    /// The wrapped robot.
    pub fn robot(&self) -> &R {
        &self.robot
    }
}

impl<R: RobotIo + GroundTruth> RobotIo for PublishTruth<R> {
    type Error = R::Error;

    fn joint_count(&self) -> usize {
        self.robot.joint_count()
    }

    fn read(&mut self, sample: &mut SensorSample) {
        self.robot.read(sample);
        self.robot.ground_truth(&mut self.truth);
        self.truth.seq += 1;
        self.truth.timestamp_ns = shm_types::monotonic_ns();
        if let Err(error) = self.publisher.publish(&self.truth)
            && !self.publish_failed
        {
            tracing::error!(%error, "cannot publish the simulator's truth (evaluation only)");
            self.publish_failed = true;
        }
    }

    fn write(&mut self, q_des: &[f64], qd_des: &[f64], dt: f64) -> Result<(), R::Error> {
        self.robot.write(q_des, qd_des, dt)?;
        self.truth.sim_time_s += dt;
        Ok(())
    }
}

/// A pose as translation xyz + quaternion xyzw (the layout of [`SimTruth`] and `DaemonStatus`).
pub(crate) fn pose_array(pose: &Isometry3<f64>) -> [f64; 7] {
    let t = &pose.translation.vector;
    let q = pose.rotation.quaternion();
    [t.x, t.y, t.z, q.i, q.j, q.k, q.w]
}

/// Angle between a pose's z axis and the world vertical (rad).
pub(crate) fn tilt(pose: &Isometry3<f64>) -> f64 {
    let up = pose.rotation * nalgebra::Vector3::z();
    up.z.clamp(-1.0, 1.0).acos()
}
