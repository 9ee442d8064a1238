//! The in-process closed loop: controller ↔ kinematic simulator, as fast as possible, with the
//! tick duration timed around `Controller::tick` (outside the controller core).

use std::sync::Arc;
use std::time::Instant;

use kinematic_sim::{KinematicSim, SafetySummary, SimMeasurement};
use kinematics::robot::{EndEffector, Robot};
use stance::PostProcessedSequence;

use crate::controller::{
    Command, Controller, ControllerConfig, ControllerState, ControllerStatus, Measurement,
    SolverKind,
};

/// How to run a walk.
#[derive(Clone, Copy, Debug)]
pub struct WalkOptions {
    /// QP back-end.
    pub solver: SolverKind,
    /// Control rate (Hz); the simulator steps by its period.
    pub rate_hz: f64,
    /// Simulated time after which an unfinished walk is stopped (s).
    pub time_limit_s: f64,
}

/// One closed-loop tick, handed to the observer after the simulator stepped.
pub struct TickObservation<'a> {
    /// Tick number (from 0).
    pub tick: u64,
    /// Simulator state and safety metrics after applying the command.
    pub sim: &'a SimMeasurement,
    /// Controller status after the tick.
    pub status: &'a ControllerStatus,
    /// The command sent.
    pub command: &'a Command,
    /// The controller (for its last QP).
    pub controller: &'a Controller,
    /// Wall time of `Controller::tick` (ns).
    pub tick_ns: u64,
}

/// How a walk ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Outcome {
    /// The controller reached `Done`.
    Done,
    /// The controller faulted; the code names why.
    Fault(crate::controller::FaultCode),
    /// The simulated CoM left the support polygon.
    Fell,
    /// The simulated time limit passed first.
    TimeLimit,
}

impl Outcome {
    /// `done` or `fault:<reason>` as printed by `walkd bench`.
    pub fn label(self) -> String {
        match self {
            Self::Done => "done".to_owned(),
            Self::Fault(code) => format!("fault:{}", code.code()),
            Self::Fell => "fault:fall".to_owned(),
            Self::TimeLimit => "fault:time_limit".to_owned(),
        }
    }
}

/// Result of a walk.
#[derive(Clone, Copy, Debug)]
pub struct WalkReport {
    /// How it ended.
    pub outcome: Outcome,
    /// Stances in the sequence.
    pub stances: usize,
    /// Control ticks run.
    pub ticks: u64,
    /// Worst safety values seen by the simulator.
    pub safety: SafetySummary,
    /// Horizontal distance the feet midpoint travelled (m, simulator truth).
    pub distance_m: f64,
}

/// Errors setting up a walk.
#[derive(Debug, thiserror::Error)]
pub enum WalkError {
    /// The controller could not be built.
    #[error(transparent)]
    Controller(#[from] crate::controller::ControllerError),
    /// The controller refused the sequence.
    #[error(transparent)]
    Refused(#[from] crate::controller::Refusal),
    /// The simulator refused the start state or a command.
    #[error("simulator: {0}")]
    Sim(kinematic_sim::SimError),
}

impl From<kinematic_sim::SimError> for WalkError {
    fn from(error: kinematic_sim::SimError) -> Self {
        Self::Sim(error)
    }
}

/// Executes `sequence` on `robot` (starting from its standing posture) in closed loop with the
/// kinematic simulator; `observe` sees every tick.
pub fn walk(
    robot: Arc<Robot>,
    config: ControllerConfig,
    sequence: &PostProcessedSequence,
    options: &WalkOptions,
    mut observe: impl FnMut(&TickObservation),
) -> Result<WalkReport, WalkError> {
    let prepared = Controller::prepare(&robot, &config, sequence)?;
    let stances = prepared.len();
    let mut controller = Controller::new(robot.clone(), config, options.solver)?;
    let mut sim = KinematicSim::new(robot.clone(), robot.standing.clone())?;
    let dof = robot.model.dof();
    let mut command = Command::new(dof);
    let dt = 1.0 / options.rate_hz;
    let max_ticks = (options.time_limit_s * options.rate_hz).ceil() as u64;
    let start_midpoint = feet_midpoint(&sim);
    if controller.start(Box::new(prepared)).is_err() {
        unreachable!("a new controller accepts a sequence");
    }
    let mut ticks = 0;
    let outcome = loop {
        if ticks >= max_ticks {
            break Outcome::TimeLimit;
        }
        let m = sim.measurement();
        let measurement = Measurement {
            q: m.q.as_slice(),
            qd: m.qd.as_slice(),
            wrenches: &m.wrenches,
            imu_orientation: Some(m.base_orientation),
        };
        let started = Instant::now();
        let commanded = controller.tick(&measurement, dt, &mut command);
        let tick_ns = started.elapsed().as_nanos() as u64;
        if !commanded {
            // Only before a first valid measurement: the simulator's never is invalid.
            break Outcome::Fault(controller.status().fault);
        }
        sim.step(command.q_des.as_slice(), command.qd_des.as_slice(), dt)?;
        observe(&TickObservation {
            tick: ticks,
            sim: sim.measurement(),
            status: controller.status(),
            command: &command,
            controller: &controller,
            tick_ns,
        });
        ticks += 1;
        if sim.measurement().safety.stability_margin < 0.0 {
            break Outcome::Fell;
        }
        match controller.status().state {
            ControllerState::Done => break Outcome::Done,
            ControllerState::Fault => break Outcome::Fault(controller.status().fault),
            _ => {}
        }
    };
    let end_midpoint = feet_midpoint(&sim);
    Ok(WalkReport {
        outcome,
        stances,
        ticks,
        safety: *sim.summary(),
        distance_m: (end_midpoint - start_midpoint).norm(),
    })
}

/// Ground-plane midpoint of the two soles (simulator truth).
fn feet_midpoint(sim: &KinematicSim) -> nalgebra::Vector2<f64> {
    let robot = sim.robot();
    let mut kinematics = kinematics::kinematics::Kinematics::new(&robot.model);
    kinematics.update(&robot.model, sim.configuration());
    let pose = |e: EndEffector| {
        kinematics
            .frame_pose(&robot.model, robot.frame(e))
            .translation
            .vector
            .xy()
    };
    (pose(EndEffector::LeftFoot) + pose(EndEffector::RightFoot)) / 2.0
}
