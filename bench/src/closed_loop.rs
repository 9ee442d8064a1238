//! The controller in closed loop with a simulator, in one process: each tick reads the
//! simulator's measurement (encoders, foot wrenches, IMU), ticks the controller on it, and steps
//! the simulator by one control period with the command. The one loop behind `walk-bench`, the
//! physics walks, the tick benchmark and the state-machine tests, for the kinematic simulator
//! and MuJoCo alike ([`Simulator`]). The controller's compute time is timed here, outside the
//! controller core.

use std::time::{Duration, Instant};

use daemon::controller::{Command, Controller, Measurement};
use kinematic_sim::Simulator;
use kinematics::robot::EndEffector;
use nalgebra::Vector2;

/// Why a tick could not be completed.
#[derive(Debug, thiserror::Error)]
pub enum TickError<E> {
    /// The controller wrote no command: it never had a valid measurement to hold (the
    /// simulator's first one was refused; its status says why).
    #[error("the controller wrote no command (its first measurement was refused)")]
    NoCommand,
    /// The simulator refused the command or the step.
    #[error("simulator: {0}")]
    Sim(E),
}

/// What the controller is about to read in a tick, for a test to tamper with first (fault
/// injection): the joint angles and the wrenches.
pub struct Readings<'a> {
    /// Joint angles, model order.
    pub q: &'a mut [f64],
    /// Wrenches by `EndEffector`.
    pub wrenches: &'a mut [[f64; 6]; 4],
}

/// A controller and the simulated robot it controls.
pub struct ClosedLoop<S> {
    /// The controller (its status, its last QP).
    pub controller: Controller,
    /// The simulated robot.
    pub sim: S,
    /// The last command sent.
    pub command: Command,
    /// The joint angles of a tick, as the controller reads them.
    q: Vec<f64>,
    dt: f64,
}

impl<S: Simulator> ClosedLoop<S> {
    /// `controller` driving `sim` at `rate_hz` (the simulator advances by `1 / rate_hz` a tick).
    pub fn new(controller: Controller, sim: S, rate_hz: f64) -> Self {
        let dof = controller.robot().model.dof();
        Self {
            controller,
            sim,
            command: Command::new(dof),
            q: vec![0.0; dof],
            dt: 1.0 / rate_hz,
        }
    }

    /// The control period (s).
    pub fn dt(&self) -> f64 {
        self.dt
    }

    /// One tick; returns the controller's compute time.
    pub fn tick(&mut self) -> Result<Duration, TickError<S::Error>> {
        self.tick_with(|_| {})
    }

    /// One tick with the readings passed through `tamper` first (fault injection); returns the
    /// controller's compute time. Allocation-free.
    pub fn tick_with(
        &mut self,
        tamper: impl FnOnce(Readings<'_>),
    ) -> Result<Duration, TickError<S::Error>> {
        let m = self.sim.measurement();
        let mut wrenches = m.wrenches;
        self.q.copy_from_slice(m.q.as_slice());
        tamper(Readings {
            q: &mut self.q,
            wrenches: &mut wrenches,
        });
        let measurement = Measurement {
            q: &self.q,
            qd: m.qd.as_slice(),
            wrenches: &wrenches,
            imu_orientation: Some(m.base_orientation),
        };
        let started = Instant::now();
        let commanded = self
            .controller
            .tick(&measurement, self.dt, &mut self.command);
        let compute = started.elapsed();
        if !commanded {
            return Err(TickError::NoCommand);
        }
        self.sim
            .step(
                self.command.q_des.as_slice(),
                self.command.qd_des.as_slice(),
                self.dt,
            )
            .map_err(TickError::Sim)?;
        Ok(compute)
    }
}

/// Ground-plane midpoint of the two simulated soles: where the walk has got to.
pub fn feet_midpoint(sim: &impl Simulator) -> Vector2<f64> {
    let pose = |e: EndEffector| sim.end_effector_pose(e).translation.vector.xy();
    (pose(EndEffector::LeftFoot) + pose(EndEffector::RightFoot)) / 2.0
}
