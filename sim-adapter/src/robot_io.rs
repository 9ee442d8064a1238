//! The robot-facing side of an adapter.

use shm_types::SensorSample;

/// A robot as an adapter sees it: sensors to read and joints to command, in the model's joint
/// order (the order of the URDF's actuated joints that `walkd` uses).
///
/// [`crate::run_adapter`] calls `read` once per period before publishing a sample, and `write`
/// once per period with the setpoint to apply (the daemon's command, or a hold posture when the
/// command watchdog tripped). Both run on the adapter's periodic thread: no blocking I/O beyond
/// the robot's own bus.
pub trait RobotIo {
    /// Why a setpoint could not be applied.
    type Error: std::error::Error + Send + Sync + 'static;

    /// Number of joints; at most [`shm_types::MAX_JOINTS`].
    fn joint_count(&self) -> usize;

    /// Writes the current joint angles and velocities (first `joint_count` entries of `q`,
    /// `qd`), the four wrenches and, if present, the IMU orientation into `sample`. The loop sets
    /// `seq`, `timestamp_ns`, `joint_count` and `adapter_holding`.
    fn read(&mut self, sample: &mut SensorSample);

    /// Applies one period's setpoint (`dt` seconds; a simulator advances by it).
    fn write(&mut self, q_des: &[f64], qd_des: &[f64], dt: f64) -> Result<(), Self::Error>;
}
